#!/usr/bin/env bash
# Near-regular textures (issue 14): renders the embedded, rectified corkboard (2×4 lattice cells
# of 64×32 texels) at 2048² with its lattice and without (same exemplar, seeds 1 and 2 at
# far-apart origins), and the default-config texture's native zoom − 1 (1024²), and writes
#   bench/out/lattice/lattice.md   autocorrelation at the lattice vectors, texq streak, and the
#                                  streak statistic outside the lattice's frequencies
#   docs/lattice_corkboard.png     exemplar, with lattice, without (512² crops, native scale ×1)
# Usage: bench/lattice.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
if [ ! -f "$SHARED/tools/texq.py" ]; then
  echo "bench/lattice.sh: needs texq.py in $SHARED/tools (set SHARED=DIR); not found" >&2
  exit 1
fi
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
BIN=target/release/textile
OUT=bench/out/lattice
rm -rf "$OUT" && mkdir -p "$OUT"
EX=config/exemplars/corkboard.png
echo "| render | autocorr (64, 0) | autocorr (0, 32) | autocorr (32, 0) | streak | streak outside the lattice |" > "$OUT/lattice.md"
echo "|---|---|---|---|---|---|" >> "$OUT/lattice.md"
for seed in 1 2; do
  origin=$(( (seed - 1) * 40960 ))
  for variant in lattice none; do
    flags=()
    [ "$variant" = lattice ] && flags=(--lattice 2,4)
    img="$OUT/${variant}_$seed.png"
    "$BIN" render --exemplar "$EX" "${flags[@]}" --seed "$seed" "--window=$origin,$origin,2048,2048" -o "$img" >/dev/null
    echo "| $variant, seed $seed | $(python3 bench/lattice_row.py "$SHARED/tools" "$img" 64 32 128) |" >> "$OUT/lattice.md"
  done
done
# Zoomed out one step (z = native − 1), lattice: the grid at half scale (cells 32×16).
"$BIN" render --exemplar "$EX" --lattice 2,4 --seed 1 --z 6 --window=0,0,1024,1024 -o "$OUT/lattice_z6.png" >/dev/null
echo "| lattice, seed 1, z−1 (1024²; cells 32×16) | $(python3 bench/lattice_row.py "$SHARED/tools" "$OUT/lattice_z6.png" 32 16 64) |" >> "$OUT/lattice.md"
python3 - "$EX" "$OUT/lattice_1.png" "$OUT/none_1.png" docs/lattice_corkboard.png <<'PY'
import sys
from PIL import Image
ex, lat, none, out = sys.argv[1:]
tiles = [Image.open(ex).convert("RGB").resize((512, 512), Image.NEAREST)]
tiles += [Image.open(p).convert("RGB").crop((0, 0, 512, 512)) for p in (lat, none)]
sheet = Image.new("RGB", (3 * 512 + 2 * 8, 512), "white")
for i, t in enumerate(tiles):
    sheet.paste(t, (i * 520, 0))
sheet.save(out, optimize=True)
PY
cat "$OUT/lattice.md"
