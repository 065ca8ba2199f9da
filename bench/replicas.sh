#!/usr/bin/env bash
# Load through nginx: `textile loadtest --pattern pan` against nginx in front of 1 and of 3
# replicas (deploy/textile.nginx.conf, started by deploy/cluster.sh), cold (a seed no one asked
# for yet) and cached (the same pan again: nginx's cache answers), and against one replica
# directly. Writes bench/out/replicas.md. Loader, nginx and replicas share the machine.
# usage: bench/replicas.sh [SECONDS per run, default 15]
set -euo pipefail
cd "$(dirname "$0")/.."
SECS=${1:-15}
BIN=target/release/textile
source deploy/cluster.sh
trap cluster_stop EXIT
mkdir -p bench/out
OUT=bench/out/replicas.md
row() { # name url seed
  "$BIN" loadtest --url "$2" --pattern pan --concurrency 16 --requests 1000000 --duration "$SECS" \
    --query "seed=$3" --json | python3 -c '
import json, sys
r = json.load(sys.stdin)
lat = r.get("latency_ms", {})
print(f"| {sys.argv[1]} | {r.get(\"requests\")} | {r.get(\"requests_per_second\", 0):.0f} | {lat.get(\"p50\", 0):.1f} | {lat.get(\"p99\", 0):.1f} | {r.get(\"status\")} |")' "$1"
}
{
  echo "| run (pan, 16 connections, ${SECS} s) | requests | tiles/s | p50 ms | p99 ms | statuses |"
  echo "|---|---|---|---|---|---|"
  for n in 1 3; do
    cluster_start "$BIN" "$n"
    row "nginx + $n replica(s), cold" "$NGINX_URL" 101
    row "nginx + $n replica(s), cached (same pan again)" "$NGINX_URL" 101
    if [ "$n" = 1 ]; then
      row "1 replica directly, cold" "${REPLICA_URLS[0]}" 202
      row "1 replica directly, its tile cache (same pan again)" "${REPLICA_URLS[0]}" 202
    fi
    cluster_stop
  done
} | tee "$OUT"
