"""Answer a fleet of videos on Ray: one Dataset row per video, Parquet out.

Windows of one video reuse each other's derivations, videos are
independent: so a video is the unit of work and is never split. Each row
of a Ray Dataset is one video; ``map_batches`` runs a callable class that
builds the engine (LogicPad, translator) once per worker and answers every
question on every window of its video through the same Rust function as
``logicrag ask --queries`` (``logicrag.answer_video``).

Output, under ``out`` (a local directory, or any URI pyarrow.fs knows):

- ``answers/video-NNNNNN.parquet``: the answers of video number ``NNNNNN``
  (its position in ``videos``), the answers schema of docs/formats.md;
- ``facts/video-NNNNNN.parquet`` with ``write_facts=True``: its facts;
- ``_summary.json``: what :func:`answer_videos` returns.

Each file is written under a temporary name and renamed when complete, and
its name depends only on the video's position: a worker that dies is
restarted by Ray and its video answered again, the file replaced whole —
nothing is lost and nothing is written twice. A video whose source is bad
(``ValueError``/``OSError``) fails alone: it is listed in the summary's
``failed`` and the others are answered.

>>> import logicrag.ray
>>> logicrag.ray.answer_videos(
...     ["sim:urban_crossing", {"source": "kitti:KITTI", "sequence": "0000"}],
...     ["Is the pedestrian walking?", "How many cars are there?"],
...     "out/",
... )  # doctest: +SKIP
{'videos': 2, 'windows': 23, 'answers': 46, 'seconds': 3.1, ...}

The command line: ``python -m logicrag.ray --videos FILE --questions FILE
--out DIR [--address ADDR]``.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import json
import os
import sys
import time
import uuid
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

import pyarrow
import pyarrow.fs
import pyarrow.parquet

import logicrag
from logicrag._videos import (
    SOURCE_OPTIONS,
    check_questions,
    check_source_options,
    common_arguments,
    read_questions,
    read_videos,
    rss_mb,
    run_command_line,
    video_rows,
)

__all__ = ["SOURCE_OPTIONS", "answer_videos", "read_videos", "read_questions", "main"]

#: One row per video, as the workers report it.
SUMMARY_SCHEMA = pyarrow.schema(
    [
        ("video_index", pyarrow.int64()),
        ("source", pyarrow.string()),
        ("windows", pyarrow.int64()),
        ("answers", pyarrow.int64()),
        ("facts", pyarrow.int64()),
        ("seconds", pyarrow.float64()),
        ("cpu_seconds", pyarrow.float64()),
        ("max_rss_mb", pyarrow.float64()),
        ("worker", pyarrow.string()),
        ("error", pyarrow.string()),
    ]
)


def _filesystem(out: str) -> tuple[pyarrow.fs.FileSystem, str]:
    """The filesystem and base path of ``out`` (a local path made absolute)."""
    if "://" not in out:
        out = os.path.abspath(out)
    return pyarrow.fs.FileSystem.from_uri(out)


def _write_atomic(fs: pyarrow.fs.FileSystem, table: pyarrow.Table, path: str) -> None:
    """Writes ``table`` to ``path`` whole or not at all (temporary name, then rename)."""
    tmp = f"{path}.tmp-{os.getpid()}-{uuid.uuid4().hex}"
    pyarrow.parquet.write_table(table, tmp, filesystem=fs, compression="zstd")
    fs.move(tmp, path)


def _remove_orphans(fs: pyarrow.fs.FileSystem, base: str, dirs: Sequence[str]) -> list[str]:
    """Deletes the temporary files of writes that never finished.

    A worker killed between writing its temporary file and renaming it leaves
    the temporary file behind; Ray then answers the video again elsewhere and
    writes the final file whole. Once the run is over no writer is left, so
    every temporary name in the output is such an orphan. Returns their paths.
    """
    removed = []
    for d in dirs:
        infos = fs.get_file_info(pyarrow.fs.FileSelector(f"{base}/{d}", allow_not_found=True))
        for info in infos:
            if info.type == pyarrow.fs.FileType.File and ".parquet.tmp-" in info.base_name:
                fs.delete_file(info.path)
                removed.append(info.path)
    return sorted(removed)


class VideoAnswerer:
    """The Ray worker: one engine per worker process, one video per call.

    Built once per worker by ``map_batches`` (its constructor loads the
    LogicPad and the translator); each call answers the videos of a batch
    (one by default) and writes their Parquet files.
    """

    def __init__(
        self,
        questions: Sequence[str],
        out: str,
        logicpad: str | None,
        write_facts: bool,
        proofs: bool,
        threads: int,
    ) -> None:
        # The engine reasons windows on a thread pool sized when first used:
        # one per CPU this worker was given, not one per CPU of the node.
        os.environ.setdefault("RAYON_NUM_THREADS", str(max(1, threads)))
        self.engine = logicrag.Engine(logicpad=logicpad) if logicpad else logicrag.Engine()
        self.questions = list(questions)
        self.fs, self.base = _filesystem(out)
        self.write_facts = write_facts
        self.proofs = proofs
        self.worker = f"{os.uname().nodename}:{os.getpid()}"

    def __call__(self, batch: pyarrow.Table) -> pyarrow.Table:
        rows = []
        for row in batch.to_pylist():
            rows.append(self._one(row))
        return pyarrow.Table.from_pylist(rows, schema=SUMMARY_SCHEMA)

    def _one(self, row: dict) -> dict:
        index = row["video_index"]
        options = json.loads(row["options"])
        wall, cpu = time.perf_counter(), time.process_time()
        result = {
            "video_index": index,
            "source": row["source"],
            "windows": 0,
            "answers": 0,
            "facts": 0,
            "worker": self.worker,
            "error": None,
        }
        try:
            answers, facts = logicrag.answer_video(
                self.engine,
                row["source"],
                self.questions,
                facts=self.write_facts,
                proofs=self.proofs,
                **options,
            )
            name = f"video-{index:06d}.parquet"
            _write_atomic(self.fs, answers, f"{self.base}/answers/{name}")
            if facts is not None:
                _write_atomic(self.fs, facts, f"{self.base}/facts/{name}")
                result["facts"] = facts.num_rows
            result["answers"] = answers.num_rows
            result["windows"] = len(set(answers.column("window").to_pylist()))
        except (ValueError, OSError) as e:
            # A bad video fails alone; the run goes on.
            result["error"] = f"{type(e).__name__}: {e}"
        result["seconds"] = time.perf_counter() - wall
        result["cpu_seconds"] = time.process_time() - cpu
        result["max_rss_mb"] = rss_mb()
        return result


def answer_videos(
    videos: Sequence[str | Mapping[str, Any]],
    questions: Sequence[str],
    out: str | os.PathLike[str],
    *,
    logicpad: str | os.PathLike[str] | None = None,
    write_facts: bool = False,
    proofs: bool = False,
    concurrency: int | None = None,
    cpus_per_worker: float = 1,
    progress: bool = False,
    **source_options: Any,
) -> dict[str, Any]:
    """Answers ``questions`` on every window of every video, on Ray.

    ``videos`` are source specs (``"sim:urban_crossing@3"``,
    ``"kitti:DIR"``) or dicts ``{"source": ..., "sequence": ..., ...}``
    whose other keys are source options; ``source_options`` (``sequence``,
    ``window``, ``stride``, ``frames``, ``config``, ``models``, ``camera``,
    ``fps``) apply to every video unless the video's dict says otherwise.
    ``questions`` are English questions or LogicPad queries.

    Uses the running Ray cluster (``ray.init(address=...)`` first), or
    starts a local one. ``concurrency`` workers (default: the cluster's
    CPUs divided by ``cpus_per_worker``) each build the engine once.
    With ``proofs=True`` the answers carry their proofs (the ``proofs``
    column's typed proof nodes, docs/formats.md).

    Returns the summary (also written to ``out/_summary.json``): videos,
    windows, answers, facts, seconds (wall), cpu_seconds (summed over the
    workers' videos), workers (distinct worker processes), max_worker_rss_mb
    (the largest peak resident memory of a worker), failed (one
    ``{"video_index", "source", "error"}`` per video that could not be
    answered), out.
    """
    import ray

    defaults = check_source_options("answer_videos", source_options)
    questions = check_questions(questions)
    rows = video_rows(videos, defaults)
    out = os.fspath(out)
    fs, base = _filesystem(out)
    fs.create_dir(f"{base}/answers", recursive=True)
    if write_facts:
        fs.create_dir(f"{base}/facts", recursive=True)
    pad = os.path.abspath(os.fspath(logicpad)) if logicpad is not None else None
    if pad is not None:
        # Fails here, once, with the CLI's message, not in every worker.
        logicrag.Engine(logicpad=pad)

    if not ray.is_initialized():
        ray.init(logging_level="WARNING", log_to_driver=False)
    if concurrency is None:
        cpus = ray.cluster_resources().get("CPU", 1)
        concurrency = max(1, int(cpus // cpus_per_worker))
    concurrency = max(1, min(concurrency, len(rows)))

    start = time.perf_counter()
    ds = ray.data.from_items(rows, override_num_blocks=len(rows))
    done = ds.map_batches(
        VideoAnswerer,
        fn_constructor_kwargs={
            "questions": questions,
            "out": out,
            "logicpad": pad,
            "write_facts": write_facts,
            "proofs": proofs,
            "threads": max(1, int(cpus_per_worker)),
        },
        batch_size=1,
        batch_format="pyarrow",
        concurrency=concurrency,
        num_cpus=cpus_per_worker,
    )
    by_video: dict[int, dict] = {}
    bar = _Progress(len(rows)) if progress else None
    for r in done.iter_rows():
        # A video answered again after a worker died reports twice; its
        # files were replaced whole, so it counts once.
        by_video[r["video_index"]] = r
        if bar:
            bar.update(by_video)
    if bar:
        bar.close()
    seconds = time.perf_counter() - start
    reports = [by_video[i] for i in sorted(by_video)]
    summary = {
        "videos": len(rows),
        "windows": sum(r["windows"] for r in reports),
        "answers": sum(r["answers"] for r in reports),
        "facts": sum(r["facts"] for r in reports),
        "seconds": round(seconds, 3),
        "cpu_seconds": round(sum(r["cpu_seconds"] for r in reports), 3),
        "workers": len({r["worker"] for r in reports}),
        "max_worker_rss_mb": round(max(r["max_rss_mb"] for r in reports), 1),
        "failed": [
            {"video_index": r["video_index"], "source": r["source"], "error": r["error"]} for r in reports if r["error"]
        ],
        "out": out,
    }
    missing = sorted(set(range(len(rows))) - set(by_video))
    if missing:
        # Ray returned without a report for these (it never does when it
        # completes): say so rather than return a short summary.
        raise RuntimeError(f"Ray returned no result for video(s) {missing}")
    _remove_orphans(fs, base, ["answers", "facts"] if write_facts else ["answers"])
    with fs.open_output_stream(f"{base}/_summary.json") as f:
        f.write(json.dumps(summary, indent=2).encode())
    return summary


class _Progress:
    """A one-line progress bar on stderr: videos done, windows, answers, rate."""

    def __init__(self, total: int) -> None:
        self.total = total
        self.start = time.perf_counter()

    def update(self, reports: Mapping[int, dict]) -> None:
        n = len(reports)
        width = 30
        filled = int(width * n / self.total)
        windows = sum(r["windows"] for r in reports.values())
        answers = sum(r["answers"] for r in reports.values())
        elapsed = time.perf_counter() - self.start
        rate = windows / elapsed if elapsed > 0 else 0.0
        sys.stderr.write(
            f"\r[{'#' * filled}{'.' * (width - filled)}] {n}/{self.total} videos, "
            f"{windows} windows, {answers} answers, {rate:.0f} windows/s, {elapsed:.1f} s"
        )
        sys.stderr.flush()

    def close(self) -> None:
        sys.stderr.write("\n")
        sys.stderr.flush()


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m logicrag.ray``: answer videos on Ray, Parquet out."""
    p = argparse.ArgumentParser(
        prog="python -m logicrag.ray",
        description="Answer questions on every window of many videos on Ray; answers (and facts) as Parquet.",
    )
    common_arguments(p)
    p.add_argument("--address", help="a running Ray cluster (default: start a local one)")
    p.add_argument("--concurrency", type=int, help="workers (default: the cluster's CPUs)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    a = p.parse_args(argv)

    @contextlib.contextmanager
    def runner() -> Iterator[Callable[..., dict[str, Any]]]:
        import ray

        if a.address:
            ray.init(address=a.address, logging_level="WARNING", log_to_driver=False)
        if not a.no_progress:
            # Our bar counts videos and windows; Ray's own bars would interleave.
            ray.data.DataContext.get_current().enable_progress_bars = False
        yield functools.partial(answer_videos, concurrency=a.concurrency, progress=not a.no_progress)

    return run_command_line(a, runner)


if __name__ == "__main__":
    sys.exit(main())
