#!/usr/bin/env bash
# Load benchmark (issue: under load), one command: starts the server on a free loopback port,
# runs the scripted loads with `textile loadtest`, and writes bench/out/load.md (a markdown table)
# so later changes can be compared. Loader and server share the machine.
# Usage: bench/load.sh [SECONDS per cold run, default 15]
set -euo pipefail
cd "$(dirname "$0")/.."
SECS=${1:-15}
source bench/server.sh
start_server
OUT=bench/out/load.md
mkdir -p bench/out
run() { # name, loadtest args...
  local name=$1; shift
  $BIN loadtest --url "$URL" --json "$@" | python3 bench/load_row.py "$name"
}
{
  echo "| run | conns | requests | req/s | p50 ms | p99 ms | p50 ms (200s) | p99 ms (200s) | statuses | server hit ratio | computation ratio |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|"
  run "hot (cached tile)" --pattern hot --concurrency 64 --requests 200000 --duration "$SECS"
  run "pan, synth (cold)" --pattern pan --concurrency 8 --requests 100000 --duration "$SECS"
  run "pan, mosaic (cold)" --pattern pan --query mode=mosaic --seed 2 --concurrency 8 --requests 100000 --duration "$SECS"
  run "zoom, synth" --pattern zoom --concurrency 8 --requests 100000 --duration "$SECS" --query seed=3
  run "random, synth" --pattern random --concurrency 8 --requests 100000 --duration "$SECS" --seed 9
  run "random ×10 (overload, clients retry at once)" --pattern random --concurrency 80 --requests 10000000 --duration "$SECS" --seed 10
  run "random ×10 (overload, clients honour Retry-After)" --pattern random --concurrency 80 --requests 10000000 --duration "$SECS" --seed 11 --honor-retry-after
} | tee "$OUT"
echo "wrote $OUT"
