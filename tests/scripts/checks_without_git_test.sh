#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The checks of scripts/test.sh (format, layers, size) in a copy of the tree that has
# no .git, as a release tarball or a copied folder has: they must list the same files
# git lists, pass where the checkout passes, and still catch a violation planted in
# the copy (so they read the disk, not an empty list).
#   checks_without_git_test.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
py=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
copy="$work/tree"
mkdir "$copy"
(cd "$src" && "$py" scripts/source_files.py) > "$work/listed-here.txt"
(cd "$src" && xargs -d '\n' cp --parents -t "$copy") < "$work/listed-here.txt"
# What a tarball of a built tree also holds: a build folder and caches, which .gitignore names.
mkdir -p "$copy/build/default" "$copy/tools/__pycache__"
printf 'int x;\n%.0s' $(seq 500) > "$copy/build/default/generated.cpp"
[[ ! -e "$copy/.git" ]] || { echo "FAIL: the copy has a .git"; exit 1; }

"$py" "$copy/scripts/source_files.py" --root "$copy" > "$work/listed-copy.txt" 2> "$work/note.txt"
diff -u "$work/listed-here.txt" "$work/listed-copy.txt" || { echo "FAIL: the copy lists other files"; exit 1; }
grep -q "no .git here" "$work/note.txt" || { echo "FAIL: no note that the disk was read"; cat "$work/note.txt"; exit 1; }

(cd "$copy" && scripts/check_format.sh) > "$work/format.txt" 2>&1 || { cat "$work/format.txt"; echo "FAIL: format"; exit 1; }
(cd "$copy" && "$py" scripts/check_layers.py) > "$work/layers.txt" 2>&1 || { cat "$work/layers.txt"; echo "FAIL: layers"; exit 1; }
(cd "$copy" && "$py" scripts/check_size.py -p "$build") > "$work/size.txt" 2>&1 || { cat "$work/size.txt"; echo "FAIL: size"; exit 1; }
echo "the three checks pass in a copy without .git ($(wc -l < "$work/listed-copy.txt") files)"

# Planted in the copy: a core header over 400 lines that includes an OS header,
# badly formatted. Each check must name it.
planted="$copy/core/planted_for_test.hpp"
{ echo '#include <unistd.h>'; echo 'int  planted ( ) ;'; printf '// line\n%.0s' $(seq 400); } > "$planted"
! (cd "$copy" && scripts/check_format.sh) > "$work/format.txt" 2>&1 || { echo "FAIL: format missed the planted file"; exit 1; }
grep -q planted_for_test "$work/format.txt" || { echo "FAIL: format did not name the planted file"; exit 1; }
! (cd "$copy" && "$py" scripts/check_layers.py) > "$work/layers.txt" 2>&1 || { echo "FAIL: layers missed it"; exit 1; }
grep -q "planted_for_test.hpp:1: #include <unistd.h>" "$work/layers.txt" || { cat "$work/layers.txt"; echo "FAIL: layers did not name it"; exit 1; }
! (cd "$copy" && "$py" scripts/check_size.py -p "$build") > "$work/size.txt" 2>&1 || { echo "FAIL: size missed it"; exit 1; }
grep -q "planted_for_test.hpp: 402 lines" "$work/size.txt" || { cat "$work/size.txt"; echo "FAIL: size did not name it"; exit 1; }
echo "and each check names a violation planted in the copy"
