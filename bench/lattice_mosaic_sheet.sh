#!/usr/bin/env bash
# Mosaic before/after contact sheet for issue 70 (background tiles laid on the lattice): the
# near-regular exemplars rendered 512² at (40960, 40960) in mosaic, `--lattice auto`, by an
# older binary (OLD, e.g. one built from 7af9e42) and by this tree's, side by side, at native
# zoom. Writes docs/lattice/mosaic_sheet.jpg.
# Usage: bench/lattice_mosaic_sheet.sh OLD_BINARY   (after bench/lattice_auto.sh made the exemplars)
set -euo pipefail
cd "$(dirname "$0")/.."
OLD=${1:?usage: bench/lattice_mosaic_sheet.sh OLD_BINARY}
SHARED=${SHARED:-../shared}
M="$SHARED/exemplars/materials"
MADE=bench/out/lattice_auto/made
OUT=bench/out/lattice_mosaic && mkdir -p "$OUT"
cargo build --release -q -p textile-server
names=()
for pair in "brick:$SHARED/exemplars/brick.png" "cobblestones:$M/cobblestones/albedo.png" \
  "tread:$MADE/tread.png" "plank_floor:$MADE/planks.png" "bond:$MADE/bond.png"; do
  name=${pair%%:*}; ex=${pair#*:}
  side=$(python3 -c "from PIL import Image; print(Image.open('$ex').size[0])")
  z=$(python3 -c "import math; print(int(math.log2($side)))")
  for which in before after; do
    bin=target/release/textile; [ "$which" = before ] && bin=$OLD
    "$bin" render --exemplar "$ex" --mode mosaic --z "$z" --window=40960,40960,512,512 -o "$OUT/${name}_$which.png" >/dev/null
  done
  names+=("$name")
done
python3 - "$OUT" "${names[@]}" <<'PY'
import sys
from PIL import Image, ImageDraw
out, names = sys.argv[1], sys.argv[2:]
s = 384
sheet = Image.new('RGB', (2 * s + 30, len(names) * (s + 24) + 24), 'white')
d = ImageDraw.Draw(sheet)
d.text((10, 6), 'mosaic, lattice auto: before (7af9e42) | after (background tiles on the lattice)', fill='black')
for i, n in enumerate(names):
    y = 24 + i * (s + 24)
    d.text((10, y), n, fill='black')
    for j, w in enumerate(['before', 'after']):
        im = Image.open(f'{out}/{n}_{w}.png').convert('RGB').resize((s, s), Image.LANCZOS)
        sheet.paste(im, (10 + j * (s + 10), y + 14))
sheet.save('docs/lattice/mosaic_sheet.jpg', quality=85)
PY
echo docs/lattice/mosaic_sheet.jpg
