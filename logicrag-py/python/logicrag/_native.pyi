"""Type stubs of logicrag's native module (the classes ``logicrag`` exports)."""

import os
from typing import Any

import pyarrow

__version__: str

class Engine:
    """The LogicPad rules and the question translator built from them.

    ``Engine()`` uses the built-in LogicPad; ``Engine(logicpad="rules.yaml")``
    reads one (the CLI's ``--logicpad``). A file that cannot be read raises
    ``OSError``, one that is not LogicPad YAML ``ValueError``; rules with
    errors are left out with a ``UserWarning``. Engines may be shared by
    threads.
    """

    def __init__(self, logicpad: str | os.PathLike[str] | None = None) -> None: ...
    def open(
        self,
        source: str,
        *,
        sequence: str | None = None,
        window: int | None = None,
        stride: int | None = None,
        frames: str | None = None,
        config: str | os.PathLike[str] | None = None,
        models: str | os.PathLike[str] | None = None,
        camera: str | os.PathLike[str] | None = None,
        fps: float | None = None,
        noise: str | None = None,
    ) -> Source:
        """Opens a source: any ``--source`` string of the CLI
        (``sim:NAME[@SEED]``, ``kitti:DIR``, ``json:FILE``, ``av2:DIR``,
        ``facts:PATH``, ``frames:DIR``) with the CLI's source options as keywords.

        Raises ``ValueError`` for a source or option the CLI refuses (with
        its message), ``OSError`` for a file that cannot be read.
        """

    def open_tracks(
        self,
        table: Any,
        *,
        map: str | os.PathLike[str] | None = None,
        poses: Any | None = None,
        name: str = "tracks",
        window: int | None = None,
        stride: int | None = None,
        frames: str | None = None,
        config: str | os.PathLike[str] | None = None,
    ) -> Source:
        """Opens a tracks table (a ``pyarrow.Table``, or anything with
        ``__arrow_c_stream__``) in the tracks schema of docs/formats.md: one
        row per object and frame — ``frame`` or ``timestamp_ns``,
        ``track_id`` (int or str), ``category``, the box centre ``x``, ``y``,
        ``z`` in the ego frame (x forward, y left, z up), ``length``,
        ``width``, ``height``, ``yaw``; optional ``color`` and ``score``.
        ``poses``: the ego's world pose per ``frame`` or ``timestamp_ns``
        (``x``, ``y``, optional ``z``, ``yaw``); ``map``: an Argoverse 2 map
        archive or a logicrag map JSON (needs ``poses``). The source is
        labelled ``tracks:NAME``.

        Raises ``ValueError`` naming the column and row of a bad value,
        ``OSError`` for a map file that cannot be read.
        """

class Source:
    """A source opened by ``Engine.open``: its windows, ready to be asked.

    Answers are the CLI's on the same source and options. Windows are
    reasoned once, on the first question; methods release the GIL.
    """

    @property
    def video(self) -> str:
        """The source's label (``sim:urban_crossing``, ``kitti:0000``): the
        ``video`` column of its tables."""
    @property
    def windows(self) -> list[str]:
        """The window ids, in order."""
    def __len__(self) -> int:
        """The number of windows."""
    def facts(self, window: str | None = None) -> pyarrow.Table:
        """The facts of one window (or every window) as a table with the
        facts schema (docs/formats.md), rows as ``facts --json`` orders them.

        Raises ``ValueError`` for an unknown window id.
        """
    def ask(
        self,
        question: str,
        window: str | None = None,
        *,
        proofs: bool = True,
        max_answers: int | None = None,
        proof_depth: int | None = None,
    ) -> dict[str, Any]:
        """Answers a question or query on every window (or one):
        ``{"results": [one object per window], "summary": {...}}``, the
        objects ``logicrag ask --json`` prints (dicts and lists built
        directly, equal to ``json.loads`` of its lines). Each yes or no result has a
        ``probability`` that it is right (1 for a noise-free source), and
        ``binding_probabilities`` when some binding is uncertain
        (docs/probability.md).

        Raises ``ValueError`` when the grammar cannot read the question, or
        for an unknown window id.
        """
    def context(self, question: str, window: str) -> dict[str, Any]:
        """The retrieval context of a question on one window, as
        ``logicrag context --json`` prints it."""
    def answer(
        self,
        questions: list[str],
        *,
        proofs: bool = False,
        max_answers: int | None = None,
        proof_depth: int | None = None,
    ) -> pyarrow.Table:
        """Every question on every window as a table with the answers schema
        (docs/formats.md): window by window, each window's rows in the order
        of ``questions`` (``query_index``), as ``logicrag ask --queries``
        orders them. ``proofs=True`` fills the ``proofs`` column (typed
        proof nodes, docs/formats.md);
        the ``probability`` column says how sure each answer is.

        Raises ``ValueError`` when the grammar cannot read a question
        (before anything is answered).
        """

def answers_schema() -> pyarrow.Schema:
    """The answers schema of docs/formats.md (``Source.answer``'s tables)."""

def facts_schema() -> pyarrow.Schema:
    """The facts schema of docs/formats.md (``Source.facts``'s tables)."""
