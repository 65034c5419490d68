"""logicrag.spark on a local Spark session (two cores): groupBy(video)
.applyInArrow answers every video through the same Rust function as the
CLI, every answer equals the CLI's, DuckDB reads the Parquet output, a bad
video fails alone, and a Python worker killed in the middle of a run loses
nothing and writes nothing twice."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import logicrag

pyspark = pytest.importorskip("pyspark", reason="logicrag.spark needs pyspark (pip install 'logicrag[spark]')")
import logicrag.spark as lspark  # noqa: E402
from logicrag._videos import read_questions  # noqa: E402

from fleet import QUESTIONS, SCENARIOS, cli_answers, cli_queries, rows, videos  # noqa: E402


@pytest.fixture(scope="module")
def spark():
    from pyspark.sql import SparkSession

    # The Python workers must import this logicrag: they run this
    # interpreter. local[2, 3]: two cores, and a task may fail three times
    # (local mode's default is once) so that the fault test sees a retry.
    os.environ["PYSPARK_PYTHON"] = sys.executable
    s = (
        SparkSession.builder.master("local[2, 3]")
        .appName("logicrag-tests")
        .config("spark.ui.enabled", "false")
        .config("spark.sql.shuffle.partitions", "4")
        .getOrCreate()
    )
    s.sparkContext.setLogLevel("ERROR")
    yield s
    s.stop()


def by_video(table) -> dict[int, list[str]]:
    """Rows of a Spark output table, per video_index, as `rows` compares them."""
    out: dict[int, list] = {}
    for i in sorted(set(table.column("video_index").to_pylist())):
        mask = [v == i for v in table.column("video_index").to_pylist()]
        out[i] = rows(table.filter(mask))
    return out


def test_answer_videos_equals_the_cli(spark, tmp_path):
    vs = videos()
    out = tmp_path / "out"
    summary = lspark.answer_videos(vs, QUESTIONS, out, spark=spark, write_facts=True)
    assert summary["failed"] == []
    assert summary["videos"] == len(vs)
    assert json.loads((out / "_summary.json").read_text()) == summary
    answers = pq.read_table(out / "answers")
    assert answers.num_rows == summary["answers"]
    assert "error" not in answers.column_names
    assert answers.schema.field("video_index").type == "int64"
    got = by_video(answers)
    assert sorted(got) == list(range(len(vs)))
    queries = cli_queries()
    windows = 0
    for i, v in enumerate(vs):
        want = cli_answers(v, queries, tmp_path)
        n = len(set(want.column("window").to_pylist()))
        windows += n
        assert len(got[i]) == len(QUESTIONS) * n, v
        assert got[i] == rows(want), v
    assert summary["windows"] == windows

    # Facts: every window's facts of every video, as Source.facts gives them.
    facts = pq.read_table(out / "facts")
    eng = logicrag.Engine()
    want_facts = 0
    for v in vs:
        spec, opts = (v, {}) if isinstance(v, str) else (v["source"], {"sequence": v["sequence"]})
        want_facts += eng.open(spec, **opts).facts().num_rows
    assert facts.num_rows == summary["facts"] == want_facts

    duckdb = pytest.importorskip("duckdb")
    con = duckdb.connect()
    n, yes, vids = con.execute(
        "select count(*), count(*) filter (where answer = 'yes'), count(distinct video_index) "
        f"from read_parquet('{out}/answers/*.parquet')"
    ).fetchone()
    assert n == summary["answers"] and 0 < yes < n and vids == len(vs)


def test_a_bad_video_fails_alone(spark, tmp_path):
    vs = ["sim:urban_crossing", "sim:no_such_scenario", {"source": "sim:braking", "window": 5}]
    summary = lspark.answer_videos(vs, QUESTIONS[:2], tmp_path, spark=spark)
    assert [f["video_index"] for f in summary["failed"]] == [1]
    assert summary["failed"][0]["source"] == "sim:no_such_scenario"
    assert summary["failed"][0]["error"].startswith("ValueError: source `sim:no_such_scenario`")
    answers = pq.read_table(tmp_path / "answers")
    assert sorted(set(answers.column("video_index").to_pylist())) == [0, 2]
    # The video's own option (window 5) was used: twice the windows of 10.
    braking = [w for v, w in zip(answers.column("video_index").to_pylist(), answers.column("window").to_pylist()) if v == 2]
    assert len(set(braking)) == 2 * len(logicrag.Engine().open("sim:braking").windows)

    # answer_frame keeps the failed video's row, with its error.
    df = lspark.answer_frame(spark, vs, QUESTIONS[:1])
    failed = df.filter("error is not null").collect()
    assert [(r.video_index, r.video, r.window) for r in failed] == [(1, "sim:no_such_scenario", None)]


def test_a_dataframe_of_videos(spark, tmp_path):
    eng = logicrag.Engine()
    vids = spark.createDataFrame(
        [("sim:pickup", None, None), ("sim:braking", None, 5), ("sim:collision", None, None)],
        "source string, sequence string, window int",
    )
    got = lspark.answer_frame(spark, vids, QUESTIONS[:3]).toArrow()
    assert got.column("error").null_count == got.num_rows
    table = by_video(got)
    assert sorted(table) == [0, 1, 2]
    for i, (spec, opts) in enumerate([("sim:pickup", {}), ("sim:braking", {"window": 5}), ("sim:collision", {})]):
        want, _ = logicrag.answer_video(eng, spec, QUESTIONS[:3], facts=False, **opts)
        assert table[i] == rows(want), spec
    with pytest.raises(ValueError, match="unknown column.*colour"):
        lspark.answer_frame(spark, vids.withColumnRenamed("window", "colour"), QUESTIONS[:1])
    with pytest.raises(ValueError, match="needs a 'source' column"):
        lspark.answer_frame(spark, vids.withColumnRenamed("source", "path"), QUESTIONS[:1])


def test_bad_arguments_are_refused_before_spark_runs(spark, tmp_path):
    with pytest.raises(ValueError, match="no questions"):
        lspark.answer_frame(spark, ["sim:braking"], [])
    with pytest.raises(ValueError, match="no videos"):
        lspark.answer_frame(spark, [], ["Vehicles(x)"])
    with pytest.raises(TypeError, match="colour"):
        lspark.answer_videos(["sim:braking"], ["Vehicles(x)"], tmp_path, spark=spark, colour="red")
    with pytest.raises(OSError):
        lspark.answer_frame(spark, ["sim:braking"], ["Vehicles(x)"], logicpad=tmp_path / "missing.yaml")


def python_workers(running: bool = False) -> list[int]:
    """Spark's forked Python workers: children of a `pyspark.daemon` process
    (with ``running``, only those on a CPU now: answering a video)."""
    daemons, parents = set(), {}
    for p in os.listdir("/proc"):
        if not p.isdigit():
            continue
        try:
            cmd = Path(f"/proc/{p}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
            ppid = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()[1]
            # The engine works on its own threads: any thread on a CPU.
            states = {t.read_text().rsplit(")", 1)[1].split()[0] for t in Path(f"/proc/{p}/task").glob("*/stat")}
        except (OSError, ValueError, IndexError):
            continue
        if "pyspark.daemon" in cmd:
            daemons.add(int(p))
            if "R" in states or not running:
                parents[int(p)] = int(ppid)
    return [p for p, pp in parents.items() if pp in daemons]


def test_a_worker_killed_mid_run_loses_nothing_and_writes_nothing_twice(spark, tmp_path):
    vs = [f"sim:{s}@{seed}" for s in SCENARIOS for seed in range(3)]
    qs = QUESTIONS[:8]
    eng = logicrag.Engine()
    reference = {i: rows(logicrag.answer_video(eng, v, qs, facts=False, stride=2)[0]) for i, v in enumerate(vs)}

    out = tmp_path / "out"
    result: dict = {}

    def run():
        result["summary"] = lspark.answer_videos(vs, qs, out, spark=spark, stride=2, partitions=len(vs))

    tracker = spark.sparkContext.statusTracker()
    jobs_before = set(tracker.getJobIdsForGroup())

    def failed_tasks() -> int:
        """Tasks of this run that Spark saw fail (and so ran again)."""
        n = 0
        for job in set(tracker.getJobIdsForGroup()) - jobs_before:
            info = tracker.getJobInfo(job)
            for stage in info.stageIds if info else []:
                st = tracker.getStageInfo(stage)
                n += st.numFailedTasks if st else 0
        return n

    t = threading.Thread(target=run)
    t.start()
    killed: list[int] = []
    deadline = time.time() + 240
    while time.time() < deadline and t.is_alive() and failed_tasks() == 0:
        # Kill the Python workers that are on a CPU a moment after the
        # workers start answering; again until Spark has seen a task die
        # (a worker can be on a CPU between two tasks too).
        if python_workers(running=True):
            time.sleep(0.3)
            for pid in python_workers(running=True):
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            time.sleep(0.5)
        time.sleep(0.01)
    t.join(timeout=600)
    assert not t.is_alive()
    assert killed, "the run ended before a worker could be killed"
    assert failed_tasks() > 0, "no task failed: every kill came between tasks"
    summary = result["summary"]
    assert summary["failed"] == []
    got = by_video(pq.read_table(out / "answers"))
    assert sorted(got) == list(range(len(vs)))
    for i in range(len(vs)):
        assert got[i] == reference[i], vs[i]
    assert summary["answers"] == sum(len(r) for r in reference.values())


def test_the_command_line(tmp_path):
    vfile = tmp_path / "videos.txt"
    vfile.write_text('# two videos\nsim:braking\n{"source": "sim:pickup"}\n', encoding="utf-8")
    qfile = tmp_path / "questions.txt"
    qfile.write_text("Are there stopped vehicles?\n\nVehicles(x) ^ Moving(x)\n", encoding="utf-8")
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "logicrag.spark", "--videos", str(vfile), "--questions", str(qfile), "--out", str(out)]
    p = subprocess.run([*cmd, "--master", "local[1]", "--noise", "high"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    summary = json.loads(p.stdout)
    assert summary["videos"] == 2 and summary["failed"] == []
    answers = pq.read_table(out / "answers")
    assert summary["answers"] == answers.num_rows > 0
    # --noise reached the workers: the answers are those of the noisy videos.
    eng = logicrag.Engine()
    want = sorted(
        r
        for v in ["sim:braking", "sim:pickup"]
        for r in rows(logicrag.answer_video(eng, v, read_questions(str(qfile)), facts=False, noise="high")[0])
    )
    assert sorted(rows(answers)) == want
    bad = tmp_path / "bad.txt"
    bad.write_text("{not json\n", encoding="utf-8")
    p = subprocess.run([*cmd[:4], str(bad), *cmd[5:]], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and f"{bad}:1:" in p.stderr
