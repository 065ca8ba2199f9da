#!/usr/bin/env bash
# Large-scale regularity of zoomed-out views (issue 41): for each development exemplar
# (../shared/exemplars/NAME.png, 128²), the same 2048² area of the texture (seed 1, origin 0)
# rendered at native zoom and 1, 2 and 3 steps out (2048², 1024², 512², 256² images), scored with
# texq `streaks` (exemplar size scaled with the zoom). Prints a markdown table and the means.
# Usage: bench/zoom_streaks.sh [BIN, default target/release/textile]
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
BIN=${1:-target/release/textile}
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT
python3 -c "import numpy, scipy, PIL" 2>/dev/null || pip install -q numpy scipy pillow
streak() { python3 "$SHARED/tools/texq.py" streaks --image "$1" --exemplar-size "$2" --json |
  python3 -c 'import json,sys; d=json.load(sys.stdin); print("%.2f" % d["streak"])'; }
echo "| exemplar | native | z−1 | z−2 | z−3 |"
echo "|---|---|---|---|---|"
for f in "$SHARED"/exemplars/*.png; do
  name=$(basename "$f" .png)
  case "$name" in *_256|*_tile) continue ;; esac
  row="| $name"
  for k in 0 1 2 3; do
    side=$((2048 >> k))
    "$BIN" render --exemplar "$f" --z $((7 - k)) --window=0,0,$side,$side --seed 1 -o "$OUT/${name}_$k.png" >/dev/null
    row="$row | $(streak "$OUT/${name}_$k.png" $((128 >> k)))"
  done
  echo "$row |"
done | tee "$OUT/rows.md"
python3 - "$OUT/rows.md" <<'PY'
import sys
rows = [[float(c) for c in l.split('|')[2:6]] for l in open(sys.argv[1])]
means = [sum(r[i] for r in rows) / len(rows) for i in range(4)]
maxes = [max(r[i] for r in rows) for i in range(4)]
print("| mean | " + " | ".join("%.2f" % m for m in means) + " |")
print("| max | " + " | ".join("%.2f" % m for m in maxes) + " |")
PY
