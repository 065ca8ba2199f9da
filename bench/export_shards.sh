#!/usr/bin/env bash
# Sharded export (issue 63): throughput of N local processes with one worker each against one
# process with one worker, and the merge's speed. One data directory, analysed first, so that
# every process only reads its analysis.
#
# usage: bench/export_shards.sh [WORLD=32] [N=2]   (N up to the core count)
set -euo pipefail
WORLD=${1:-32}
N=${2:-2}
cargo build --release -q -p textile-server
BIN=$PWD/target/release/textile
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
# Analyse once (an export of the smallest world).
"$BIN" export --texture gravel --world 1 --data-dir "$WORK/data" -o "$WORK/warm.pmtiles" > /dev/null 2>&1
secs() { python3 -c "import time; print(time.time())"; }

t0=$(secs)
"$BIN" export --texture gravel --world "$WORLD" --data-dir "$WORK/data" --workers 1 --shard 0/1 \
  -o "$WORK/one.part" > /dev/null 2>&1
t1=$(secs)
tiles=$(python3 -c "print(sum(4**a for a in range(0, ($WORLD).bit_length())))")
for i in $(seq 0 $((N-1))); do
  "$BIN" export --texture gravel --world "$WORLD" --data-dir "$WORK/data" --workers 1 --shard "$i/$N" \
    -o "$WORK/part-$i.part" > /dev/null 2>&1 &
done
wait
t2=$(secs)
"$BIN" merge "$WORK"/part-*.part -o "$WORK/world.pmtiles"
"$BIN" merge "$WORK/one.part" -o "$WORK/one.pmtiles" > /dev/null
cmp "$WORK/world.pmtiles" "$WORK/one.pmtiles" && echo "merged $N parts = one process's archive, byte for byte"
python3 - "$t0" "$t1" "$t2" "$tiles" "$N" <<'PY'
import sys
t0, t1, t2, tiles, n = map(float, sys.argv[1:])
one, many = tiles / (t1 - t0), tiles / (t2 - t1)
print(f"world {int(tiles)} tiles: 1 process × 1 worker {one:.1f} tiles/s ({t1 - t0:.1f} s); "
      f"{int(n)} processes × 1 worker {many:.1f} tiles/s ({t2 - t1:.1f} s) = {many / (n * one):.2f} × N × one")
PY
