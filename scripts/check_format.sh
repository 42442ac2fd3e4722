#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Every tracked C++ file as .clang-format says (clang-format 14, Debian's): exits 1
# naming each file that differs, with the first lines of its diff. `--fix` rewrites
# them in place instead.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
# git's tracked files, or the files on disk where there is no git (scripts/source_files.py)
mapfile -t files < <(/usr/bin/python3 scripts/source_files.py '*.cpp' '*.hpp' '*.h')
(( ${#files[@]} > 0 )) || { echo "format: no C++ files found" >&2; exit 1; }
if [[ "${1:-}" == "--fix" ]]; then
  clang-format -i "${files[@]}"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "format: $f differs from .clang-format:"
    clang-format "$f" | diff -u "$f" - | sed -n '3,12p' || true
    bad=$((bad + 1))
  fi
done
if (( bad > 0 )); then
  echo "format: $bad of ${#files[@]} files differ (scripts/check_format.sh --fix rewrites them)"
  exit 1
fi
echo "format: ${#files[@]} files follow .clang-format"
