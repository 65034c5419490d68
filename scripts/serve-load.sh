#!/usr/bin/env bash
# The bounded load test of `logicrag serve` (loopback only, at most 60 s per
# endpoint): starts an instant scripted OpenAI-compatible upstream (Python's
# standard library) and the server on the simulator, then prints
# requests/s, p50 and p99 for /api/ask, /v1/retrieve and the proxy
# (/v1/chat/completions), and the server's resident memory.
#
#   scripts/serve-load.sh                  # release build, 10 s per endpoint, 16 clients
#   PROFILE=dev SECONDS_EACH=5 scripts/serve-load.sh
set -euo pipefail
cd "$(dirname "$0")/.."

PROFILE="${PROFILE:-release}"
SECONDS_EACH="${SECONDS_EACH:-10}"
CLIENTS="${CLIENTS:-16}"
DIR=target/$([ "$PROFILE" = dev ] && echo debug || echo "$PROFILE")
cargo build --quiet --profile "$PROFILE" -p logicrag --bin logicrag --example serve_load

WORK="$(mktemp -d)"
cleanup() {
    [ -n "${SERVER:-}" ] && kill "$SERVER" 2>/dev/null || true
    [ -n "${UPSTREAM:-}" ] && kill "$UPSTREAM" 2>/dev/null || true
    rm -rf "$WORK"
}
trap cleanup EXIT

# The instant upstream: every POST gets the same chat completion at once.
python3 - "$WORK/upstream-port" <<'PY' &
import json, sys
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
REPLY = json.dumps({"id": "x", "object": "chat.completion", "created": 0, "model": "instant",
                    "choices": [{"index": 0, "message": {"role": "assistant", "content": "Yes."},
                                 "finish_reason": "stop"}]}).encode()
class H(BaseHTTPRequestHandler):
    protocol_version = "HTTP/1.1"
    def do_POST(self):
        self.rfile.read(int(self.headers.get("Content-Length", 0)))
        # One write for the head and the body: written apart, the second
        # small write waits on the first's delayed ACK (Nagle), 40 ms a call.
        head = f"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: {len(REPLY)}\r\n\r\n"
        self.wfile.write(head.encode() + REPLY)
    def log_message(self, *a):
        pass
s = ThreadingHTTPServer(("127.0.0.1", 0), H)
open(sys.argv[1], "w").write(str(s.server_address[1]))
s.serve_forever()
PY
UPSTREAM=$!
for _ in $(seq 50); do [ -s "$WORK/upstream-port" ] && break; sleep 0.1; done
UP="http://127.0.0.1:$(cat "$WORK/upstream-port")/v1"

"$DIR/logicrag" serve --port 0 --source sim:urban_crossing --llm "$UP" --llm-model instant --lmm-frames "${FRAMES:-5}" >"$WORK/serve.out" 2>"$WORK/serve.err" &
SERVER=$!
for _ in $(seq 300); do grep -q "listening on" "$WORK/serve.out" 2>/dev/null && break; sleep 0.1; done
URL="$(sed -n 's/^listening on \(http:[^ ]*\).*/\1/p' "$WORK/serve.out" | head -1)"
URL="${URL%/}"
[ -n "$URL" ] || { cat "$WORK/serve.err" >&2; echo "the server did not start" >&2; exit 1; }

load() {
    echo "== $1"
    "$DIR/examples/serve_load" --url "$URL" --path "$1" --body "$2" \
        --clients "$CLIENTS" --seconds "$SECONDS_EACH" --pid "$SERVER"
}
load /api/ask '{"question":"Is the pedestrian walking?","window":"urban_crossing_000030"}'
load /v1/retrieve '{"query":"Is the pedestrian walking?","k":4}'
load /v1/chat/completions '{"model":"instant","messages":[{"role":"user","content":"Is the pedestrian walking?"}]}'
