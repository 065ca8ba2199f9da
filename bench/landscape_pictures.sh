#!/usr/bin/env bash
# Pictures of a landscape's blends (issue 82): the worked garden (docs/landscape/garden.toml: a
# painted splat of grass, a gravel path and flagstone terraces) by height and by linear blending,
# at native zoom (a 384 × 256 crop across the path) and zoomed out 2 steps (the whole 768 × 512
# texel splat and its repeats). Writes bench/out/landscape_blends.png, and docs/landscape.png
# (the README's contact sheet).
set -euo pipefail
cd "$(dirname "$0")/.."
. bench/server.sh
CFG=$(mktemp -d)
cp docs/landscape/splat.png "$CFG/"
{ cat docs/landscape/garden.toml
  sed -n '/^\[\[landscapes\]\]/,$p' docs/landscape/garden.toml \
    | sed 's/^id = "garden"/id = "garden_linear"/; s/^name = "Garden"/name = "Garden (linear)"/; s/^kind = "height"/kind = "linear"/'
} > "$CFG/garden.toml"
start_server --config "$CFG/garden.toml"
mkdir -p bench/out
for id in garden garden_linear; do
  curl -sf -o "$CFG/$id-native.png" "$URL/windows/$id.png?z=7&x=192&y=0&w=384&h=256"
  curl -sf -o "$CFG/$id-out.png" "$URL/windows/$id.png?z=5&x=-96&y=-64&w=384&h=256"
done
curl -sf -o "$CFG/splat-out.png" "$URL/windows/garden.png?z=5&x=-96&y=-64&w=384&h=256&map=splat"
python3 - "$CFG" <<'PY'
import sys
from PIL import Image, ImageDraw
d = sys.argv[1]
cells = [["garden-native", "garden-out"], ["garden_linear-native", "garden_linear-out"]]
sheet = Image.new("RGB", (2 * 384 + 3 * 8, 3 * 256 + 4 * 8 + 3 * 18), "white")
draw = ImageDraw.Draw(sheet)
labels = [["height blend, native zoom", "height blend, 2 zooms out"], ["linear blend, native zoom", "linear blend, 2 zooms out"]]
for r, row in enumerate(cells):
    for c, name in enumerate(row):
        x, y = 8 + c * (384 + 8), 8 + r * (256 + 8 + 18)
        draw.text((x, y), labels[r][c], fill="black")
        sheet.paste(Image.open(f"{d}/{name}.png").convert("RGB"), (x, y + 18))
y = 8 + 2 * (256 + 8 + 18)
draw.text((8, y), "the painted splat (map=splat), 2 zooms out", fill="black")
sheet.paste(Image.open(f"{d}/splat-out.png").convert("RGB"), (8, y + 18))
sheet.save("bench/out/landscape_blends.png")
sheet.save("docs/landscape.png", optimize=True)
print("wrote bench/out/landscape_blends.png and docs/landscape.png")
PY
rm -rf "$CFG"
