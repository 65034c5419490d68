"""logicrag.ray on a real two-node Ray cluster on 127.0.0.1 (head plus one
worker node, ray.cluster_utils.Cluster): every answer equals the CLI's on
the same input, DuckDB reads the Parquet output, and a worker killed in
the middle of a run loses nothing and writes nothing twice."""

from __future__ import annotations

import json
import os
import signal
import sys
import subprocess
import threading
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import logicrag

ray = pytest.importorskip("ray", reason="logicrag.ray needs ray[data] (pip install 'logicrag[ray]')")
import logicrag.ray as lray  # noqa: E402

from fleet import QUESTIONS, SCENARIOS, cli_answers, cli_queries, rows, videos  # noqa: E402

@pytest.fixture(scope="module")
def cluster():
    from ray.cluster_utils import Cluster

    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    c.add_node(num_cpus=1)
    ray.init(address=c.address, logging_level="WARNING", log_to_driver=False)
    ray.data.DataContext.get_current().enable_progress_bars = False
    assert len([n for n in ray.nodes() if n["Alive"]]) == 2
    yield c
    ray.shutdown()
    c.shutdown()


def test_answer_videos_on_two_nodes_equals_the_cli(cluster, tmp_path):
    vs = videos()
    out = tmp_path / "out"
    summary = lray.answer_videos(vs, QUESTIONS, out, write_facts=True)
    assert summary["failed"] == []
    assert summary["videos"] == len(vs)
    files = sorted(p.name for p in (out / "answers").iterdir())
    assert files == [f"video-{i:06d}.parquet" for i in range(len(vs))]
    assert summary["answers"] == sum(pq.read_metadata(out / "answers" / f).num_rows for f in files)
    assert json.loads((out / "_summary.json").read_text()) == summary
    # Both nodes worked (two workers of one CPU each).
    assert summary["workers"] >= 2
    queries = cli_queries()
    for i, v in enumerate(vs):
        got = pq.read_table(out / "answers" / f"video-{i:06d}.parquet")
        want = cli_answers(v, queries, tmp_path)
        assert got.num_rows == len(QUESTIONS) * len(set(want.column("window").to_pylist()))
        assert rows(got) == rows(want), v
        facts = pq.read_table(out / "facts" / f"video-{i:06d}.parquet")
        assert facts.num_rows > 0

    duckdb = pytest.importorskip("duckdb")
    con = duckdb.connect()
    n, yes = con.execute(
        f"select count(*), count(*) filter (where answer = 'yes') from read_parquet('{out}/answers/*.parquet')"
    ).fetchone()
    assert n == summary["answers"] and 0 < yes < n
    (facts,) = con.execute(f"select count(*) from read_parquet('{out}/facts/*.parquet')").fetchone()
    assert facts == summary["facts"]


def test_a_bad_video_fails_alone(cluster, tmp_path):
    summary = lray.answer_videos(["sim:urban_crossing", "sim:no_such_scenario"], QUESTIONS[:2], tmp_path)
    assert [f["video_index"] for f in summary["failed"]] == [1]
    assert "no_such_scenario" in summary["failed"][0]["error"]
    assert summary["failed"][0]["error"].startswith("ValueError")
    assert (tmp_path / "answers" / "video-000000.parquet").exists()
    assert not (tmp_path / "answers" / "video-000001.parquet").exists()


def test_bad_arguments_are_refused_before_ray_runs(tmp_path):
    with pytest.raises(ValueError, match="no questions"):
        lray.answer_videos(["sim:braking"], [], tmp_path)
    with pytest.raises(ValueError, match="needs a 'source'"):
        lray.answer_videos([{"sequence": "0000"}], ["Vehicles(x)"], tmp_path)
    with pytest.raises(TypeError, match="colour"):
        lray.answer_videos(["sim:braking"], ["Vehicles(x)"], tmp_path, colour="red")


