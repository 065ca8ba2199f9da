#!/usr/bin/env bash
# `textile tileable` over the development exemplars: time, texq scores of the output against its
# exemplar, and the seams of a 2×2 tiling of the output (≈ 1: seamless). Optionally the
# exhaustive search for comparison (EXACT="gravel brick").
#   bench/tileable.sh [SIZE] [OUT_DIR]      (needs ../shared/exemplars and ../shared/tools/texq.py)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SIZE=${1:-256}
OUT=${2:-$ROOT/target/bench-tileable}
EX=${EXEMPLARS:-$ROOT/../shared/exemplars}
TEXQ=${TEXQ:-$ROOT/../shared/tools/texq.py}
BIN=${BIN:-$ROOT/target/release/textile}
[ -x "$BIN" ] || (cd "$ROOT" && cargo build --release -p textile-server)
mkdir -p "$OUT/tsvq" "$OUT/exact"
tile2x2() {
  python3 - "$1" "$2" <<'PY'
import sys
from PIL import Image
im = Image.open(sys.argv[1]); w, h = im.size
big = Image.new("RGB", (2 * w, 2 * h))
for i in range(2):
    for j in range(2):
        big.paste(im, (i * w, j * h))
big.save(sys.argv[2])
PY
}
row() { # name kind file seconds
  local s seams
  s=$(python3 "$TEXQ" score --exemplar "$EX/$1.png" --output "$3" --json)
  tile2x2 "$3" "$3.2x2.png"
  seams=$(python3 "$TEXQ" seams --image "$3.2x2.png" --tile "$SIZE" | awk '/^ratio /{print $2}')
  python3 -c "
import json,sys
s=json.loads(sys.argv[1]); n=lambda k: s[k] if not isinstance(s[k], dict) else s[k].get('value')
print(f\"| $1 | $2 | $4 | {s['nn_err']:.4f} | {s['nn_ref']:.4f} | {s['swd']:.4f} | {s['period']:.3f} | {s['copy_frac']:.3f} | {s['grad']:.4f} | $seams |\")" "$s"
}
echo "| exemplar | search | seconds | nn_err | nn_ref | swd | period | copy_frac | grad | seams 2×2 |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for f in "$EX"/*.png; do
  name=$(basename "$f" .png)
  case "$name" in *_256|*_tile) continue ;; esac
  t0=$(date +%s.%N)
  "$BIN" tileable "$f" --size "$SIZE" --seed 1 -o "$OUT/tsvq/$name.png" > /dev/null 2>&1
  t=$(python3 -c "print(f'{$(date +%s.%N) - $t0:.2f}')")
  row "$name" "TSVQ B=8" "$OUT/tsvq/$name.png" "$t"
done
for name in ${EXACT:-}; do
  t0=$(date +%s.%N)
  "$BIN" tileable "$EX/$name.png" --size "$SIZE" --seed 1 --exact -o "$OUT/exact/$name.png" > /dev/null 2>&1
  t=$(python3 -c "print(f'{$(date +%s.%N) - $t0:.2f}')")
  row "$name" "exhaustive" "$OUT/exact/$name.png" "$t"
done
