# Shell functions (sourced by deploy/test.sh and bench/replicas.sh): start N textile replicas on
# free loopback ports, each with its own data directory, and nginx running
# deploy/textile.nginx.conf with the ports and paths substituted; stop everything again.
#   cluster_start BIN N   sets WORK, NGINX_URL, REPLICA_URLS (array), REPLICA_PIDS (array)
#   cluster_stop          kills what cluster_start started and removes WORK

cluster_start() {
  local bin=$1 n=$2 nginx
  nginx=$(command -v nginx || echo /usr/sbin/nginx)
  [ -x "$bin" ] || { echo "no binary at $bin (cargo build --release)" >&2; return 1; }
  [ -x "$nginx" ] || { echo "nginx is not installed (apt-get install nginx)" >&2; return 1; }
  WORK=$(mktemp -d)
  REPLICA_PIDS=()
  REPLICA_URLS=()
  local ports
  read -r -a ports < <(python3 -c '
import socket, sys
ss = [socket.socket() for _ in range(int(sys.argv[1]) + 1)]
for s in ss: s.bind(("127.0.0.1", 0))
print(*[s.getsockname()[1] for s in ss])
for s in ss: s.close()' "$n")
  local pn=${ports[0]} servers="" i
  for i in $(seq 1 "$n"); do
    local port=${ports[$i]}
    mkdir -p "$WORK/data$i"
    "$bin" serve --config deploy/textile.toml --bind "127.0.0.1:$port" --data-dir "$WORK/data$i" \
      >"$WORK/replica$i.out" 2>"$WORK/replica$i.log" &
    REPLICA_PIDS+=($!)
    REPLICA_URLS+=("http://127.0.0.1:$port")
    servers+="    server 127.0.0.1:$port max_fails=3 fail_timeout=5s;\n"
  done
  mkdir -p "$WORK/cache" "$WORK/tmp"
  # The deployment file with our replicas in place of its three example servers.
  awk -v servers="$servers" '
    /^    server 127\.0\.0\.1:808[1-3]/ { if (!done) { printf "%s", servers; done = 1 } next }
    { print }' deploy/textile.nginx.conf |
    sed -e "s|listen 80;|listen 127.0.0.1:$pn;|" -e "s|/var/cache/nginx/textile|$WORK/cache|" >"$WORK/textile.conf"
  cat >"$WORK/nginx.conf" <<CONF
worker_processes 2;
pid $WORK/nginx.pid;
error_log $WORK/nginx.log warn;
$( [ "$(id -u)" = 0 ] && echo "user root;" )
events { worker_connections 4096; }
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
  "$nginx" -t -q -p "$WORK" -c "$WORK/nginx.conf"
  "$nginx" -p "$WORK" -c "$WORK/nginx.conf"
  NGINX_URL="http://127.0.0.1:$pn"
  local u
  for u in "${REPLICA_URLS[@]}"; do
    for _ in $(seq 1 600); do
      curl -sf "$u/ready" >/dev/null 2>&1 && break
      sleep 0.2
    done
    curl -sf "$u/ready" >/dev/null || { echo "replica $u never became ready" >&2; cat "$WORK"/replica*.log >&2; return 1; }
  done
}

cluster_stop() {
  local p
  for p in "${REPLICA_PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  # Replicas drain for at most their shutdown grace; anything left after 15 s is killed.
  for _ in $(seq 1 150); do
    local alive=0
    for p in "${REPLICA_PIDS[@]}"; do kill -0 "$p" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  for p in "${REPLICA_PIDS[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  REPLICA_PIDS=()
  [ -n "${WORK:-}" ] && [ -f "$WORK/nginx.pid" ] && kill "$(cat "$WORK/nginx.pid")" 2>/dev/null || true
  wait 2>/dev/null || true
  [ -n "${WORK:-}" ] && rm -rf "$WORK"
  return 0
}
