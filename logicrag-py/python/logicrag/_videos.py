"""What the fleet runners (``logicrag.ray``, ``logicrag.spark``) share: the
list of videos, the questions, and the files the command lines read.

A video is a source spec (``"sim:urban_crossing@3"``, ``"kitti:DIR"``,
``"av2:LOG_DIR"``) or
a dict ``{"source": ..., "sequence": ..., ...}`` whose other keys are
source options. Each becomes a row ``{"video_index", "source", "options"}``
whose options are JSON, so that every runner hands a worker the same
three plain values and the worker calls :func:`logicrag.answer_video`
with them.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from collections.abc import Callable, Iterable, Mapping
from contextlib import AbstractContextManager
from typing import Any

#: The source options a video may carry (``Engine.open``'s keywords).
SOURCE_OPTIONS = ("sequence", "window", "stride", "frames", "config", "models", "camera", "fps", "noise")


#: Options that only some kinds of source take, by the specs' prefixes
#: (the CLI refuses them for the others).
ONLY_FOR = {
    "sequence": ("kitti:", "json:"),
    "noise": ("sim:",),
    "models": ("frames:",),
    "camera": ("frames:",),
    "fps": ("frames:",),
}


def applicable(defaults: Mapping[str, Any], source: str) -> dict[str, Any]:
    """The defaults that apply to ``source``: one that only one kind of
    source takes is left out for the others (``--sequence 0000`` names a
    KITTI sequence; a sim: video in the same list would be refused for it)."""
    return {k: v for k, v in defaults.items() if k not in ONLY_FOR or source.startswith(ONLY_FOR[k])}


def check_source_options(function: str, source_options: Mapping[str, Any]) -> dict[str, Any]:
    """The options that apply to every video, paths made plain strings;
    an unknown keyword raises ``TypeError`` as Python does for a function."""
    unknown = sorted(set(source_options) - set(SOURCE_OPTIONS))
    if unknown:
        raise TypeError(f"{function}() got unexpected keyword argument(s) {', '.join(unknown)}")
    return {k: (os.fspath(v) if isinstance(v, os.PathLike) else v) for k, v in source_options.items() if v is not None}


def check_questions(questions: Iterable[str]) -> list[str]:
    """The questions as a list; none, or a blank one, raises ``ValueError``."""
    qs = list(questions)
    if not qs:
        raise ValueError("no questions to answer")
    if any(not isinstance(q, str) or not q.strip() for q in qs):
        raise ValueError("every question must be a non-empty string")
    return qs


def video_rows(videos: Iterable[str | Mapping[str, Any]], defaults: Mapping[str, Any]) -> list[dict]:
    """Each video as a row: its position, its source and its options (JSON).

    Raises ``TypeError``/``ValueError`` naming the video's position for a
    video that is neither a spec nor a dict with a ``source``, or that has
    an option no source takes; none of them raises ``ValueError`` too.
    """
    rows = []
    for i, v in enumerate(videos):
        if isinstance(v, str):
            spec: dict[str, Any] = {"source": v}
        elif isinstance(v, Mapping):
            spec = dict(v)
        else:
            raise TypeError(f"video {i}: expected a source spec or a dict with 'source', got {type(v).__name__}")
        source = spec.pop("source", None)
        if not isinstance(source, str) or not source:
            raise ValueError(f"video {i}: a dict needs a 'source' (a source spec such as 'sim:urban_crossing')")
        unknown = sorted(set(spec) - set(SOURCE_OPTIONS))
        if unknown:
            raise ValueError(
                f"video {i}: unknown option(s) {', '.join(unknown)} (expected some of {', '.join(SOURCE_OPTIONS)})"
            )
        options = {**applicable(defaults, source), **{k: v for k, v in spec.items() if v is not None}}
        rows.append({"video_index": i, "source": source, "options": json.dumps(options, sort_keys=True)})
    if not rows:
        raise ValueError("no videos to answer")
    return rows


def _lines(path: str) -> list[tuple[int, str]]:
    """The non-blank lines of a file that are not ``#`` comments, numbered from 1."""
    with open(path, encoding="utf-8") as f:
        return [(n, line.strip()) for n, line in enumerate(f, 1) if line.strip() and not line.lstrip().startswith("#")]


def read_videos(path: str) -> list[str | dict]:
    """A videos file: one video a line, a source spec or a JSON object
    (``{"source": "kitti:DIR", "sequence": "0000"}``); ``#`` starts a comment."""
    out: list[str | dict] = []
    for n, line in _lines(path):
        if line.startswith("{"):
            try:
                v = json.loads(line)
            except json.JSONDecodeError as e:
                raise ValueError(f"{path}:{n}: expected a JSON object or a source spec: {e}") from None
            if not isinstance(v, dict) or "source" not in v:
                raise ValueError(f'{path}:{n}: a JSON video needs a "source"')
            out.append(v)
        else:
            out.append(line)
    return out


def read_questions(path: str) -> list[str]:
    """A questions file: one question or query a line; ``#`` starts a comment."""
    return [line for _, line in _lines(path)]


def common_arguments(p: Any) -> None:
    """The command-line arguments both runners take (an ``argparse`` parser)."""
    p.add_argument("--videos", required=True, help="file: one source spec or JSON object a line")
    p.add_argument("--questions", required=True, help="file: one question or query a line")
    p.add_argument("--out", required=True, help="output directory (answers/, facts/, _summary.json)")
    p.add_argument("--logicpad", help="LogicPad YAML (default: the built-in one)")
    p.add_argument("--facts", action="store_true", help="also write every window's facts under facts/")
    p.add_argument("--proofs", action="store_true", help="answers carry their proofs (typed proof nodes)")
    p.add_argument("--window", type=int, help="frames per window (default 10)")
    p.add_argument("--stride", type=int, help="frames between window starts (default: the window)")
    p.add_argument("--sequence", help="KITTI sequence for videos that name none")
    p.add_argument("--noise", help="noise level of sim: videos (none, low, default, high, mono)")


def run_command_line(
    a: argparse.Namespace, runner: Callable[[], AbstractContextManager[Callable[..., dict[str, Any]]]]
) -> int:
    """The body of both runners' command lines, once ``a`` is parsed: reads
    the videos and questions files, then, within ``runner()`` (which starts
    the cluster or session and yields the runner's ``answer_videos`` with
    its own options set), answers them with the options of
    :func:`common_arguments` and prints the summary. Returns the exit
    status: 2 for a bad input or option (said on stderr as ``error: …``),
    1 when some video failed, 0 otherwise."""
    try:
        videos = read_videos(a.videos)
        questions = read_questions(a.questions)
    except (ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    with runner() as answer_videos:
        try:
            summary = answer_videos(
                videos,
                questions,
                a.out,
                logicpad=a.logicpad,
                write_facts=a.facts,
                proofs=a.proofs,
                window=a.window,
                stride=a.stride,
                sequence=a.sequence,
                noise=a.noise,
            )
        except (ValueError, OSError, TypeError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 2
    print(json.dumps(summary, indent=2))
    return 1 if summary["failed"] else 0


def rss_mb() -> float:
    """Peak resident memory of this process so far, in MiB (Linux reports KiB)."""
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


__all__ = [
    "SOURCE_OPTIONS",
    "applicable",
    "check_questions",
    "check_source_options",
    "common_arguments",
    "read_questions",
    "read_videos",
    "rss_mb",
    "run_command_line",
    "video_rows",
]
