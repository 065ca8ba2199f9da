#!/usr/bin/env bash
# Soak (issue: under load): run the server with a 64 MiB tile cache and a 64 MiB pyramidal
# cache, drive it for SECONDS (default 300) with cold random, panning (synth) and panning
# (mosaic) traffic, and print its resident memory every 30 s.
# Target: resident memory stays within the cache sizes + 150 MiB.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_TOTAL=${1:-300}
source bench/server.sh
start_server --cache-mib 64 --level-cache-mib 64
$BIN loadtest --url "$URL" --pattern random --concurrency 4 --requests 10000000 --duration "$SECONDS_TOTAL" > "$DATA/random" &
L1=$!
$BIN loadtest --url "$URL" --pattern pan --query mode=mosaic --concurrency 4 --requests 10000000 --duration "$SECONDS_TOTAL" > "$DATA/pan" &
L2=$!
$BIN loadtest --url "$URL" --pattern pan --texture grass --concurrency 2 --requests 10000000 --duration "$SECONDS_TOTAL" > "$DATA/pan_synth" &
L3=$!
for ((t = 0; t <= SECONDS_TOTAL; t += 30)); do
  printf 't=%4ss  rss=%6s MiB\n' "$t" "$(( $(awk '/VmRSS/ {print $2}' /proc/$PID/status) / 1024 ))"
  sleep 30
done
wait $L1 $L2 $L3
cat "$DATA/random" "$DATA/pan" "$DATA/pan_synth"
curl -s "$URL/metrics" | grep -E '^textile_(level_)?cache_(bytes|entries|blocks|evictions_total) '
printf 'final rss=%s MiB (cache limits 64 + 64 MiB)\n' "$(( $(awk '/VmRSS/ {print $2}' /proc/$PID/status) / 1024 ))"
