"""logicrag: ask questions about driving video and get proved answers.

A source (the built-in simulator, KITTI tracking labels, JSON tracks, a
text KB, raw frames through ONNX models) is cut into windows of frames;
each window's facts, with their provenance, plus the LogicPad rules make a
knowledge base; a question in English is translated into a query, and the
answer — yes (with every binding and its proof), no (with why-not),
unknown (the source cannot observe what the question needs) or invalid —
is proved by logicrag's own miniKanren engine. The same library runs the
``logicrag`` command line: answers, JSON and error messages are the CLI's.

>>> import logicrag
>>> eng = logicrag.Engine()                  # the built-in LogicPad
>>> src = eng.open("sim:urban_crossing")     # any --source, its options as keywords
>>> src.windows[:2]
['urban_crossing_000000', 'urban_crossing_000010']
>>> src.ask("Is the pedestrian walking?")["summary"]["summary"]["answer"]
'yes'
>>> src.facts(src.windows[0]).num_rows > 0   # a pyarrow.Table
True

Tables (``Source.facts``, ``Source.answer``, ``answer_video``) have the
schemas of docs/formats.md, the same as the Parquet files of
``logicrag facts --parquet DIR`` and ``logicrag ask --queries FILE
--parquet OUT``. Bad input raises ``ValueError`` with the CLI's message; a
file that cannot be read raises ``OSError``.
"""

from __future__ import annotations

import os
from collections.abc import Sequence

import pyarrow

from ._native import Engine, Source, __version__, answers_schema, facts_schema

__all__ = ["Engine", "Source", "answer_video", "answers_schema", "facts_schema", "__version__"]


def answer_video(
    engine: Engine,
    source: str,
    questions: Sequence[str],
    *,
    facts: bool = True,
    proofs: bool = False,
    max_answers: int | None = None,
    sequence: str | None = None,
    window: int | None = None,
    stride: int | None = None,
    frames: str | None = None,
    config: str | os.PathLike[str] | None = None,
    models: str | os.PathLike[str] | None = None,
    camera: str | os.PathLike[str] | None = None,
    fps: float | None = None,
    noise: str | None = None,
) -> tuple[pyarrow.Table, pyarrow.Table | None]:
    """Answers ``questions`` on every window of one video, in one call.

    Opens ``source`` with ``engine`` (the keywords from ``sequence`` on are
    ``Engine.open``'s), answers every question on every window
    (``Source.answer``) and, with ``facts=True``, reads every window's facts
    (``Source.facts``). Returns ``(answers, facts)``: two ``pyarrow.Table``
    with the answers and facts schemas of docs/formats.md, or
    ``(answers, None)`` without facts.

    Meant as the unit of work of a distributed job (one video per task,
    e.g. a Ray worker): everything it needs is in its arguments, the heavy
    work runs without the GIL, and its tables concatenate across videos
    (their ``video`` column tells them apart).

    Raises ``ValueError`` for a bad source, option or question (nothing is
    answered then), ``OSError`` for a file that cannot be read.
    """
    src = engine.open(
        source,
        sequence=sequence,
        window=window,
        stride=stride,
        frames=frames,
        config=config,
        models=models,
        camera=camera,
        fps=fps,
        noise=noise,
    )
    answers = src.answer(list(questions), proofs=proofs, max_answers=max_answers)
    return answers, (src.facts() if facts else None)
