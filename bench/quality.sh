#!/usr/bin/env bash
# Quality benchmark (issue: core engine). Synthesizes 512×512 from each development exemplar
# (../shared/exemplars/NAME.png, 128×128) with four settings — default parameters, correction
# off, plain tiling (mode=tiling), and the cheap chaos-mosaic mode — scores them with ../shared/tools/texq.py and writes
#   bench/out/quality/scores.md     the texq table (one block per setting, mean rows)
#   docs/contact-sheet.png          exemplar beside the default output, for every exemplar
# Usage: bench/quality.sh [extra render args, e.g. --seed 3]
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
python3 bench/contact_sheet.py "$OUT/exemplars" "$OUT/default" docs/contact-sheet.png
cat "$OUT/scores.md"
