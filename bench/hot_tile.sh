#!/usr/bin/env bash
# Cached hot-tile throughput of two textile binaries side by side (issue 71 item 2): both serve
# the default configuration on loopback, the tile is fetched once (cold) then hammered by
# `wrk -t2 -c64 -d5s` in alternating rounds (A, B, A, B, ...), and each round's requests/s and
# the tile's size are printed, then the median of each. Needs wrk (Debian: apt-get install wrk).
#
# usage: bench/hot_tile.sh OLD_BINARY NEW_BINARY [ROUNDS=4] [TILE=/tiles/gravel/7/1/1.png]
set -euo pipefail
OLD=$1
NEW=$2
ROUNDS=${3:-4}
TILE=${4:-/tiles/gravel/7/1/1.png}
WORK=$(mktemp -d)
PIDS=()
trap 'kill "${PIDS[@]}" 2>/dev/null; rm -rf "$WORK"' EXIT

. "$(dirname "$0")/server.sh"
serve_binary "$OLD" "$WORK/old"
PIDS+=("$PID")
URL_OLD=$URL
serve_binary "$NEW" "$WORK/new"
PIDS+=("$PID")
URL_NEW=$URL
for u in "$URL_OLD" "$URL_NEW"; do
  curl -s -o /dev/null "$u$TILE"
done
echo "tile $TILE: old $(curl -s "$URL_OLD$TILE" | wc -c) bytes, new $(curl -s "$URL_NEW$TILE" | wc -c) bytes"
echo "| round | old req/s | new req/s | new/old |"
echo "|---|---|---|---|"
old_all=()
new_all=()
for r in $(seq 1 "$ROUNDS"); do
  o=$(wrk -t2 -c64 -d5s "$URL_OLD$TILE" | awk '/Requests\/sec/ {print $2}')
  n=$(wrk -t2 -c64 -d5s "$URL_NEW$TILE" | awk '/Requests\/sec/ {print $2}')
  old_all+=("$o")
  new_all+=("$n")
  echo "| $r | $o | $n | $(python3 -c "print(f'{$n/$o:.3f}')") |"
done
python3 - "${old_all[*]}" "${new_all[*]}" <<'EOF'
import statistics, sys
o = [float(v) for v in sys.argv[1].split()]
n = [float(v) for v in sys.argv[2].split()]
mo, mn = statistics.median(o), statistics.median(n)
print(f"median: old {mo:.0f} req/s, new {mn:.0f} req/s, new/old {mn / mo:.3f}")
EOF
