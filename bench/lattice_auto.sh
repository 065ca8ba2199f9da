#!/usr/bin/env bash
# Detected lattices (issue 60): detection on every development-set and shared-materials exemplar
# (found or none, and its time), then the near-regular ones — the materials' planks and
# cobblestones, the development set's brick, and four made in code (bench/lattice_exemplars.py:
# square tiles, a grating, a running bond, a plank floor of spacing 42.67) — rendered 512² far
# from the origin with `textile render --exemplar`, synth and mosaic, with the detected lattice
# (`auto`, native zoom and one zoom out) and without (`none`, what every mode did before), and
# scored with texq (lattice, nn_err, nn_ref, copy_frac, edges; one zoom out against the
# exemplar box-halved). Writes bench/out/lattice_auto/{detect.txt,scores.md} and the renders.
# Usage: bench/lattice_auto.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
if [ ! -f "$SHARED/tools/texq.py" ]; then
  echo "bench/lattice_auto.sh: needs texq.py in $SHARED/tools (set SHARED=DIR); not found" >&2
  exit 1
fi
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
cargo build --release -q -p textile-core --example lattice_detect
BIN=target/release/textile
OUT=bench/out/lattice_auto
rm -rf "$OUT" && mkdir -p "$OUT/made"
python3 bench/lattice_exemplars.py "$SHARED" "$OUT/made"
target/release/examples/lattice_detect "$SHARED"/exemplars/*.png "$SHARED"/exemplars/materials/*/albedo.png \
  "$OUT"/made/*.png | tee "$OUT/detect.txt"
score() { # EXEMPLAR OUTPUT
  python3 "$SHARED/tools/texq.py" score --exemplar "$1" --output "$2" --json 2>/dev/null | python3 -c '
import json, sys
d = json.load(sys.stdin)
print(" | ".join(f"{d[k]:.3f}" for k in ["lattice", "nn_err", "nn_ref", "copy_frac", "edges"]))'
}
M="$SHARED/exemplars/materials"
echo "| exemplar | mode | lattice | zoom | texq lattice | nn_err | nn_ref | copy_frac | edges |" > "$OUT/scores.md"
echo "|---|---|---|---|---|---|---|---|---|" >> "$OUT/scores.md"
for pair in "planks:$M/planks/albedo.png" "cobblestones:$M/cobblestones/albedo.png" \
  "brick:$SHARED/exemplars/brick.png" "tiles:$OUT/made/tiles.png" "grating:$OUT/made/grating.png" \
  "bond:$OUT/made/bond.png" "plank floor:$OUT/made/planks.png" "tread:$OUT/made/tread.png" \
  "brick 256:$SHARED/exemplars/brick_256.png"; do
  name=${pair%%:*}; ex=${pair#*:}
  side=$(python3 -c "from PIL import Image; print(Image.open('$ex').size[0])")
  native=$(python3 -c "import math; print(int(math.log2($side)))")
  half="$OUT/${name// /_}_half.png"
  python3 -c "from PIL import Image; im = Image.open('$ex').convert('RGB'); im.resize((im.width // 2, im.height // 2), Image.BOX).save('$half')"
  for mode in synth mosaic; do
    for run in "auto 0" "auto 1" "none 0"; do
      set -- $run
      img="$OUT/${name// /_}_${mode}_$1_z$2.png"
      "$BIN" render --exemplar "$ex" --lattice "$1" --mode "$mode" --z $((native - $2)) \
        "--window=$((40960 >> $2)),$((40960 >> $2)),512,512" -o "$img" >/dev/null
      ref=$ex; [ "$2" = 1 ] && ref=$half
      echo "| $name | $mode | $1 | native−$2 | $(score "$ref" "$img") |" >> "$OUT/scores.md"
    done
  done
done
cat "$OUT/scores.md"
