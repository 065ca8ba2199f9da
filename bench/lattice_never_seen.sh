#!/usr/bin/env bash
# Structure on materials never seen (issue 80): detection on every image of the development set,
# the shared materials and the lattices set (bench/out/lattice_never_seen/detect.txt), then the
# eight regular materials of the lattices set rendered 512² far from the origin with
# `textile render --exemplar`, synth and mosaic, with the detected lattice (`auto`) and without
# (`none`), and the exemplar tiled 2×2 (what a repeat would give), each scored with texq against
# the exemplar: lattice, nn_err, nn_ref, edges. Writes bench/out/lattice_never_seen/scores.md.
# Usage: bench/lattice_never_seen.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
if [ ! -f "$SHARED/tools/texq.py" ]; then
  echo "bench/lattice_never_seen.sh: needs texq.py in $SHARED/tools (set SHARED=DIR); not found" >&2
  exit 1
fi
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
cargo build --release -q -p textile-core --example lattice_detect
BIN=target/release/textile
OUT=bench/out/lattice_never_seen
L="$SHARED/exemplars/lattices"
rm -rf "$OUT" && mkdir -p "$OUT"
target/release/examples/lattice_detect "$L"/*/albedo.png "$SHARED"/exemplars/*.png \
  "$SHARED"/exemplars/materials/*/albedo.png | tee "$OUT/detect.txt"
score() { # EXEMPLAR OUTPUT
  python3 "$SHARED/tools/texq.py" score --exemplar "$1" --output "$2" --json 2>/dev/null | python3 -c '
import json, sys
d = json.load(sys.stdin)
print(" | ".join(f"{d[k]:.3f}" for k in ["lattice", "nn_err", "nn_ref", "edges"]))'
}
echo "| material | what | texq lattice | nn_err | nn_ref | edges |" > "$OUT/scores.md"
echo "|---|---|---|---|---|---|" >> "$OUT/scores.md"
for name in brick_red stone_bricks planks roof_tiles tread_plate metal_tiles hex_tiles concrete_formwork; do
  ex="$L/$name/albedo.png"
  tiled="$OUT/${name}_tiled.png"
  python3 -c "
from PIL import Image
im = Image.open('$ex').convert('RGB'); w, h = im.size
out = Image.new('RGB', (2 * w, 2 * h))
for i in range(2):
    for j in range(2):
        out.paste(im, (i * w, j * h))
out.save('$tiled')"
  echo "| $name | tiled 2×2 | $(score "$ex" "$tiled") |" >> "$OUT/scores.md"
  for mode in synth mosaic; do
    for lattice in auto none; do
      img="$OUT/${name}_${mode}_${lattice}.png"
      "$BIN" render --exemplar "$ex" --lattice "$lattice" --mode "$mode" \
        "--window=40960,40960,512,512" -o "$img" >/dev/null
      echo "| $name | $mode $lattice | $(score "$ex" "$img") |" >> "$OUT/scores.md"
    done
  done
done
cat "$OUT/scores.md"
