#!/usr/bin/env bash
# Quality benchmark. Synthesizes 512×512 from each development exemplar
# (../shared/exemplars/NAME.png, 128×128) with four settings — default parameters, correction
# off, plain tiling (mode=tiling), and the cheap chaos-mosaic mode — scores them with
# ../shared/tools/texq.py; renders 2048×2048 (default and correction off, seeds 1 and 2 at
# far-apart origins) and the same areas zoomed out one step (1024×1024) for texq `streaks`; writes
#   bench/out/quality/scores.md     the texq table (one block per setting, mean rows)
#   bench/out/quality/streaks.md    streak per exemplar: default and correction off, native and z−1
#   docs/contact-sheet.png          exemplar, default output, and a 2048² render zoomed out
#   docs/seams-before-after.png     with BEFORE=BINARY (a textile built from the code before):
#                                   slime, bark and brick rendered by both, side by side
# texq's table has an `edges` column: hard edges the exemplar lacks (patch seams).
# Usage: [BEFORE=BINARY] bench/quality.sh [extra render args, e.g. --seed 3]
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
if [ ! -d "$SHARED/exemplars" ] || [ ! -f "$SHARED/tools/texq.py" ]; then
  echo "bench/quality.sh: needs the development set and texq.py in $SHARED (set SHARED=DIR); not found" >&2
  exit 1
fi
OUT=bench/out/quality
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
BIN=target/release/textile
rm -rf "$OUT" && mkdir -p "$OUT"/{exemplars,default,no_correction,tiling,mosaic}
WIN=--window=4096,-8192,512,512
for f in "$SHARED"/exemplars/*.png; do
  name=$(basename "$f" .png)
  case "$name" in *_256|*_tile) continue ;; esac
  cp "$f" "$OUT/exemplars/"
  "$BIN" render --exemplar "$f" "$WIN" "$@" -o "$OUT/default/$name.png" >/dev/null
  "$BIN" render --exemplar "$f" "$WIN" --param passes=0 "$@" -o "$OUT/no_correction/$name.png" >/dev/null
  "$BIN" render --exemplar "$f" "$WIN" --mode tiling -o "$OUT/tiling/$name.png" >/dev/null
  "$BIN" render --exemplar "$f" "$WIN" --mode mosaic "$@" -o "$OUT/mosaic/$name.png" >/dev/null
done
python3 "$SHARED/tools/texq.py" table --exemplar-dir "$OUT/exemplars" \
  --output-dir "$OUT/default" "$OUT/no_correction" "$OUT/tiling" "$OUT/mosaic" > "$OUT/scores.md"

# Large-scale regularity: 2048² at native zoom and the same area at z = native − 1 (1024²).
streak() { python3 "$SHARED/tools/texq.py" streaks --image "$1" --exemplar-size "$2" --json |
  python3 -c 'import json,sys; d=json.load(sys.stdin); print("%.2f" % d["streak"])'; }
mkdir -p "$OUT/big" "$OUT/big_z" "$OUT/big_p0"
echo "| exemplar | seed 1 | seed 2 | seed 1, z−1 | seed 2, z−1 | correction off |" > "$OUT/streaks.md"
echo "|---|---|---|---|---|---|" >> "$OUT/streaks.md"
for f in "$SHARED"/exemplars/*.png; do
  name=$(basename "$f" .png)
  case "$name" in *_256|*_tile) continue ;; esac
  row="| $name"
  for s in 1 2; do
    origin=$(( s == 1 ? 0 : 1 << 20 ))
    "$BIN" render --exemplar "$f" --window=$origin,$origin,2048,2048 --seed $s -o "$OUT/big/${name}_$s.png" >/dev/null
    row="$row | $(streak "$OUT/big/${name}_$s.png" 128)"
  done
  for s in 1 2; do
    origin=$(( s == 1 ? 0 : 1 << 19 ))
    "$BIN" render --exemplar "$f" --z 6 --window=$origin,$origin,1024,1024 --seed $s -o "$OUT/big_z/${name}_$s.png" >/dev/null
    row="$row | $(streak "$OUT/big_z/${name}_$s.png" 64)"
  done
  "$BIN" render --exemplar "$f" --window=0,0,2048,2048 --seed 1 -p passes=0 -o "$OUT/big_p0/$name.png" >/dev/null
  cp "$OUT/big/${name}_1.png" "$OUT/big/$name.png"
  echo "$row | $(streak "$OUT/big_p0/$name.png" 128) |" >> "$OUT/streaks.md"
done
python3 bench/contact_sheet.py "$OUT/exemplars" "$OUT/default" "$OUT/big" docs/contact-sheet.png
if [ -n "${BEFORE:-}" ]; then
  mkdir -p "$OUT/before"
  for name in slime bark brick; do
    "$BEFORE" render --exemplar "$SHARED/exemplars/$name.png" "$WIN" "$@" -o "$OUT/before/$name.png" >/dev/null
  done
  python3 bench/before_after.py "$OUT/exemplars" "$OUT/before" "$OUT/default" docs/seams-before-after.png slime bark brick
fi
cat "$OUT/scores.md" "$OUT/streaks.md"
