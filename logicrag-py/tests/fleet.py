"""What the fleet tests (Ray, Spark) share: the videos, twenty questions,
and the CLI's answers to compare with (computed once per video and kept
for the whole test session, since both runners compare with them)."""

from __future__ import annotations

import functools
import json
from pathlib import Path

import pyarrow
import pyarrow.parquet as pq

import logicrag

from conftest import KITTI, cli

SCENARIOS = [
    "urban_crossing",
    "highway_merge",
    "parking_lot",
    "intersection",
    "braking",
    "pickup",
    "collision",
]

#: Twenty questions of every category, English and LogicPad queries.
QUESTIONS = [
    "Is the pedestrian walking?",
    "Is there a pedestrian on the road?",
    "Are there stopped vehicles?",
    "Is there a car moving at constant speed?",
    "How many cars are there?",
    "Is there a white car?",
    "Is there a van on the left?",
    "Is any vehicle speeding up?",
    "Is any vehicle slowing down?",
    "Is a car getting closer to a pedestrian?",
    "Is there a cyclist?",
    "Is there a truck?",
    "Does a vehicle appear in this window?",
    "Does a vehicle disappear in this window?",
    "Vehicles(x) ^ Moving(x)",
    "Pedestrian(x) ^ Stopped(x)",
    "TypeOf(x, Car) ^ ColorOf(x, White)",
    "Vehicles(x) ^ Vehicles(y) ^ x != y ^ GettingCloser(x, y)",
    "∀x: Pedestrian(x) → NotCross(x)",
    "Vehicles(x) ^ ¬Moving(x)",
]


def videos() -> list:
    vs: list = [f"sim:{s}" for s in SCENARIOS]
    if KITTI.is_dir():
        vs += [{"source": f"kitti:{KITTI}", "sequence": f"{n:04d}"} for n in range(21)]
    return vs


QUERY_CHARS = set("()^")


@functools.cache
def _cli_queries() -> tuple[str, ...]:
    return tuple(_translate(q) for q in QUESTIONS)


def _translate(q: str) -> str:
    if QUERY_CHARS & set(q):
        return q
    return json.loads(cli("translate", "--json", q).stdout)["query"]


def cli_queries() -> list[str]:
    """Each question as the CLI translates it (`logicrag translate --json`);
    queries as written."""
    return list(_cli_queries())


_ANSWERS: dict[str, pyarrow.Table] = {}


def cli_answers(video, queries: list[str], tmp: Path) -> pyarrow.Table:
    """The CLI's answers (`ask --queries --parquet`) to every query on every
    window of one video; asked once per (video, queries) in a test session."""
    key = json.dumps([video, queries], sort_keys=True)
    if key not in _ANSWERS:
        _ANSWERS[key] = _cli_answers(video, queries, tmp)
    return _ANSWERS[key]


def _cli_answers(video, queries: list[str], tmp: Path) -> pyarrow.Table:
    spec = video if isinstance(video, str) else video["source"]
    options = {} if isinstance(video, str) else {"sequence": video["sequence"]}
    args = [a for k, v in options.items() for a in (f"--{k}", v)]
    src = logicrag.Engine().open(spec, **options)
    lines = [f"{w}\t{q}" for w in src.windows for q in queries]
    qfile = tmp / "queries.tsv"
    qfile.write_text("\n".join(lines) + "\n", encoding="utf-8")
    out = tmp / "cli.parquet"
    cli("ask", "--source", spec, *args, "--queries", str(qfile), "--parquet", str(out))
    return pq.read_table(out)


# The CLI's batch reads queries, so the English question itself is not
# compared: its translation (`query`) is.
KEY = ["window", "query", "answer", "count", "bindings"]


def rows(t: pyarrow.Table) -> list[str]:
    return sorted(json.dumps({k: r[k] for k in KEY}, sort_keys=True) for r in t.select(KEY).to_pylist())


