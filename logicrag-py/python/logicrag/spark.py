"""Answer a fleet of videos on Spark: ``groupBy(video).applyInArrow``, Parquet out.

The same unit of work as :mod:`logicrag.ray`: a video is never split (its
windows reuse each other's derivations), videos are independent. Each
video is one group of a Spark DataFrame; ``applyInArrow`` hands the group
to a Python worker, which answers it through the same Rust function as
``logicrag ask --queries`` (:func:`logicrag.answer_video`) and returns the
answers as an Arrow table — no pandas, no row-by-row conversion. A worker
process builds the engine (LogicPad, translator) once and keeps it for
every video it is given.

- :func:`answer_frame` — a DataFrame of answers (lazy, like any Spark
  DataFrame): the answers schema of docs/formats.md with ``video_index``
  first and ``error`` last;
- :func:`facts_frame` — the same for facts;
- :func:`answer_videos` — writes Parquet under ``out`` and returns a
  summary, as :func:`logicrag.ray.answer_videos` does.

A video whose source is bad (``ValueError``/``OSError`` in the worker)
fails alone: its group is one row with ``video_index``, ``video`` (the
source spec) and ``error`` set, every other column null. Spark retries a
task whose worker died; the task's videos are answered again and, since a
task's output is committed whole, appear once.

The workers must import ``logicrag``: on a cluster, install the wheel on
every executor; locally, ``answer_videos`` without a session starts one
whose workers run this interpreter (``PYSPARK_PYTHON``).

>>> from pyspark.sql import SparkSession
>>> import logicrag.spark
>>> spark = SparkSession.builder.master("local[4]").getOrCreate()
>>> df = logicrag.spark.answer_frame(spark, ["sim:braking", "sim:pickup"], ["Are there stopped vehicles?"])
>>> df.groupBy("answer").count().show()  # doctest: +SKIP

The command line: ``python -m logicrag.spark --videos FILE --questions FILE
--out DIR [--master URL]``.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import os
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import TYPE_CHECKING, Any

import pyarrow

import logicrag
from logicrag._videos import (
    SOURCE_OPTIONS,
    applicable,
    check_questions,
    check_source_options,
    common_arguments,
    run_command_line,
    video_rows,
)

if TYPE_CHECKING:
    from pyspark.sql import DataFrame, SparkSession

__all__ = ["answer_frame", "facts_frame", "answer_videos", "frame_schema", "main"]

#: Partitions per core of the session when the caller names none: small
#: enough that a slow video does not leave cores idle at the end, large
#: enough that task start-up (tens of milliseconds) stays small beside a
#: video's work.
PARTITIONS_PER_CORE = 8

#: Videos and the options they are opened with, as Spark sees them.
VIDEOS_DDL = "video_index long, source string, options string"


def frame_schema(kind: str) -> pyarrow.Schema:
    """The Arrow schema of :func:`answer_frame` (``kind="answers"``) or
    :func:`facts_frame` (``"facts"``): docs/formats.md's table with
    ``video_index`` (int64, the video's position) first and ``error``
    (string, null unless the video failed) last; every column nullable,
    since a failed video's row has only those two and ``video``."""
    if kind == "answers":
        base = logicrag.answers_schema()
    elif kind == "facts":
        base = logicrag.facts_schema()
    else:
        raise ValueError(f"expected 'answers' or 'facts', got {kind!r}")
    fields = [pyarrow.field("video_index", pyarrow.int64())]
    fields += [f.with_nullable(True) for f in base]
    fields.append(pyarrow.field("error", pyarrow.string()))
    return pyarrow.schema(fields)


#: One engine per LogicPad per Python worker process (Spark reuses its
#: workers across tasks, so a worker builds it once).
_ENGINES: dict[str | None, logicrag.Engine] = {}


def _engine(logicpad: str | None) -> logicrag.Engine:
    eng = _ENGINES.get(logicpad)
    if eng is None:
        # The engine's thread pool is sized when first used: one thread per
        # CPU Spark gave this task, not one per CPU of the machine.
        try:
            from pyspark import TaskContext

            ctx = TaskContext.get()
            cpus = ctx.cpus() if ctx is not None else 1
        except ImportError:
            cpus = 1
        os.environ.setdefault("RAYON_NUM_THREADS", str(max(1, cpus)))
        eng = logicrag.Engine(logicpad=logicpad) if logicpad else logicrag.Engine()
        _ENGINES[logicpad] = eng
    return eng


class _VideoWorker:
    """The function ``applyInArrow`` runs on each video's group (pickled to
    the workers; it carries only plain values)."""

    def __init__(
        self,
        kind: str,
        questions: Sequence[str],
        logicpad: str | None,
        proofs: bool,
        max_answers: int | None,
        defaults: Mapping[str, Any],
    ) -> None:
        self.kind = kind
        self.questions = list(questions)
        self.logicpad = logicpad
        self.proofs = proofs
        self.max_answers = max_answers
        self.defaults = dict(defaults)
        self.schema = frame_schema(kind)

    def __call__(self, group: pyarrow.Table) -> pyarrow.Table:
        tables = [self._one(row) for row in group.to_pylist()]
        return pyarrow.concat_tables(tables) if tables else self.schema.empty_table()

    def _one(self, row: dict) -> pyarrow.Table:
        index = row["video_index"]
        try:
            options = {**applicable(self.defaults, row["source"]), **json.loads(row["options"] or "{}")}
            engine = _engine(self.logicpad)
            if self.kind == "answers":
                table, _ = logicrag.answer_video(
                    engine,
                    row["source"],
                    self.questions,
                    facts=False,
                    proofs=self.proofs,
                    max_answers=self.max_answers,
                    **options,
                )
            else:
                table = engine.open(row["source"], **options).facts()
        except (ValueError, OSError, TypeError) as e:
            # A bad video fails alone: one row that says why.
            failed = {"video_index": index, "video": row["source"], "error": f"{type(e).__name__}: {e}"}
            return pyarrow.Table.from_pylist([failed], schema=self.schema)
        n = table.num_rows
        table = table.add_column(0, "video_index", pyarrow.array([index] * n, pyarrow.int64()))
        table = table.append_column("error", pyarrow.nulls(n, pyarrow.string()))
        return table.cast(self.schema)


def _videos_frame(spark: SparkSession, videos: Any, defaults: Mapping[str, Any]) -> tuple[DataFrame, int]:
    """Videos as a DataFrame ``(video_index, source, options)`` and their number.

    ``videos`` is a list (as :func:`logicrag.ray.answer_videos` takes) or a
    DataFrame with a ``source`` column, optional columns named as source
    options (``sequence``, ``window``, …; null means the default) and an
    optional ``video_index``; without one, videos are numbered in the
    DataFrame's order.
    """
    from pyspark.sql import DataFrame
    from pyspark.sql import functions as F

    if isinstance(videos, DataFrame):
        if "source" not in videos.columns:
            raise ValueError(f"the videos DataFrame needs a 'source' column (it has {', '.join(videos.columns)})")
        unknown = sorted(set(videos.columns) - set(SOURCE_OPTIONS) - {"source", "video_index"})
        if unknown:
            raise ValueError(
                f"the videos DataFrame has unknown column(s) {', '.join(unknown)} "
                f"(expected source, video_index and some of {', '.join(SOURCE_OPTIONS)})"
            )
        if "video_index" not in videos.columns:
            # Numbered in order, the same numbers on every recomputation.
            from pyspark.sql.types import LongType, StructField, StructType

            numbered = videos.rdd.zipWithIndex().map(lambda p: (*p[0], p[1]))
            schema = StructType([*videos.schema.fields, StructField("video_index", LongType(), False)])
            videos = spark.createDataFrame(numbered, schema)
        opts = [c for c in videos.columns if c in SOURCE_OPTIONS]
        # to_json leaves out null fields: a null option is the default.
        options = F.to_json(F.struct(*opts)) if opts else F.lit("{}")
        frame = videos.select(
            F.col("video_index").cast("long").alias("video_index"),
            F.col("source").cast("string").alias("source"),
            options.alias("options"),
        )
        return frame, frame.count()
    rows = video_rows(videos, defaults)
    return spark.createDataFrame([(r["video_index"], r["source"], r["options"]) for r in rows], VIDEOS_DDL), len(rows)


def _grouped(
    spark: SparkSession,
    kind: str,
    videos: Any,
    questions: Sequence[str],
    logicpad: str | os.PathLike[str] | None,
    proofs: bool,
    max_answers: int | None,
    partitions: int | None,
    defaults: Mapping[str, Any],
) -> tuple[DataFrame, int, int]:
    """The grouped DataFrame of ``kind``, the number of videos and of partitions."""
    from pyspark.sql.pandas.types import from_arrow_schema

    pad = os.path.abspath(os.fspath(logicpad)) if logicpad is not None else None
    if pad is not None:
        # Fails here, once, with the CLI's message, not in every task.
        logicrag.Engine(logicpad=pad)
    frame, n = _videos_frame(spark, videos, defaults)
    if partitions is None:
        partitions = spark.sparkContext.defaultParallelism * PARTITIONS_PER_CORE
    partitions = max(1, min(int(partitions), max(n, 1)))
    worker = _VideoWorker(kind, questions, pad, proofs, max_answers, defaults)

    # A plain function with type hints: Spark reads the hints to choose the
    # table-in, table-out form (it cannot read a callable object's).
    def answer_group(group: pyarrow.Table) -> pyarrow.Table:
        return worker(group)

    # Range partitioning by video_index: contiguous, balanced partitions
    # that already satisfy the grouping, so groupBy adds no shuffle; and
    # adaptive execution never coalesces a partition count the query
    # names, so the videos stay spread over the cores.
    grouped = (
        frame.repartitionByRange(partitions, "video_index")
        .groupBy("video_index")
        .applyInArrow(answer_group, from_arrow_schema(worker.schema))
    )
    return grouped, n, partitions


def answer_frame(
    spark: SparkSession,
    videos: Any,
    questions: Sequence[str],
    *,
    logicpad: str | os.PathLike[str] | None = None,
    proofs: bool = False,
    max_answers: int | None = None,
    partitions: int | None = None,
    **source_options: Any,
) -> DataFrame:
    """The answers to ``questions`` on every window of every video, as a
    Spark DataFrame (lazy: nothing runs until an action).

    ``videos``: source specs or dicts ``{"source": ..., "sequence": ...}``
    (as :func:`logicrag.ray.answer_videos` takes), or a DataFrame with a
    ``source`` column and optional option and ``video_index`` columns.
    ``source_options`` apply to every video unless it says otherwise.
    Columns: :func:`frame_schema` ``("answers")`` — one row per (window,
    question) of each video, and one row with ``error`` for a video that
    could not be answered. ``partitions`` (default: 8 per core of the
    session, at most one per video) bounds the tasks.

    Raises ``ValueError``/``TypeError`` before Spark runs for no questions,
    a malformed video or an unknown option.
    """
    defaults = check_source_options("answer_frame", source_options)
    questions = check_questions(questions)
    return _grouped(spark, "answers", videos, questions, logicpad, proofs, max_answers, partitions, defaults)[0]


def facts_frame(
    spark: SparkSession,
    videos: Any,
    *,
    logicpad: str | os.PathLike[str] | None = None,
    partitions: int | None = None,
    **source_options: Any,
) -> DataFrame:
    """Every window's facts of every video as a Spark DataFrame:
    :func:`frame_schema` ``("facts")``, as :func:`answer_frame` for answers."""
    defaults = check_source_options("facts_frame", source_options)
    return _grouped(spark, "facts", videos, [], logicpad, False, None, partitions, defaults)[0]


def _session(spark: SparkSession | None) -> SparkSession:
    """The given session, the active one, or a new local one whose Python
    workers run this interpreter (so they import this logicrag)."""
    if spark is not None:
        return spark
    from pyspark.sql import SparkSession

    active = SparkSession.getActiveSession()
    if active is not None:
        return active
    os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
    return SparkSession.builder.appName("logicrag").config("spark.ui.enabled", "false").getOrCreate()


def _location(out: str) -> str:
    """``out`` as Spark and pyarrow both read it: a local path made absolute."""
    return out if "://" in out else os.path.abspath(out)


def answer_videos(
    videos: Any,
    questions: Sequence[str],
    out: str | os.PathLike[str],
    *,
    spark: SparkSession | None = None,
    logicpad: str | os.PathLike[str] | None = None,
    write_facts: bool = False,
    proofs: bool = False,
    max_answers: int | None = None,
    partitions: int | None = None,
    **source_options: Any,
) -> dict[str, Any]:
    """Answers ``questions`` on every window of every video on Spark and
    writes Parquet: ``out/answers/`` (the answers of the videos answered,
    :func:`frame_schema` without ``error``), ``out/facts/`` with
    ``write_facts=True`` (a second pass over the videos: perception runs
    again), and ``out/_summary.json``. Existing output under those names is
    replaced.

    ``spark``: a session (default: the active one, or a new local one).
    The other arguments are :func:`answer_frame`'s.

    Returns the summary: videos, windows, answers, facts, seconds (wall),
    partitions, failed (one ``{"video_index", "source", "error"}`` per video
    that could not be answered, in order), out.
    """
    from pyspark import StorageLevel
    from pyspark.sql import functions as F

    session = _session(spark)
    out = _location(os.fspath(out))
    start = time.perf_counter()
    defaults = check_source_options("answer_videos", source_options)
    questions = check_questions(questions)
    frame, n, parts = _grouped(
        session, "answers", videos, questions, logicpad, proofs, max_answers, partitions, defaults
    )
    # Answered once: the write and the counts below read the same rows.
    frame = frame.persist(StorageLevel.MEMORY_AND_DISK)
    try:
        ok = frame.filter(F.col("error").isNull()).drop("error")
        ok.write.mode("overwrite").parquet(f"{out}/answers")
        answers, windows = ok.agg(F.count(F.lit(1)), F.countDistinct("video_index", "window")).first()
        failed = [
            {"video_index": r["video_index"], "source": r["video"], "error": r["error"]}
            for r in frame.filter(F.col("error").isNotNull()).orderBy("video_index").collect()
        ]
    finally:
        frame.unpersist()
    facts = 0
    if write_facts:
        ff = _grouped(session, "facts", videos, [], logicpad, False, None, partitions, defaults)[0]
        ff = ff.filter(F.col("error").isNull()).drop("error").persist(StorageLevel.MEMORY_AND_DISK)
        try:
            ff.write.mode("overwrite").parquet(f"{out}/facts")
            facts = ff.count()
        finally:
            ff.unpersist()
    summary = {
        "videos": n,
        "windows": windows,
        "answers": answers,
        "facts": facts,
        "seconds": round(time.perf_counter() - start, 3),
        "partitions": parts,
        "failed": failed,
        "out": out,
    }
    _write_summary(out, summary)
    return summary


def _write_summary(out: str, summary: Mapping[str, Any]) -> None:
    import pyarrow.fs

    fs, base = pyarrow.fs.FileSystem.from_uri(out)
    with fs.open_output_stream(f"{base}/_summary.json") as f:
        f.write(json.dumps(summary, indent=2).encode())


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m logicrag.spark``: answer videos on Spark, Parquet out."""
    p = argparse.ArgumentParser(
        prog="python -m logicrag.spark",
        description="Answer questions on every window of many videos on Spark; answers (and facts) as Parquet.",
    )
    common_arguments(p)
    p.add_argument("--master", help="Spark master URL (default: spark-submit's, else local[*])")
    p.add_argument("--partitions", type=int, help="tasks (default: 8 per core, at most one per video)")
    a = p.parse_args(argv)

    @contextlib.contextmanager
    def runner() -> Iterator[Callable[..., dict[str, Any]]]:
        from pyspark.sql import SparkSession

        os.environ.setdefault("PYSPARK_PYTHON", sys.executable)
        builder = SparkSession.builder.appName("logicrag").config("spark.ui.enabled", "false")
        if a.master:
            builder = builder.master(a.master)
        spark = builder.getOrCreate()
        try:
            yield functools.partial(answer_videos, spark=spark, partitions=a.partitions)
        finally:
            spark.stop()

    return run_command_line(a, runner)


if __name__ == "__main__":
    sys.exit(main())
