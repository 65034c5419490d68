"""Benchmarks of the Python package (figures, not tests; docs/benchmarks.md).

    python logicrag-py/bench/bench_python.py overhead   # src.answer vs the CLI, KITTI KB benchmark
    python logicrag-py/bench/bench_python.py ray        # one process vs a two-node local Ray cluster
    python logicrag-py/bench/bench_python.py scale --videos 2000   # simulated videos through Ray to Parquet
    python logicrag-py/bench/bench_python.py spark      # one process vs a local Spark session (2 cores)

Run with the wheel installed in release mode (``pip install ./logicrag-py``)
and the CLI built with ``cargo build --release``; the KITTI KB benchmark
from ``python3 ../shared/bench/gen_kb_bench.py --out target/kb-bench
--datasets kitti``.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time


import logicrag

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENARIOS = ["urban_crossing", "highway_merge", "parking_lot", "intersection", "braking", "pickup", "collision"]
QUESTIONS = [
    "Is the pedestrian walking?",
    "Is there a pedestrian on the road?",
    "Are there stopped vehicles?",
    "Is there a car moving at constant speed?",
    "How many cars are there?",
    "Is there a white car?",
    "Is any vehicle speeding up?",
    "Is a car getting closer to a pedestrian?",
    "Vehicles(x) ^ Moving(x)",
    "Vehicles(x) ^ Vehicles(y) ^ x != y ^ GettingCloser(x, y)",
]


def cpu_children() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_self() -> float:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def overhead(a: argparse.Namespace) -> None:
    """The same work through the CLI and through ``Source.answer``: every one
    of the KB benchmark's distinct query texts (up to ``--queries``) on
    every window of its KITTI dataset."""
    d = ROOT / "target" / "kb-bench" / "kitti"
    if not d.is_dir():
        sys.exit("generate the KB benchmark first: python3 ../shared/bench/gen_kb_bench.py --out target/kb-bench --datasets kitti")
    texts = []
    for line in (d / "queries.tsv").read_text().splitlines():
        q = line.split("\t", 1)[1]
        if q not in texts:
            texts.append(q)
        if len(texts) == a.queries:
            break
    eng = logicrag.Engine(logicpad=str(d / "rules.yaml"))
    src = eng.open(f"facts:{d / 'facts'}")
    windows = src.windows
    with tempfile.TemporaryDirectory() as tmp:
        qfile = pathlib.Path(tmp) / "q.tsv"
        qfile.write_text("".join(f"{w}\t{q}\n" for w in windows for q in texts))
        cli = str(ROOT / "target" / "release" / "logicrag")
        base = ["ask", "--source", f"facts:{d / 'facts'}", "--logicpad", str(d / "rules.yaml"), "--queries", str(qfile)]
        runs = []
        for _ in range(a.repeat):
            # The CLI writes its Parquet table; Python builds the same table
            # in memory (and opens the source, as the CLI does each run).
            t0, c0 = time.perf_counter(), cpu_children()
            subprocess.run([cli, *base, "--parquet", str(pathlib.Path(tmp) / "a.parquet")], check=True)
            cli_wall, cli_cpu = time.perf_counter() - t0, cpu_children() - c0
            t0, c0 = time.perf_counter(), cpu_self()
            table = eng.open(f"facts:{d / 'facts'}").answer(texts)
            py_wall, py_cpu = time.perf_counter() - t0, cpu_self() - c0
            runs.append((cli_wall, cli_cpu, py_wall, py_cpu))
        n = table.num_rows
    cw, cc, pw, pc = (statistics.median(r[i] for r in runs) for i in range(4))
    print(json.dumps({
        "bench": "python overhead (KITTI KB, every query on every window)",
        "windows": len(windows), "queries": len(texts), "answers": n, "repeat": a.repeat,
        "cli_wall_s": round(cw, 3), "cli_cpu_s": round(cc, 3),
        "python_wall_s": round(pw, 3), "python_cpu_s": round(pc, 3),
        "python_over_cli_wall": round(pw / cw, 3), "python_over_cli_cpu": round(pc / cc, 3),
    }, indent=2))


def fleet(n: int, stride: int | None) -> list[str]:
    return [f"sim:{SCENARIOS[i % len(SCENARIOS)]}@{i // len(SCENARIOS)}" for i in range(n)]


def one_process(videos: list[str], stride: int | None) -> tuple[int, float, float]:
    """The baseline: ``answer_video`` over ``videos`` in a loop in this
    process; returns (windows, wall seconds, CPU seconds)."""
    eng = logicrag.Engine()
    t0, c0 = time.perf_counter(), cpu_self()
    windows = 0
    for v in videos:
        answers, _ = logicrag.answer_video(eng, v, QUESTIONS, facts=False, stride=stride)
        windows += len(set(answers.column("window").to_pylist()))
    return windows, time.perf_counter() - t0, cpu_self() - c0


def ray_bench(a: argparse.Namespace) -> None:
    """The same videos in one process (answer_video in a loop) and on a
    two-node local cluster (head plus one node, one CPU each)."""
    import ray
    from ray.cluster_utils import Cluster

    import logicrag.ray as lray

    videos = fleet(a.videos, a.stride)
    windows, one_wall, one_cpu = one_process(videos, a.stride)

    c = Cluster(initialize_head=True, head_node_args={"num_cpus": 1})
    c.add_node(num_cpus=1)
    ray.init(address=c.address, logging_level="WARNING", log_to_driver=False)
    ray.data.DataContext.get_current().enable_progress_bars = False
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        s = lray.answer_videos(videos, QUESTIONS, tmp, stride=a.stride)
        ray_wall = time.perf_counter() - t0
    ray.shutdown()
    c.shutdown()
    print(json.dumps({
        "bench": "one process vs two-node local Ray cluster",
        "videos": len(videos), "windows": windows, "questions": len(QUESTIONS),
        "one_process": {"wall_s": round(one_wall, 2), "windows_per_s": round(windows / one_wall, 1),
                        "cpu_s_per_window": round(one_cpu / windows, 5)},
        "ray_two_nodes": {"wall_s": round(ray_wall, 2), "windows_per_s": round(s["windows"] / ray_wall, 1),
                          "worker_cpu_s_per_window": round(s["cpu_seconds"] / s["windows"], 5),
                          "workers": s["workers"]},
        "ray_cpu_over_one_process": round((s["cpu_seconds"] / s["windows"]) / (one_cpu / windows), 3),
    }, indent=2))


def scale(a: argparse.Namespace) -> None:
    """``--videos`` simulated videos (scenarios × seeds) through Ray to Parquet."""
    import ray

    import logicrag.ray as lray

    ray.init(logging_level="WARNING", log_to_driver=False)
    ray.data.DataContext.get_current().enable_progress_bars = False
    out = pathlib.Path(a.out)
    t0 = time.perf_counter()
    s = lray.answer_videos(fleet(a.videos, a.stride), QUESTIONS, out, write_facts=True, progress=True, stride=a.stride)
    wall = time.perf_counter() - t0
    ray.shutdown()
    answers_bytes = sum(p.stat().st_size for p in (out / "answers").glob("*.parquet"))
    facts_bytes = sum(p.stat().st_size for p in (out / "facts").glob("*.parquet"))
    print(json.dumps({
        "bench": "scale: simulated videos through Ray to Parquet",
        **{k: s[k] for k in ("videos", "windows", "answers", "facts", "workers", "max_worker_rss_mb", "cpu_seconds")},
        "wall_s": round(wall, 1), "windows_per_s": round(s["windows"] / wall, 1),
        "cpu_s_per_window": round(s["cpu_seconds"] / s["windows"], 5),
        "answers_bytes_per_window": round(answers_bytes / s["windows"], 1),
        "facts_bytes_per_window": round(facts_bytes / s["windows"], 1),
    }, indent=2))


def tree_cpu(root: int, only: str | None = None) -> float:
    """CPU seconds (user + system) of ``root``'s living descendants, from
    /proc: Spark's JVM and its Python workers, which never exit during a
    run, so RUSAGE_CHILDREN would not count them. With ``only``, just the
    processes whose command line contains it (``pyspark.daemon``: the
    Python workers)."""
    tick = os.sysconf("SC_CLK_TCK")
    stats = {}
    for p in os.listdir("/proc"):
        if p.isdigit():
            try:
                f = pathlib.Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
                cmd = pathlib.Path(f"/proc/{p}/cmdline").read_bytes().decode(errors="replace")
            except OSError:
                continue
            stats[int(p)] = (int(f[1]), (int(f[11]) + int(f[12])) / tick, cmd)
    total, frontier = 0.0, {root}
    while frontier:
        kids = {p for p, (pp, _, _) in stats.items() if pp in frontier}
        total += sum(stats[p][1] for p in kids if only is None or only in stats[p][2])
        frontier = kids
    return total


def spark_bench(a: argparse.Namespace) -> None:
    """The same videos in one process and through logicrag.spark on a local
    session of ``--cores`` cores (Spark's JVM and Python workers' CPU)."""
    from pyspark.sql import SparkSession

    import logicrag.spark as lspark

    videos = fleet(a.videos, a.stride)
    windows, one_wall, one_cpu = one_process(videos, a.stride)

    os.environ["PYSPARK_PYTHON"] = sys.executable
    spark = (
        SparkSession.builder.master(f"local[{a.cores}]").config("spark.ui.enabled", "false")
        .config("spark.ui.showConsoleProgress", "false").getOrCreate()
    )
    spark.sparkContext.setLogLevel("ERROR")
    runs = []
    with tempfile.TemporaryDirectory() as tmp:
        # The first run starts the Python workers (and builds their
        # engines); the second is the steady state a long job sees.
        for _ in range(2):
            c0, t0 = tree_cpu(os.getpid()) + cpu_self(), time.perf_counter()
            w0 = tree_cpu(os.getpid(), "pyspark.daemon")
            s = lspark.answer_videos(videos, QUESTIONS, tmp, spark=spark, stride=a.stride)
            workers = tree_cpu(os.getpid(), "pyspark.daemon") - w0
            runs.append((time.perf_counter() - t0, tree_cpu(os.getpid()) + cpu_self() - c0, s, workers))
    spark.stop()
    wall, cpu, s, workers = runs[-1]
    assert s["windows"] == windows and not s["failed"], s
    print(json.dumps({
        "bench": f"one process vs logicrag.spark on local[{a.cores}]",
        "videos": len(videos), "windows": windows, "questions": len(QUESTIONS),
        "one_process": {"wall_s": round(one_wall, 2), "windows_per_s": round(windows / one_wall, 1),
                        "cpu_s_per_window": round(one_cpu / windows, 5)},
        "spark_first_run": {"wall_s": round(runs[0][0], 2), "cpu_s": round(runs[0][1], 2)},
        "spark": {"wall_s": round(wall, 2), "windows_per_s": round(windows / wall, 1),
                  "cpu_s_per_window": round(cpu / windows, 5),
                  "python_worker_cpu_s_per_window": round(workers / windows, 5), "partitions": s["partitions"]},
        "spark_cpu_over_one_process": round(cpu / one_cpu, 3),
        "spark_worker_cpu_over_one_process": round(workers / one_cpu, 3),
    }, indent=2))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="bench", required=True)
    o = sub.add_parser("overhead")
    o.add_argument("--queries", type=int, default=100)
    o.add_argument("--repeat", type=int, default=5)
    r = sub.add_parser("ray")
    r.add_argument("--videos", type=int, default=56)
    r.add_argument("--stride", type=int, default=2)
    s = sub.add_parser("scale")
    s.add_argument("--videos", type=int, default=2000)
    s.add_argument("--stride", type=int, default=None)
    s.add_argument("--out", default=str(ROOT / "target" / "scale-run"))
    k = sub.add_parser("spark")
    k.add_argument("--videos", type=int, default=56)
    k.add_argument("--stride", type=int, default=2)
    k.add_argument("--cores", type=int, default=2)
    a = p.parse_args()
    {"overhead": overhead, "ray": ray_bench, "scale": scale, "spark": spark_bench}[a.bench](a)


if __name__ == "__main__":
    main()
