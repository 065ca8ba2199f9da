#!/usr/bin/env bash
# User-space instructions per cached tile answer (issue 85), which do not drift with noise:
# textile runs under callgrind (every thread, kernel excluded) with the default configuration;
# the tile is fetched once cold and 200 times to warm up, the counts are zeroed, then N requests
# on one keep-alive connection — plain GETs (200) and GETs with the tile's ETag (304) — are
# counted, one server per kind. Needs valgrind (callgrind_control, callgrind_annotate) and python3.
#
# usage: bench/hot_tile_callgrind.sh [BINARY=target/release/textile] [N=2000] [TILE=/tiles/gravel/7/1/1.png]
set -euo pipefail
BIN=${1:-target/release/textile}
N=${2:-2000}
TILE=${3:-/tiles/gravel/7/1/1.png}
command -v valgrind >/dev/null || { echo "bench: needs valgrind (apt-get install valgrind)" >&2; exit 2; }
WORK=$(mktemp -d)
VP=
trap '[ -n "$VP" ] && kill "$VP" 2>/dev/null; rm -rf "$WORK"' EXIT

# N requests of TILE on one connection, with If-None-Match ETAG when given.
hits() {
  python3 - "$1" "$2" "$TILE" "${3:-}" <<'PY'
import http.client, sys
port, n, tile, etag = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
c = http.client.HTTPConnection("127.0.0.1", port)
h = {"If-None-Match": etag} if etag else {}
for _ in range(n):
    c.request("GET", tile, headers=h)
    r = c.getresponse(); r.read()
print(r.status, r.getheader("ETag"))
PY
}

count() {  # kind (200|304)
  local port out
  port=$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  mkdir -p "$WORK/data" "$WORK/$1"
  valgrind --tool=callgrind --callgrind-out-file="$WORK/$1/cg.%p" "$BIN" serve --bind "127.0.0.1:$port" \
    --data-dir "$WORK/data" > "$WORK/$1/log" 2>&1 &
  VP=$!
  for _ in $(seq 1200); do curl -sf "127.0.0.1:$port/ready" >/dev/null && break; sleep 0.5; done
  local etag
  etag=$(hits "$port" 1 | cut -d' ' -f2-)
  [ "$1" = 304 ] || etag=
  hits "$port" 200 "$etag" > /dev/null
  callgrind_control -z "$VP" > /dev/null 2>&1
  out=$(hits "$port" "$N" "$etag")
  callgrind_control -d "$VP" > /dev/null 2>&1
  sleep 1
  kill "$VP"; wait "$VP" 2>/dev/null || true; VP=
  python3 - "$N" "$1" "$out" "$WORK/$1" <<'PY'
import glob, re, subprocess, sys
n, kind, out, d = int(sys.argv[1]), sys.argv[2], sys.argv[3], sys.argv[4]
tot = 0
for f in glob.glob(d + "/cg.*"):
    text = subprocess.run(["callgrind_annotate", f], capture_output=True, text=True).stdout
    m = re.search(r"([\d,]+) \(100.0%\)\s+PROGRAM TOTALS", text) or re.search(r"([\d,]+)\s+\(100\.0%\)", text)
    if m:
        tot = max(tot, int(m.group(1).replace(",", "")))
print(f"{kind} (answered {out.split()[0]}): {tot / n:.0f} instructions per request")
PY
}
count 200
count 304
