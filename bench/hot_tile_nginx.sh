#!/usr/bin/env bash
# A cached tile through textile against the same bytes from a file through nginx, side by side
# (issue 85): textile serves the default configuration on loopback; the tile is fetched once
# (cold), its bytes written to a file nginx serves (worker_processes 2, sendfile on, tcp_nopush
# on, access_log off, keepalive_requests 1000000: the static-file limit of this machine). Then
# `wrk -t2 -c64 -d8s` hammers each in alternating rounds, a 200 (plain GET) and a 304 (GET with
# If-None-Match: the tile's ETag, which nginx answers too), and the median ratio textile/nginx
# of each is printed. Needs nginx and wrk (Debian: apt-get install nginx wrk).
#
# usage: bench/hot_tile_nginx.sh [BINARY=target/release/textile] [ROUNDS=3] [TILE=/tiles/gravel/7/1/1.png]
set -euo pipefail
BIN=${1:-target/release/textile}
ROUNDS=${2:-3}
TILE=${3:-/tiles/gravel/7/1/1.png}
SECS=${SECS:-8}
WORK=$(mktemp -d)
PIDS=()
trap 'kill "${PIDS[@]}" 2>/dev/null; [ -f "$WORK/nginx.pid" ] && kill "$(cat "$WORK/nginx.pid")" 2>/dev/null; rm -rf "$WORK"' EXIT
command -v wrk >/dev/null || { echo "bench: needs wrk (apt-get install wrk)" >&2; exit 2; }
NGINX=$(command -v nginx || echo /usr/sbin/nginx)
[ -x "$NGINX" ] || { echo "bench: needs nginx (apt-get install nginx)" >&2; exit 2; }

. "$(dirname "$0")/server.sh"
serve_binary "$BIN" "$WORK/data"
PIDS+=("$PID")
T=$URL
mkdir -p "$WORK/www$(dirname "$TILE")"
curl -s -o "$WORK/www$TILE" "$T$TILE"
ETAG=$(curl -s -D - -o /dev/null "$T$TILE" | awk 'tolower($1) == "etag:" {print $2}' | tr -d '\r')
PORT=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
cat > "$WORK/nginx.conf" <<CONF
worker_processes 2;
pid $WORK/nginx.pid;
error_log $WORK/nginx.err;
events { worker_connections 1024; }
http {
  access_log off;
  sendfile on;
  tcp_nopush on;
  keepalive_requests 1000000;
  default_type image/png;
  client_body_temp_path $WORK/tmp;
  etag on;
  server {
    listen 127.0.0.1:$PORT;
    root $WORK/www;
  }
}
CONF
mkdir -p "$WORK/tmp"
chmod 755 "$WORK"; chmod -R a+rX "$WORK/www"  # nginx workers run as an unprivileged user
"$NGINX" -c "$WORK/nginx.conf" -p "$WORK"
N="http://127.0.0.1:$PORT"
for _ in $(seq 50); do curl -sf -o /dev/null "$N$TILE" && break; sleep 0.1; done
NETAG=$(curl -s -D - -o /dev/null "$N$TILE" | awk 'tolower($1) == "etag:" {print $2}' | tr -d '\r')
echo "tile $TILE: textile $(curl -s "$T$TILE" | wc -c) bytes, nginx $(curl -s "$N$TILE" | wc -c) bytes"
echo "304s: textile $(curl -s -o /dev/null -w '%{http_code}' -H "If-None-Match: $ETAG" "$T$TILE"), nginx $(curl -s -o /dev/null -w '%{http_code}' -H "If-None-Match: $NETAG" "$N$TILE")"
rate() { wrk -t2 -c64 -d"${SECS}s" "$@" | awk '/Requests\/sec/ {print $2}'; }
echo "| round | textile 200 req/s | nginx 200 req/s | ratio | textile 304 req/s | nginx 304 req/s | ratio |"
echo "|---|---|---|---|---|---|---|"
all=()
for r in $(seq 1 "$ROUNDS"); do
  t=$(rate "$T$TILE"); n=$(rate "$N$TILE")
  t3=$(rate -H "If-None-Match: $ETAG" "$T$TILE"); n3=$(rate -H "If-None-Match: $NETAG" "$N$TILE")
  all+=("$t,$n,$t3,$n3")
  echo "| $r | $t | $n | $(python3 -c "print(f'{$t/$n:.3f}')") | $t3 | $n3 | $(python3 -c "print(f'{$t3/$n3:.3f}')") |"
done
python3 - "${all[@]}" <<'PY'
import statistics, sys
rows = [[float(v) for v in a.split(",")] for a in sys.argv[1:]]
r200 = statistics.median(t / n for t, n, _, _ in rows)
r304 = statistics.median(t / n for _, _, t, n in rows)
print(f"median textile/nginx: 200 {r200:.3f}, 304 {r304:.3f}")
PY