def worker_pids() -> list[int]:
    """The processes of Ray's VideoAnswerer actors on this machine."""
    pids = []
    for p in os.listdir("/proc"):
        if not p.isdigit():
            continue
        try:
            cmd = Path(f"/proc/{p}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
        except OSError:
            continue
        if cmd.startswith("ray::") and "VideoAnswerer" in cmd:
            pids.append(int(p))
    return pids


def test_orphaned_temporary_files_are_removed(tmp_path):
    # Regression (CI, stop 26): a worker killed between writing its temporary
    # file and renaming it left `video-000001.parquet.tmp-<pid>-<uuid>` in the
    # output after the video had been answered again elsewhere.
    (tmp_path / "answers").mkdir()
    (tmp_path / "facts").mkdir()
    (tmp_path / "answers" / "video-000001.parquet").write_bytes(b"done")
    (tmp_path / "answers" / "video-000001.parquet.tmp-7277-41d7").write_bytes(b"half")
    (tmp_path / "facts" / "video-000002.parquet.tmp-1-2").write_bytes(b"half")
    fs, base = lray._filesystem(str(tmp_path))
    removed = lray._remove_orphans(fs, base, ["answers", "facts", "missing"])
    assert [Path(p).name for p in removed] == ["video-000001.parquet.tmp-7277-41d7", "video-000002.parquet.tmp-1-2"]
    assert sorted(p.name for p in (tmp_path / "answers").iterdir()) == ["video-000001.parquet"]
    assert list((tmp_path / "facts").iterdir()) == []


def test_a_worker_killed_mid_run_loses_nothing_and_writes_nothing_twice(cluster, tmp_path):
    # Enough work to be killed in the middle of: every scenario with four
    # seeds, windows every frame.
    vs = [f"sim:{s}@{seed}" for s in SCENARIOS for seed in range(4)]
    qs = QUESTIONS[:8]
    reference = {}
    eng = logicrag.Engine()
    for i, v in enumerate(vs):
        answers, _ = logicrag.answer_video(eng, v, qs, facts=False, stride=2)
        reference[i] = rows(answers)

    out = tmp_path / "out"
    result: dict = {}

    def run():
        result["summary"] = lray.answer_videos(vs, qs, out, stride=2)

    t = threading.Thread(target=run)
    t.start()
    killed = None
    deadline = time.time() + 240
    while time.time() < deadline and t.is_alive():
        done = list((out / "answers").glob("video-*.parquet")) if (out / "answers").is_dir() else []
        pids = worker_pids()
        if len(done) >= 2 and pids:
            killed = pids[0]
            os.kill(killed, signal.SIGKILL)
            break
        time.sleep(0.05)
    done_at_kill = len(done)
    t.join(timeout=600)
    assert not t.is_alive()
    assert killed is not None, "the run ended before a worker could be killed"
    assert done_at_kill < len(vs), "the kill came after the last video"
    summary = result["summary"]
    assert summary["failed"] == []
    files = sorted(p.name for p in (out / "answers").iterdir())
    # Nothing left half-written, nothing twice.
    assert files == [f"video-{i:06d}.parquet" for i in range(len(vs))]
    for i in range(len(vs)):
        assert rows(pq.read_table(out / "answers" / f"video-{i:06d}.parquet")) == reference[i], vs[i]
    assert summary["answers"] == sum(len(r) for r in reference.values())


def test_the_command_line(cluster, tmp_path):
    vfile = tmp_path / "videos.txt"
    vfile.write_text("# two videos\nsim:braking\n{\"source\": \"sim:pickup\"}\n", encoding="utf-8")
    qfile = tmp_path / "questions.txt"
    qfile.write_text("Are there stopped vehicles?\n\nVehicles(x) ^ Moving(x)\n", encoding="utf-8")
    out = tmp_path / "out"
    env = {**os.environ, "RAY_ADDRESS": cluster.address}
    p = subprocess.run(
        [
            sys.executable,
            "-m",
            "logicrag.ray",
            "--videos",
            str(vfile),
            "--questions",
            str(qfile),
            "--out",
            str(out),
            "--address",
            cluster.address,
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert p.returncode == 0, p.stderr
    summary = json.loads(p.stdout)
    assert summary["videos"] == 2 and summary["failed"] == []
    assert "2/2 videos" in p.stderr
    bad = tmp_path / "bad.txt"
    bad.write_text("{not json\n", encoding="utf-8")
    p = subprocess.run(
        [sys.executable, "-m", "logicrag.ray", "--videos", str(bad), "--questions", str(qfile), "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 2 and f"{bad}:1:" in p.stderr
