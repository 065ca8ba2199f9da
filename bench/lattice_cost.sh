#!/usr/bin/env bash
# What structure detection adds to an exemplar's analysis (issue 69: at most 10 % for a 128²
# and a 256² exemplar): `textile analyze` prints detection's own time beside the analysis's;
# three runs each, the median. Usage: bench/lattice_cost.sh
set -euo pipefail
cd "$(dirname "$0")/.."
SHARED=${SHARED:-../shared}
cargo build --release -q -p textile-server
BIN=target/release/textile
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| exemplar | side | class | detection ms | analysis s | share |"
echo "|---|---|---|---|---|---|"
for ex in "$SHARED"/exemplars/{gravel,brick,smallstone,leaves}.png "$SHARED"/exemplars/{gravel,brick,granite}_256.png \
  "$SHARED"/exemplars/materials/{planks,cobblestones}/albedo.png; do
  det=(); ana=(); class=
  for _ in 1 2 3; do
    out=$("$BIN" analyze "$ex" -o "$tmp/a.tex")
    det+=("$(sed -n 's/^structure: .*(\([0-9]*\) ms)$/\1/p' <<<"$out")")
    ana+=("$(sed -n 's/^analysed .* in \([0-9.]*\)s .*/\1/p' <<<"$out")")
    class=$(sed -n 's/^structure: \([a-z]*\).*/\1/p' <<<"$out")
  done
  d=$(printf '%s\n' "${det[@]}" | sort -n | sed -n 2p)
  a=$(printf '%s\n' "${ana[@]}" | sort -n | sed -n 2p)
  side=$(python3 -c "from PIL import Image; print(Image.open('$ex').size[0])")
  name=${ex#"$SHARED"/exemplars/}
  echo "| $name | $side | $class | $d | $a | $(python3 -c "print(f'{$d / 1000 / $a * 100:.1f} %')") |"
done
