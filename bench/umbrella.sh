#!/usr/bin/env bash
# Umbrella mode (issue 15): 512² outputs of the element-like development exemplars (leaves,
# smallstone, gravel, granite) with mode=umbrella, synth and mosaic, scored by texq; texq
# `streak` of 2048² umbrella renders; the storage table (cargo bench --bench umbrella_storage);
# docs/umbrella.jpg: per exemplar, the extraction sheet (bases with rims and centres, then
# modified umbrellas) beside a 256² output; docs/umbrella_lod.jpg: the built-in gravel one and
# two steps out (merged levels of detail, bottom) under its native render box-filtered to the
# same scale (top).
#   bench/out/umbrella/scores.md, bench/out/umbrella/streaks.md
# Usage: bench/umbrella.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
if [ ! -d "$SHARED/exemplars" ] || [ ! -f "$SHARED/tools/texq.py" ]; then
  echo "bench/umbrella.sh: needs the development set and texq.py in $SHARED (set SHARED=DIR); not found" >&2
  exit 1
fi
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
BIN=${BIN:-target/release/textile}
OUT=bench/out/umbrella
rm -rf "$OUT" && mkdir -p "$OUT"/{exemplars,umbrella,synth,mosaic,big,sheets}
NAMES="leaves smallstone gravel granite"
for name in $NAMES; do
  f="$SHARED/exemplars/$name.png"
  cp "$f" "$OUT/exemplars/"
  for mode in umbrella synth mosaic; do
    "$BIN" render --exemplar "$f" --window=4096,-8192,512,512 --mode "$mode" --seed 1 -o "$OUT/$mode/$name.png" >/dev/null
  done
  "$BIN" render --exemplar "$f" --window=0,0,2048,2048 --mode umbrella --seed 1 -o "$OUT/big/$name.png" >/dev/null
  "$BIN" render --exemplar "$f" --mode umbrella --debug-umbrellas -o "$OUT/sheets/$name.png"
done
python3 "$SHARED/tools/texq.py" table --exemplar-dir "$OUT/exemplars" \
  --output-dir "$OUT/umbrella" "$OUT/synth" "$OUT/mosaic" > "$OUT/scores.md"
echo "| exemplar | streak (2048², umbrella) |" > "$OUT/streaks.md"
echo "|---|---|" >> "$OUT/streaks.md"
for name in $NAMES; do
  s=$(python3 "$SHARED/tools/texq.py" streaks --image "$OUT/big/$name.png" --exemplar-size 128 --json |
    python3 -c 'import json,sys; print("%.2f" % json.load(sys.stdin)["streak"])')
  echo "| $name | $s |" >> "$OUT/streaks.md"
done
cargo bench -q -p textile-core --bench umbrella_storage 2>/dev/null | grep -E '^\||^\(v' > "$OUT/storage.md" || true
python3 - "$OUT" $NAMES <<'PY'
import sys
from PIL import Image
out, names = sys.argv[1], sys.argv[2:]
rows = []
for n in names:
    sheet = Image.open(f"{out}/sheets/{n}.png").convert("RGB")
    ex = Image.open(f"{out}/exemplars/{n}.png").convert("RGB")
    res = Image.open(f"{out}/umbrella/{n}.png").convert("RGB").crop((0, 0, 256, 256))
    h = max(sheet.height, 256)
    row = Image.new("RGB", (128 + 8 + sheet.width + 8 + 256, h), (255, 255, 255))
    row.paste(ex, (0, 0)); row.paste(sheet, (136, 0)); row.paste(res, (136 + sheet.width + 8, 0))
    rows.append(row)
w = max(r.width for r in rows)
sheet = Image.new("RGB", (w, sum(r.height + 8 for r in rows)), (255, 255, 255))
y = 0
for r in rows:
    sheet.paste(r, (0, y)); y += r.height + 8
sheet.save("docs/umbrella.jpg", quality=85)
PY
cat "$OUT/scores.md" "$OUT/streaks.md" "$OUT/storage.md"

# Levels of detail: the same 1024² texels of the built-in gravel (native zoom 7) at zoom-out 1
# and 2, against the native render box-filtered.
"$BIN" render --texture gravel --mode umbrella --z 7 --window=0,0,1024,1024 -o "$OUT/lod_native.png" >/dev/null
"$BIN" render --texture gravel --mode umbrella --z 6 --window=0,0,512,512 -o "$OUT/lod_1.png" >/dev/null
"$BIN" render --texture gravel --mode umbrella --z 5 --window=0,0,256,256 -o "$OUT/lod_2.png" >/dev/null
python3 - "$OUT" <<'PY'
import sys
from PIL import Image, ImageChops, ImageStat
out = sys.argv[1]
native = Image.open(f"{out}/lod_native.png").convert("RGB")
one, two = (Image.open(f"{out}/lod_{k}.png").convert("RGB") for k in (1, 2))
ref1, ref2 = native.resize((512, 512), Image.BOX), native.resize((256, 256), Image.BOX)
for k, (a, b) in enumerate([(one, ref1), (two, ref2)], 1):
    print(f"zoom-out {k}: mean |merged − native box-filtered| {ImageStat.Stat(ImageChops.difference(a, b)).mean[0]:.2f}")
# Shown at 512² each: zoom-out 1 as is, zoom-out 2 enlarged 2× (nearest).
sheet = Image.new("RGB", (512 * 2 + 8, 512 * 2 + 8), (255, 255, 255))
sheet.paste(ref1, (0, 0)); sheet.paste(ref2.resize((512, 512), Image.NEAREST), (520, 0))
sheet.paste(one, (0, 520)); sheet.paste(two.resize((512, 512), Image.NEAREST), (520, 520))
sheet.save("docs/umbrella_lod.jpg", quality=85)
PY
