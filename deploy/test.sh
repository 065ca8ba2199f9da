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
BIN=${1:-target/release/textile}
NGINX=$(command -v nginx || echo /usr/sbin/nginx)
[ -x "$BIN" ] || { echo "deploy/test.sh: no binary at $BIN (cargo build --release)" >&2; exit 1; }
[ -x "$NGINX" ] || { echo "deploy/test.sh: nginx is not installed (apt-get install nginx)" >&2; exit 1; }

WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  [ -f "$WORK/nginx.pid" ] && kill "$(cat "$WORK/nginx.pid")" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT

# Free loopback ports: nginx and three replicas.
read -r PN P1 P2 P3 < <(python3 -c '
import socket
ss = [socket.socket() for _ in range(4)]
for s in ss: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in ss])
for s in ss: s.close()')

for i in 1 2 3; do
  port_var="P$i"; port=${!port_var}
  mkdir -p "$WORK/data$i"
  "$BIN" serve --config deploy/textile.toml --bind "127.0.0.1:$port" --data-dir "$WORK/data$i" \
    >"$WORK/replica$i.out" 2>"$WORK/replica$i.log" &
  PIDS+=($!)
  echo "replica $i: pid $! on 127.0.0.1:$port"
done

# nginx: a main configuration of our own around the deployment file, everything under $WORK.
mkdir -p "$WORK/cache" "$WORK/tmp"
sed -e "s/127.0.0.1:8081/127.0.0.1:$P1/; s/127.0.0.1:8082/127.0.0.1:$P2/; s/127.0.0.1:8083/127.0.0.1:$P3/" \
    -e "s|listen 80;|listen 127.0.0.1:$PN;|" \
    -e "s|/var/cache/nginx/textile|$WORK/cache|" deploy/textile.nginx.conf >"$WORK/textile.conf"
cat >"$WORK/nginx.conf" <<CONF
worker_processes 2;
pid $WORK/nginx.pid;
error_log $WORK/nginx.log warn;
$( [ "$(id -u)" = 0 ] && echo "user root;" )
events { worker_connections 1024; }
http {
    access_log off;
    client_body_temp_path $WORK/tmp/body;
    proxy_temp_path $WORK/tmp/proxy;
    fastcgi_temp_path $WORK/tmp/fastcgi;
    uwsgi_temp_path $WORK/tmp/uwsgi;
    scgi_temp_path $WORK/tmp/scgi;
    include $WORK/textile.conf;
}
CONF
"$NGINX" -t -q -p "$WORK" -c "$WORK/nginx.conf"
"$NGINX" -p "$WORK" -c "$WORK/nginx.conf"
echo "nginx on 127.0.0.1:$PN"

# Wait until every replica is ready (textures analysed).
for port in "$P1" "$P2" "$P3"; do
  for _ in $(seq 1 600); do
    curl -sf "http://127.0.0.1:$port/ready" >/dev/null 2>&1 && break
    sleep 0.2
  done
  curl -sf "http://127.0.0.1:$port/ready" >/dev/null || { echo "replica on $port never became ready" >&2; cat "$WORK"/replica*.log >&2; exit 1; }
done

timeout 900 python3 deploy/check.py "http://127.0.0.1:$PN" \
  "http://127.0.0.1:$P1" "http://127.0.0.1:$P2" "http://127.0.0.1:$P3" --kill-pid "${PIDS[2]}" || {
  echo "--- nginx error log (last lines)" >&2; tail -n 20 "$WORK/nginx.log" >&2; exit 1; }
echo "deploy/test.sh: all checks passed"
