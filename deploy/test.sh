#!/usr/bin/env bash
# Loopback test of replicas behind nginx: starts three textile replicas (each with its own data
# directory) and nginx running deploy/textile.nginx.conf (ports and paths substituted), runs the
# checks of deploy/check.py — identical bytes and ETags from every replica and through nginx, URI
# affinity, kill -9 of a replica under load with zero failures, one synthesis for 100 concurrent
# identical requests, 304 through nginx — and stops everything it started.
#
# usage: deploy/test.sh [path/to/textile]   (default: target/release/textile; needs nginx, python3)
set -euo pipefail
cd "$(dirname "$0")/.."
source deploy/cluster.sh
trap cluster_stop EXIT
cluster_start "${1:-target/release/textile}" 3
echo "replicas ${REPLICA_URLS[*]} behind nginx at $NGINX_URL"
timeout 900 python3 deploy/check.py "$NGINX_URL" "${REPLICA_URLS[@]}" --kill-pid "${REPLICA_PIDS[2]}" || {
  echo "--- nginx error log (last lines)" >&2; tail -n 20 "$WORK/nginx.log" >&2; exit 1; }
echo "deploy/test.sh: all checks passed"
