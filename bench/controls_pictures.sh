#!/usr/bin/env bash
# Pictures of synth's request controls (issue 14), rendered by `textile render --controls` on the
# built-in gravel, the same 384² window each time (seed 1), the controls outlined over the
# second copy of each (features yellow, calm strokes blue, wild ones red):
#   docs/controls.jpg   exemplar (feature source marked) · none · noise modulation (scale 128,
#                       range 0–1) · painted strokes (a calm disc, wild discs) · three features
#                       (the exemplar around its centre dropped at three places)
# Usage: bench/controls_pictures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -c 'import PIL' 2>/dev/null || pip install -q pillow
cargo build --release -q -p textile-server
BIN=${BIN:-target/release/textile}
OUT=bench/out/controls
rm -rf "$OUT" && mkdir -p "$OUT"
WIN=--window=0,0,384,384
echo '{}' > "$OUT/none.json"
echo '{"noise": {"scale": 128, "range": [0, 1]}}' > "$OUT/noise.json"
echo '{"strokes": [{"at": [120, 130], "radius": 70, "soft": 30, "value": 0},
  {"at": [300, 40], "radius": 30, "soft": 10, "value": 1}, {"at": [300, 200], "radius": 30, "soft": 10, "value": 1},
  {"at": [300, 330], "radius": 30, "soft": 10, "value": 1}]}' > "$OUT/strokes.json"
echo '{"features": [{"at": [90, 90], "source": [64, 64], "inner": 24, "outer": 72},
  {"at": [290, 120], "source": [64, 64], "inner": 24, "outer": 72},
  {"at": [180, 300], "source": [64, 64], "inner": 24, "outer": 72}]}' > "$OUT/features.json"
for c in none noise strokes features; do
  args=()
  [ "$c" != none ] && args=(--controls "$OUT/$c.json")
  "$BIN" render --texture gravel "$WIN" --seed 1 "${args[@]}" -o "$OUT/$c.png" >/dev/null
done
python3 - "$OUT" config/exemplars/gravel.png docs/controls.jpg <<'PY'
import json, sys
from PIL import Image, ImageDraw
out, exemplar, dest = sys.argv[1:]
names = ["none", "noise", "strokes", "features"]
S, G, T = 384, 8, 22
sheet = Image.new("RGB", (5 * S + 4 * G, 2 * S + G + T), "white")
d = ImageDraw.Draw(sheet)
ex = Image.open(exemplar).convert("RGB").resize((256, 256), Image.NEAREST)
ImageDraw.Draw(ex).ellipse((128 - 48, 128 - 48, 128 + 48, 128 + 48), outline=(255, 230, 0), width=2)
sheet.paste(ex, ((S - 256) // 2, T + (S - 256) // 2))
d.text((4, 4), "exemplar (x2), feature source", fill="black")
for i, n in enumerate(names, start=1):
    img = Image.open(f"{out}/{n}.png").convert("RGB")
    x = i * (S + G)
    sheet.paste(img, (x, T))
    ann = img.copy()
    a = ImageDraw.Draw(ann)
    c = json.load(open(f"{out}/{n}.json"))
    for s in c.get("strokes", []):
        (cx, cy), r = s["at"], s["radius"] + s["soft"] / 2
        a.ellipse((cx - r, cy - r, cx + r, cy + r), outline=(40, 90, 255) if s["value"] < 0.5 else (255, 40, 40), width=2)
    for f in c.get("features", []):
        (cx, cy), r = f["at"], f["inner"]
        a.ellipse((cx - r, cy - r, cx + r, cy + r), outline=(255, 230, 0), width=2)
    sheet.paste(ann, (x, T + S + G))
    d.text((x + 4, 4), n, fill="black")
sheet.save(dest, quality=85)
PY
echo "wrote docs/controls.jpg"
