# Sourced by the bench scripts.

# `serve_binary BIN DIR [SERVE FLAGS...]` starts BIN's `textile serve` on a free loopback port
# with data directory DIR and waits until it is ready (failing if it exits). Sets PID and URL;
# stopping it is the caller's.
serve_binary() {
  local bin=$1 dir=$2
  shift 2
  mkdir -p "$dir"
  "$bin" serve --bind 127.0.0.1:0 --data-dir "$dir" "$@" > "$dir/out" 2>&1 &
  PID=$!
  until grep -q "textile ready" "$dir/out" 2>/dev/null; do
    kill -0 "$PID" 2>/dev/null || { echo "textile serve exited:" >&2; cat "$dir/out" >&2; exit 1; }
    sleep 0.2
  done
  URL=$(sed -n 's/^textile ready: viewer at \(http[^ ]*\)\/ .*/\1/p' "$dir/out")
}

# `start_server [SERVE FLAGS...]` builds the release binary and serves it (`serve_binary`) with a
# temporary data directory, stopping it and removing the directory on exit.
# Sets BIN, DATA, PID and URL.
start_server() {
  cargo build --release -q -p textile-server
  BIN=target/release/textile
  DATA=$(mktemp -d)
  trap 'kill $PID 2>/dev/null; rm -rf "$DATA"' EXIT
  serve_binary "$BIN" "$DATA" "$@"
}
