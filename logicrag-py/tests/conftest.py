"""Shared by the Python tests: where the workspace, the KITTI labels and
the CLI built from the same tree are."""

from __future__ import annotations

import os
import pathlib
import subprocess

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
KITTI = ROOT.parent / "shared" / "data" / "kitti-tracking"


def require(path: pathlib.Path, what: str) -> None:
    """Fails a test whose input from ../shared is absent, as the Rust tests
    do: CI has it, and a silently skipped test checks nothing.
    ``LOGICRAG_SKIP_MISSING=1`` skips instead, saying so."""
    if path.exists():
        return
    message = f"{path} is not present ({what})"
    if os.environ.get("LOGICRAG_SKIP_MISSING"):
        pytest.skip(message)
    pytest.fail(f"{message}; set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent")


def cli_binary() -> str:
    """``LOGICRAG_BIN``, else the newest ``target/{release,debug}/logicrag``."""
    if os.environ.get("LOGICRAG_BIN"):
        return os.environ["LOGICRAG_BIN"]
    built = [p for p in (ROOT / "target").glob("*/logicrag") if p.is_file()]
    if not built:
        pytest.fail("no logicrag CLI to compare with: build it (cargo build -p logicrag) or set LOGICRAG_BIN")
    return str(max(built, key=lambda p: p.stat().st_mtime))


def cli(*args: str, ok: bool = True) -> subprocess.CompletedProcess[str]:
    """Runs the CLI from the workspace root; with ``ok``, it must succeed."""
    out = subprocess.run([cli_binary(), *args], capture_output=True, text=True, cwd=ROOT, check=False)
    if ok:
        assert out.returncode == 0, out.stderr
    return out
