#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# `tensegrity analyze` on a short episode of a shipped policy: the CSV files and the
# summary are written, the JSON on stdout is the summary, the numbers are sane, and
# the PNGs exist when the summary says the plots were written.
set -eu
cli="$1"
src="${TENSEGRITY_SOURCE_DIR:?}"
policy="$src/docs/results/policies/superball-ntrt2014-t4-n5-e5000.json"
[ -f "$policy" ] || policy=$(ls "$src"/policies/*.json | head -n 1)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

"$cli" analyze --help | grep -q -- "--duration" || { echo "FAIL: --help lists no --duration"; exit 1; }
"$cli" analyze "$policy" --duration 10 --out "$out/run" --json > "$out/stdout.json"

for f in fig10_11_muscles.csv fig11_timeseries.csv fig12_signals.csv fig12_correlation.csv fig12_linkage.csv \
         fig12_aligned_correlation.csv fig12_aligned_lag_samples.csv fig12_aligned_linkage.csv fig12_clusters.csv contacts.csv faces.csv \
         endcaps.csv summary.json; do
  [ -s "$out/run/$f" ] || { echo "FAIL: $f missing or empty"; exit 1; }
done
cmp -s "$out/stdout.json" "$out/run/summary.json" || { echo "FAIL: stdout differs from summary.json"; exit 1; }

# 24 muscles + header, 10 s at 100 Hz + the start + header.
[ "$(wc -l < "$out/run/fig10_11_muscles.csv")" -eq 25 ] || { echo "FAIL: fig10_11_muscles.csv rows"; exit 1; }
[ "$(wc -l < "$out/run/fig11_timeseries.csv")" -eq 1002 ] || { echo "FAIL: fig11_timeseries.csv rows"; exit 1; }

/usr/bin/python3 - "$out/run" <<'PY'
import json, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
assert s["episode"]["feasible"], s["episode"]
assert 0.6 - 1e-9 <= s["rest_length_m"]["min"] <= s["rest_length_m"]["max"] <= 1.1 + 1e-9, s["rest_length_m"]
assert 0 < s["tension_n"]["mean"] < s["tension_n"]["peak"], s["tension_n"]
assert s["rolling"]["endcaps_touched_count"] >= 3, s["rolling"]
assert len(s["rolling"]["face_sequence"]) >= 1, s["rolling"]
assert sorted(c for g in s["clusters"]["zero_lag"] for c in g) == list(range(24)), s["clusters"]
plots = s["plots"]
assert plots == "written" or plots.startswith("skipped"), plots
if plots == "written":
    for f in ("fig10_rest_lengths.png", "fig11_time.png", "fig11_muscles.png", "fig12_correlation.png",
              "fig12_dendrogram.png", "fig12_signals.png", "rolling.png"):
        assert os.path.getsize(os.path.join(d, f)) > 1000, f
print("plots:", plots)
PY
echo "PASS"
