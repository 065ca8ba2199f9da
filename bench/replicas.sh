#!/usr/bin/env bash
# Load through nginx: `textile loadtest --pattern pan` against nginx in front of 1 and of 3
# replicas (deploy/textile.nginx.conf, started by deploy/cluster.sh), cold (a seed no one asked
# for yet) and cached (the same tiles again: nginx's cache answers), and against one replica
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
row() { # name url seed [requests]: prints the row; the request count is left in $WORK_N
  "$BIN" loadtest --url "$2" --pattern pan --concurrency 16 --requests "${4:-1000000}" --duration "$SECS" \
    --query "seed=$3" --json >"$TMPJ"
  python3 bench/replicas_row.py "$1" <"$TMPJ"
}
count() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["requests"])' "$TMPJ"; }
TMPJ=$(mktemp)
{
  echo "| run (pan, 16 connections, ${SECS} s) | requests | tiles/s | p50 ms | p99 ms | statuses |"
  echo "|---|---|---|---|---|---|"
  for n in 1 3; do
    cluster_start "$BIN" "$n"
    row "nginx + $n replica(s), cold" "$NGINX_URL" "10$n"
    row "nginx + $n replica(s), cached (the same tiles again: nginx answers)" "$NGINX_URL" "10$n" "$(count)"
    if [ "$n" = 1 ]; then
      row "1 replica directly, cold" "${REPLICA_URLS[0]}" 202
      row "1 replica directly, cached (the same tiles again: its tile cache)" "${REPLICA_URLS[0]}" 202 "$(count)"
    fi
    cluster_stop
  done
} | tee "$OUT"
