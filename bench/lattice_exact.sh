#!/usr/bin/env bash
# Exact repeats (issue 69): what refusing a texel's copies as its second coherence candidate
# does to the exemplars that are a tile repeated — the development set's granite, leaves,
# smallstone, bark and corkboard crops, slime_256, the planks material — and the embedded
# corkboard: its configured cells [2, 4] (where the held grid is all copies, the phase wins)
# against `auto` (exact, no lattice held), in the before/after columns of its row. Each rendered 512² by synth far from the origin at native zoom and
# one zoom out, `--lattice none` (what textile did before: no detection, byte for byte) and
# `auto`, scored with texq (nn_err, swd, copy_frac, edges; one zoom out against the exemplar
# box-halved); then a contact sheet per zoom, before | after, one row per exemplar.
# Writes bench/out/lattice_exact/{scores.md,sheet_z0.png,sheet_z1.png} and the renders.
# Usage: bench/lattice_exact.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
python3 -c 'import numpy, scipy, PIL' 2>/dev/null || pip install -q numpy scipy pillow
cargo build --release -q -p textile-server
BIN=target/release/textile
OUT=bench/out/lattice_exact
rm -rf "$OUT" && mkdir -p "$OUT"
E="$SHARED/exemplars"
score() { # EXEMPLAR OUTPUT
  python3 "$SHARED/tools/texq.py" score --exemplar "$1" --output "$2" --json 2>/dev/null | python3 -c '
import json, sys
d = json.load(sys.stdin)
print(" | ".join(f"{d[k]:.3f}" for k in ["nn_err", "swd", "copy_frac", "edges"]))'
}
echo "| exemplar | zoom | before: nn_err | swd | copy_frac | edges | after: nn_err | swd | copy_frac | edges |" > "$OUT/scores.md"
echo "|---|---|---|---|---|---|---|---|---|---|" >> "$OUT/scores.md"
rows=()
for pair in "granite:$E/granite.png:" "leaves:$E/leaves.png:" "smallstone:$E/smallstone.png:" \
  "bark:$E/bark.png:" "corkboard:$E/corkboard.png:" "slime_256:$E/slime_256.png:" \
  "planks:$E/materials/planks/albedo.png:" "corkboard [2,4]:config/exemplars/corkboard.png:2,4"; do
  IFS=: read -r name ex given <<<"$pair"
  file=${name//[^a-z0-9_]/_}
  half="$OUT/${file}_half.png"
  python3 -c "from PIL import Image; im = Image.open('$ex').convert('RGB'); im.resize((im.width // 2, im.height // 2), Image.BOX).save('$half')"
  side=$(python3 -c "from PIL import Image; print(Image.open('$ex').size[0])")
  native=$(python3 -c "import math; print(int(math.log2($side)))")
  for z in 0 1; do
    line="| $name | native−$z"
    for when in before after; do
      lattice=none; [ "$when" = after ] && lattice=auto
      # The configured corkboard: its cells [2, 4] (left) against `auto` (right).
      if [ -n "$given" ] && [ "$when" = before ]; then lattice=$given; fi
      img="$OUT/${file}_${when}_z$z.png"
      "$BIN" render --exemplar "$ex" --lattice "$lattice" --mode synth --z $((native - z)) \
        "--window=$((40960 >> z)),$((40960 >> z)),512,512" -o "$img" >/dev/null
      ref=$ex; [ "$z" = 1 ] && ref=$half
      line="$line | $(score "$ref" "$img")"
    done
    echo "$line |" >> "$OUT/scores.md"
  done
  rows+=("$file")
done
python3 - "$OUT" "${rows[@]}" <<'PY'
import sys
from PIL import Image, ImageDraw
out, rows = sys.argv[1], sys.argv[2:]
for z in (0, 1):
    sheet = Image.new("RGB", (2 * 512 + 30, len(rows) * 532 + 10), "white")
    d = ImageDraw.Draw(sheet)
    for i, r in enumerate(rows):
        for j, when in enumerate(("before", "after")):
            sheet.paste(Image.open(f"{out}/{r}_{when}_z{z}.png").convert("RGB"), (10 + j * 522, 10 + i * 532))
        label = "lattice [2, 4] | auto" if r.startswith("corkboard__2") else "before (no detection) | after (copies not candidates)"
        d.text((14, 12 + i * 532), f"{r}: {label}", fill="red")
    sheet.save(f"{out}/sheet_z{z}.png")
PY
cat "$OUT/scores.md"
