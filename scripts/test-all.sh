#!/usr/bin/env bash
# All tests, on a fresh machine that has only Rust, Python 3.11 with pip and
# gcc: installs what the tests need, then runs the Rust tests and the
# Python package's tests against the wheel it builds. `.ci/run` calls
# exactly this; README.md shows it as the test command.
set -euo pipefail
cd "$(dirname "$0")/.."

PIP_FLAGS=(--quiet --disable-pip-version-check)

# ONNX Runtime (loaded at run time by perception through `ort`'s
# load-dynamic, found through `python3`) and the `onnx` package that
# generates the tiny test models.
python3 -m pip install "${PIP_FLAGS[@]}" onnxruntime==1.31.1 onnx numpy

# Headless Chromium for the browser tests of `logicrag serve`
# (logicrag/tests/integration/browser.rs fails without it, and says so).
if ! command -v chromium >/dev/null 2>&1; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends chromium
fi

# A Java runtime for Spark (logicrag.spark's tests run a local Spark
# session; PySpark 4 needs Java 17 or later).
if ! command -v java >/dev/null 2>&1; then
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends openjdk-17-jre-headless
fi

# No incremental cache: the tests build once, and the cache doubles the
# disk a clean build needs.
export CARGO_INCREMENTAL=0

# Formatting and lints first: a diff or a lint fails in seconds, before
# the long build. Clippy's warnings are errors.
rustup component add rustfmt clippy >/dev/null 2>&1 || true
cargo fmt --all --check
cargo clippy --workspace --all-targets -- -D warnings
# The reasoning core's public surface (issue 33): at most 20 public items
# that no front end names.
python3 scripts/pub-audit.py --max 20 | tail -1

# The Rust tests (with a bounded fuzz run of every parser).
cargo test --workspace

# The Python package (logicrag-py/), in a virtual environment of its own,
# installed as a user installs it, with Ray, Spark, DuckDB and LangChain for its
# tests; they compare it with the CLI the step above built. The wheel is
# built in the dev profile so that it reuses the dependencies `cargo test`
# compiled instead of compiling them all again for release.
VENV=target/test-venv
python3 -m venv "$VENV"
"$VENV/bin/pip" install "${PIP_FLAGS[@]}" maturin pyarrow duckdb pandas pytest "ray[data]==2.60.0" pyspark==4.1.1 langchain-core
MATURIN_PEP517_ARGS="--profile dev" "$VENV/bin/pip" install "${PIP_FLAGS[@]}" --force-reinstall --no-deps ./logicrag-py
LOGICRAG_BIN=target/debug/logicrag "$VENV/bin/python" -m pytest -q -p no:cacheprovider logicrag-py/tests
