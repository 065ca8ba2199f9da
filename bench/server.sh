# Sourced by the bench scripts. `start_server [SERVE FLAGS...]` builds the release binary, starts
# `textile serve` on a free loopback port with a temporary data directory, waits until it is
# ready (failing if it exits), and stops it and removes the directory on exit.
# Sets BIN, DATA, PID and URL.
start_server() {
  cargo build --release -q -p textile-server
  BIN=target/release/textile
  DATA=$(mktemp -d)
  "$BIN" serve --bind 127.0.0.1:0 --data-dir "$DATA" "$@" > "$DATA/out" 2>&1 &
  PID=$!
  trap 'kill $PID 2>/dev/null; rm -rf "$DATA"' EXIT
  until grep -q "textile ready" "$DATA/out" 2>/dev/null; do
    kill -0 "$PID" 2>/dev/null || { echo "textile serve exited:" >&2; cat "$DATA/out" >&2; exit 1; }
    sleep 0.2
  done
  URL=$(sed -n 's/^textile ready: viewer at \(http[^ ]*\)\/ .*/\1/p' "$DATA/out")
}
