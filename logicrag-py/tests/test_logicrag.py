"""The Python package against the command line it wraps.

Run against the installed wheel (``pip install ./logicrag-py``), with the
CLI built from the same tree: ``LOGICRAG_BIN`` names it, otherwise the
newest ``target/{release,debug}/logicrag`` of this workspace is used.
Every comparison parses what the CLI prints and compares it with what
Python returns, field by field: nothing here is a recorded answer.
"""

from __future__ import annotations

import doctest
import json
import pathlib
import pydoc
import threading

import duckdb
import pyarrow
import pyarrow.parquet
import pytest

import logicrag

from conftest import require, KITTI, cli

SCENARIOS = ["urban_crossing", "highway_merge", "intersection", "braking"]
QUESTIONS = [
    "Is the pedestrian walking?",
    "Is there a white car?",
    "How many pedestrians are there?",
    "What colour is the van?",
]
QUERIES = [
    "TypeOf(x, Car) ^ Moving(x)",
    "Pedestrian(x) ^ ¬Moving(x)",
    "Vehicles(x) ^ ¬SpeedUp(x) ^ ¬SpeedDown(x)",
    "DistanceDecrease(x, y)",
    "Levitates(x)",
    "TypeOf(car_1, Car)",
]


def cli_json_lines(*args: str) -> list[dict]:
    return [json.loads(line) for line in cli(*args).stdout.splitlines() if line]


def cli_error(*args: str) -> str:
    """The message of a failing CLI run, without its `error: ` prefix."""
    out = cli(*args, ok=False)
    assert out.returncode == 2, (out.stdout, out.stderr)
    lines = [l for l in out.stderr.splitlines() if l.startswith("error: ")]
    assert len(lines) == 1, out.stderr
    return lines[0].removeprefix("error: ")


@pytest.fixture(scope="module")
def engine() -> logicrag.Engine:
    return logicrag.Engine()


@pytest.fixture(scope="module")
def urban(engine: logicrag.Engine) -> logicrag.Source:
    return engine.open("sim:urban_crossing")


def assert_same(py: dict, cli_obj: dict, where: str) -> None:
    """Field by field, so that a difference names its field."""
    assert sorted(py) == sorted(cli_obj), where
    for key in cli_obj:
        assert py[key] == cli_obj[key], f"{where}: field {key!r}"


# --- ask ---------------------------------------------------------------


def test_noise_level_equals_cli(engine: logicrag.Engine) -> None:
    # A simulator source opened at another noise level answers as the CLI's
    # --noise does, and differs from the scenario's own level somewhere.
    src = engine.open("sim:urban_crossing@2", noise="high")
    plain = engine.open("sim:urban_crossing@2")
    text = "Is the red car stopped?"
    lines = cli_json_lines("ask", "--json", "--source", "sim:urban_crossing@2", "--noise", "high", text)
    got = src.ask(text)
    for i, (py, c) in enumerate(zip(got["results"], lines[:-1])):
        assert_same(py, c, f"noise high window {i}")
    # High noise leaves doubt: the answers say how sure they are, and the
    # table carries the same figures.
    probs = [r["probability"] for r in got["results"]]
    assert all(0.0 <= p <= 1.0 for p in probs) and any(p < 1.0 for p in probs), probs
    table = src.answer([text]).to_pylist()
    assert [row["probability"] for row in table] == probs
    assert src.facts().num_rows != plain.facts().num_rows or src.facts() != plain.facts()
    with pytest.raises(ValueError, match="unknown noise level `loud`"):
        engine.open("sim:urban_crossing", noise="loud")
    with pytest.raises(ValueError, match="applies to simulator sources"):
        engine.open(f"kitti:{KITTI}", sequence="0000", noise="high")


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_ask_equals_cli_json(engine: logicrag.Engine, scenario: str) -> None:
    src = engine.open(f"sim:{scenario}")
    assert src.video == f"sim:{scenario}"
    for text in QUESTIONS + QUERIES[:3]:
        lines = cli_json_lines("ask", "--json", "--source", f"sim:{scenario}", text)
        got = src.ask(text)
        assert sorted(got) == ["results", "summary"]
        assert len(got["results"]) == len(lines) - 1 == len(src.windows)
        for i, (py, c) in enumerate(zip(got["results"], lines[:-1])):
            assert_same(py, c, f"{scenario} {text!r} window {i}")
        assert_same(got["summary"], lines[-1], f"{scenario} {text!r} summary")


def same_types(a: object, b: object, where: str = "") -> list[type]:
    """Asserts `a == b` with every value of the same Python type (1 is not
    1.0, nor True), and returns the types met."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} {a!r} vs {type(b).__name__} {b!r}"
    met = [type(a)]
    if isinstance(a, dict):
        assert sorted(a) == sorted(b), where
        for k in a:
            met += same_types(a[k], b[k], f"{where}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            met += same_types(x, y, f"{where}[{i}]")
    else:
        assert a == b, where
    return met


def test_ask_builds_the_objects_json_loads_would(engine: logicrag.Engine) -> None:
    # Floats, ints, bools, None, nested lists and non-ASCII text (¬, ∧ in
    # queries and proofs) come out of `ask` as `json.loads` makes them of
    # the CLI's output (keys in the fields' order rather than sorted).
    src = engine.open("sim:urban_crossing@2", noise="high")
    text = "Vehicles(x) ^ ¬SpeedUp(x) ^ ¬SpeedDown(x)"
    lines = cli_json_lines("ask", "--json", "--source", "sim:urban_crossing@2", "--noise", "high", text)
    got = src.ask(text)
    met = set()
    for i, (py, c) in enumerate(zip(got["results"], lines[:-1])):
        met |= set(same_types(py, c, f"window {i}"))
    met |= set(same_types(got["summary"], lines[-1], "summary"))
    assert {dict, list, str, int, float, type(None)} <= met, met
    assert any("¬" in r["query"] for r in got["results"])
    ctx = src.context("Is the pedestrian walking?", src.windows[0])
    c = cli_json_lines(
        "context", "--json", "--source", "sim:urban_crossing@2", "--noise", "high",
        "--window-id", src.windows[0], "Is the pedestrian walking?",
    )[0]
    same_types(ctx, c, "context")


def test_the_converter_builds_what_json_loads_builds() -> None:
    # The values answers may hold, and some they do not yet: every kind of
    # JSON value, through the converter `ask` and `context` use.
    from logicrag import _native

    text = json.dumps({
        "bools": [True, False], "none": None, "ints": [0, -1, 2**53 + 1, 2**64 - 1, -(2**63)],
        "floats": [0.1, -2.5, 1e-300, 1.0, 3.0e10], "nested": [[[], [[1, [2.5]]]], {"a": [{}]}],
        "text": ["¬∃y: (Road(y) ∧ On(ped_1, y))", "naïve 車 😀", "quote \" backslash \\ tab \t", ""],
        "ключ": "значение",
    }, ensure_ascii=False)
    same_types(_native._json_to_python(text), json.loads(text), "converted")


def test_ask_one_window_and_cli_options_equal_cli(engine: logicrag.Engine) -> None:
    src = engine.open("sim:intersection", window=6, stride=3)
    w = src.windows[2]
    for text, flags in [
        ("Is there a car moving?", []),
        ("TypeOf(x, Car) ^ Moving(x)", ["--no-proofs"]),
        ("Vehicles(x) ^ Vehicles(y)", ["--max-answers", "2"]),
        ("Vehicles(x) ^ ¬SpeedUp(x)", ["--proof-depth", "0"]),
    ]:
        lines = cli_json_lines(
            "ask", "--json", "--source", "sim:intersection", "--window", "6",
            "--stride", "3", "--window-id", w, *flags, text,
        )
        kwargs = {}
        if "--no-proofs" in flags:
            kwargs["proofs"] = False
        if "--max-answers" in flags:
            kwargs["max_answers"] = 2
        if "--proof-depth" in flags:
            kwargs["proof_depth"] = 0
        got = src.ask(text, w, **kwargs)
        assert len(got["results"]) == 1
        assert_same(got["results"][0], lines[0], f"{text!r} {flags}")
        assert_same(got["summary"], lines[1], f"{text!r} {flags} summary")


def test_frames_range_equals_cli(engine: logicrag.Engine) -> None:
    src = engine.open("sim:braking", frames="5-17")
    assert len(src.windows) == 1
    text = "Is a car slowing down?"
    lines = cli_json_lines("ask", "--json", "--source", "sim:braking", "--frames", "5-17", text)
    got = src.ask(text)
    assert_same(got["results"][0], lines[0], text)
    assert_same(got["summary"], lines[1], text)


def test_kitti_equals_cli(engine: logicrag.Engine) -> None:
    require(KITTI, "the KITTI labels of ../shared")
    spec = f"kitti:{KITTI}"
    src = engine.open(spec, sequence="0000", frames="0-29")
    for text in ["Is there a van on the left?", "TypeOf(x, Van) ^ ColorOf(x, White)"]:
        lines = cli_json_lines(
            "ask", "--json", "--source", spec, "--sequence", "0000", "--frames", "0-29", text
        )
        got = src.ask(text)
        assert_same(got["results"][0], lines[0], text)
        assert_same(got["summary"], lines[1], text)
    # A source that cannot see colours says unknown, never no.
    assert got["summary"]["summary"]["answer"] == "unknown"


def test_context_equals_cli(urban: logicrag.Source) -> None:
    w = "urban_crossing_000030"
    text = "Is the blue sedan moving?"
    lines = cli_json_lines("context", "--json", "--window-id", w, text)
    assert len(lines) == 1
    assert_same(urban.context(text, w), lines[0], text)


# --- facts -------------------------------------------------------------


def provenance_json(p: dict) -> dict:
    """A provenance struct (facts table, proof node) as its JSON object."""
    prov = {"window": p["window"], "frames": [p["first_frame"], p["last_frame"]], "source": p["source"]}
    if p["measured"] is not None:
        prov["measured"] = p["measured"]
    if p["threshold"] is not None:
        prov["threshold"] = [p["threshold"]["name"], p["threshold"]["value"]]
    if p["note"] is not None:
        prov["note"] = p["note"]
    if p["probability"] is not None:
        prov["probability"] = p["probability"]
    return prov


def row_as_fact(row: dict) -> dict:
    """A facts-table row as the fact object of `facts --json`."""
    return {"predicate": row["predicate"], "args": row["args"], "provenance": provenance_json(row["provenance"])}


@pytest.mark.parametrize("scenario", SCENARIOS)
def test_facts_equal_cli_json(engine: logicrag.Engine, scenario: str) -> None:
    src = engine.open(f"sim:{scenario}")
    windows = cli_json_lines("facts", "--json", "--source", f"sim:{scenario}")
    assert [w["window"] for w in windows] == src.windows
    table = src.facts()
    rows = table.to_pylist()
    assert len(rows) == sum(len(w["facts"]) for w in windows)
    i = 0
    for w in windows:
        one = src.facts(w["window"]).to_pylist()
        assert one == rows[i : i + len(w["facts"])]
        for fact, row in zip(w["facts"], one):
            assert row["video"] == w["source"] == src.video
            assert (row["window"], row["window_index"], row["first_frame"], row["last_frame"]) == (
                w["window"], w["index"], w["first_frame"], w["last_frame"],
            )
            assert row_as_fact(row) == fact
        i += len(w["facts"])
    # Measured facts exist, so the struct's optional fields were exercised.
    assert any(r["provenance"]["threshold"] is not None for r in rows)


def test_no_column_is_unsigned(urban: logicrag.Source) -> None:
    def walk(t: pyarrow.DataType):
        yield t
        if pyarrow.types.is_list(t):
            yield from walk(t.value_type)
        if pyarrow.types.is_struct(t):
            for f in t:
                yield from walk(f.type)

    for table in [urban.facts(), urban.answer(QUERIES[:1])]:
        for field in table.schema:
            for t in walk(field.type):
                assert not pyarrow.types.is_unsigned_integer(t), (field.name, t)


# --- answer (batches) ---------------------------------------------------


def node_step(n: dict) -> dict:
    """A proof node's step as JSON writes it."""
    if n["kind"] == "observed":
        p = n["provenance"]
        return {"kind": "observed", "provenance": None if p is None else provenance_json(p)}
    if n["kind"] == "rule":
        return {"kind": "rule", "line": n["rule_line"], "text": n["rule_text"]}
    if n["kind"] == "absent":
        return {"kind": "absent"} | ({} if n["doubt"] is None else {"doubt": n["doubt"]})
    assert n["kind"] == "cut", n
    return {"kind": "cut", "reason": n["reason"]}


def proof_trees(answers: list[list[dict]]) -> list[list[dict]]:
    """The `proofs` column of a row (one list of nodes in pre-order per
    answer, each naming its parent) as the trees of `ask --json`."""
    out = []
    for nodes in answers:
        objs = [{"fact": n["fact"], "step": node_step(n)} for n in nodes]
        roots = []
        for n, obj in zip(nodes, objs):
            # The typed atom is the fact's text read apart.
            if n["predicate"] is not None:
                text = f"{n['predicate']}({', '.join(n['args'])})"
                assert ("¬" if n["negated"] else "") + text == n["fact"], n
            if n["parent"] is None:
                assert n["depth"] == 0, n
                roots.append(obj)
            else:
                assert n["parent"] < len(objs) and n["depth"] == nodes[n["parent"]]["depth"] + 1, n
                objs[n["parent"]].setdefault("premises", []).append(obj)
        out.append(roots)
    return out


def batch_rows_equal(table: pyarrow.Table, lines: list[dict], proofs: bool) -> None:
    rows = table.to_pylist()
    assert len(rows) == len(lines)
    for row, line in zip(rows, lines):
        where = f"{line['window']} query {line['query_index']}"
        assert row["window"] == line["window"], where
        assert (row["first_frame"], row["last_frame"]) == (line["first_frame"], line["last_frame"])
        assert row["query"] == line["query"] == line["query_text"], where
        assert row["query_index"] == line["query_index"], where
        assert row["answer"] == line["answer"], where
        assert row["count"] == line["count"], where
        assert row["variables"] == line["variables"], where
        bindings = [[[p["variable"], p["value"]] for p in b] for b in row["bindings"]]
        assert bindings == line["bindings"], where
        assert row["reasons"] == line["reasons"], where
        assert row["probability"] == line.get("probability"), where
        if proofs:
            assert proof_trees(row["proofs"]) == line["proofs"], where
        else:
            assert row["proofs"] is None, where
            assert line["proofs"] == [], where


@pytest.mark.parametrize("proofs", [True, False])
def test_answer_equals_cli_queries_batch(
    urban: logicrag.Source, tmp_path: pathlib.Path, proofs: bool
) -> None:
    qfile = tmp_path / "queries.tsv"
    qfile.write_text("".join(f"{w}\t{q}\n" for w in urban.windows for q in QUERIES))
    flags = [] if proofs else ["--no-proofs"]
    lines = cli_json_lines("ask", "--queries", str(qfile), "--json", *flags)
    table = urban.answer(QUERIES, proofs=proofs)
    assert table.column("video").to_pylist() == [urban.video] * len(lines)
    assert table.column("question").null_count == len(lines)
    batch_rows_equal(table, lines, proofs)
    assert {l["answer"] for l in lines} == {"yes", "no", "invalid"}


def test_answer_translates_questions_as_ask_does(urban: logicrag.Source) -> None:
    table = urban.answer(QUESTIONS).to_pylist()
    assert len(table) == len(QUESTIONS) * len(urban.windows)
    for k, text in enumerate(QUESTIONS):
        per_window = urban.ask(text, proofs=False)["results"]
        rows = [r for r in table if r["query_index"] == k]
        assert [r["window"] for r in rows] == urban.windows
        for row, obj in zip(rows, per_window):
            assert row["question"] == obj["question"] == text
            assert (row["query"], row["answer"], row["count"]) == (
                obj["query"], obj["answer"], obj["count"],
            )
            assert [[[p["variable"], p["value"]] for p in b] for b in row["bindings"]] == obj["bindings"]


def test_answer_video_is_answer_and_facts(engine: logicrag.Engine, urban: logicrag.Source) -> None:
    answers, facts = logicrag.answer_video(engine, "sim:urban_crossing", QUERIES, proofs=True)
    assert answers.equals(urban.answer(QUERIES, proofs=True))
    assert facts is not None and facts.equals(urban.facts())
    answers, facts = logicrag.answer_video(
        engine, "sim:urban_crossing", QUERIES[:2], facts=False, window=20
    )
    assert facts is None
    assert answers.num_rows == 2 * len(engine.open("sim:urban_crossing", window=20).windows)


def test_threads_share_a_source(urban: logicrag.Source) -> None:
    expected = urban.ask("Is the pedestrian walking?")
    got: list[dict] = []

    def ask() -> None:
        got.append(urban.ask("Is the pedestrian walking?"))

    threads = [threading.Thread(target=ask) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert got == [expected] * 4


# --- Parquet from the CLI -------------------------------------------------


def test_cli_parquet_answers_equal_python_and_duckdb_reads_them(
    urban: logicrag.Source, tmp_path: pathlib.Path
) -> None:
    qfile = tmp_path / "queries.tsv"
    qfile.write_text("".join(f"{w}\t{q}\n" for w in urban.windows for q in QUERIES))
    out = tmp_path / "answers.parquet"
    cli("ask", "--queries", str(qfile), "--parquet", str(out))
    written = pyarrow.parquet.read_table(out)
    assert written.equals(urban.answer(QUERIES, proofs=True))
    lines = cli_json_lines("ask", "--queries", str(qfile), "--json")
    batch_rows_equal(written, lines, proofs=True)
    # SQL over the typed columns: bindings unnest to (variable, value).
    con = duckdb.connect()
    n_yes = con.execute(
        "SELECT count(*) FROM read_parquet(?) WHERE answer = 'yes'", [str(out)]
    ).fetchone()[0]
    assert n_yes == sum(l["answer"] == "yes" for l in lines)
    pairs = con.execute(
        "SELECT p.variable, p.value FROM "
        "(SELECT unnest(flatten(bindings)) AS p FROM read_parquet(?))",
        [str(out)],
    ).fetchall()
    assert pairs == [tuple(p) for l in lines for b in l["bindings"] for p in b]
    assert pairs
    # Proof nodes are typed: SQL reads a node's predicate, kind and
    # provenance without parsing anything.
    nodes = con.execute(
        "SELECT n.predicate, n.negated, n.kind, n.provenance.window FROM "
        "(SELECT unnest(flatten(proofs)) AS n FROM read_parquet(?)) WHERE n.depth = 0",
        [str(out)],
    ).fetchall()
    roots = [
        (root["fact"].lstrip("¬").split("(")[0], root["fact"].startswith("¬"), root["step"]["kind"],
         (root["step"].get("provenance") or {}).get("window"))
        for l in lines for answer in l["proofs"] for root in answer
    ]
    assert nodes == roots
    assert ("Moving", True, "absent", None) in nodes and any(k == "observed" for _, _, k, _ in nodes)
    # --no-proofs leaves the column null.
    cli("ask", "--queries", str(qfile), "--parquet", str(out), "--no-proofs")
    assert pyarrow.parquet.read_table(out).column("proofs").null_count == len(lines)


def test_cli_parquet_facts_equal_python_and_duckdb_reads_them(
    urban: logicrag.Source, tmp_path: pathlib.Path
) -> None:
    out = tmp_path / "facts"
    cli("facts", "--parquet", str(out))
    files = sorted(p.name for p in out.iterdir())
    assert files == [f"{w}.parquet" for w in urban.windows]
    for w in urban.windows:
        assert pyarrow.parquet.read_table(out / f"{w}.parquet").equals(urban.facts(w))
    con = duckdb.connect()
    df = con.execute(
        'SELECT "window", predicate, args, provenance.threshold.name AS threshold '
        "FROM read_parquet(?) ORDER BY window_index",
        [str(out / "*.parquet")],
    ).df()
    everything = urban.facts().to_pandas()
    assert len(df) == len(everything)
    assert list(df["window"]) == list(everything["window"])
    assert list(df["predicate"]) == list(everything["predicate"])
    names = {t["name"] for t in everything["provenance"].map(lambda p: p["threshold"]) if t}
    assert set(df["threshold"].dropna()) == names and names


# --- errors ----------------------------------------------------------------


def test_a_bad_source_raises_value_error_with_the_cli_message(engine: logicrag.Engine) -> None:
    for spec, kwargs, flags in [
        ("nope:x", {}, []),
        ("sim:urban_crossing", {"sequence": "0000"}, ["--sequence", "0000"]),
        ("sim:urban_crossing", {"window": 0}, ["--window", "0"]),
        ("sim:urban_crossing", {"frames": "9-2"}, ["--frames", "9-2"]),
        ("sim:urban_crossing", {"fps": 5.0}, ["--fps", "5"]),
    ]:
        with pytest.raises(ValueError) as e:
            engine.open(spec, **kwargs)
        message = cli_error("ask", "--source", spec, *flags, "Pedestrian(x)")
        # The CLI's argument parser reads the source string, and says so
        # before the library's message.
        message = message.removeprefix(f"invalid value '{spec}' for '--source <SOURCE>': ")
        assert str(e.value) == message


def test_a_bad_question_or_window_raises_value_error_with_the_cli_message(
    urban: logicrag.Source,
) -> None:
    text = "Is the zorblax frobnicating wildly?"
    with pytest.raises(ValueError) as e:
        urban.ask(text)
    assert str(e.value) == cli_error("ask", text)
    assert str(e.value).startswith("cannot translate the question: ")
    with pytest.raises(ValueError) as e:
        urban.answer(["Pedestrian(x)", text])
    assert str(e.value) == cli_error("ask", text)
    with pytest.raises(ValueError) as e:
        urban.context(text, urban.windows[0])
    assert str(e.value) == cli_error("context", "--window-id", urban.windows[0], text)
    # An unknown window: one message, whichever method and front end.
    unknown = cli_error("ask", "--window-id", "no_such_window", "Pedestrian(x)")
    assert unknown.startswith("sim:urban_crossing has no window `no_such_window`"), unknown
    assert unknown == cli_error("context", "--window-id", "no_such_window", "Pedestrian(x)")
    with pytest.raises(ValueError) as e:
        urban.ask("Pedestrian(x)", "no_such_window")
    assert str(e.value) == unknown
    with pytest.raises(ValueError) as e:
        urban.context("Pedestrian(x)", "no_such_window")
    assert str(e.value) == unknown
    with pytest.raises(ValueError) as e:
        urban.facts("no_such_window")
    assert str(e.value) == unknown
    with pytest.raises(ValueError) as e:
        urban.ask("Pedestrian(x)", max_answers=0)
    assert str(e.value) == cli_error("ask", "--max-answers", "0", "Pedestrian(x)")
    # An invalid query is an answer, not an error.
    assert urban.ask("Levitates(x)")["summary"]["summary"]["answer"] == "invalid"


def test_unreadable_files_raise_os_error_with_the_cli_message(
    engine: logicrag.Engine, tmp_path: pathlib.Path
) -> None:
    missing = str(tmp_path / "missing.yaml")
    with pytest.raises(OSError) as e:
        logicrag.Engine(logicpad=missing)
    assert str(e.value) == cli_error("ask", "--logicpad", missing, "Pedestrian(x)")
    tracks = str(tmp_path / "missing.json")
    with pytest.raises(OSError) as e:
        engine.open(f"json:{tracks}")
    assert str(e.value) == cli_error("ask", "--source", f"json:{tracks}", "Pedestrian(x)")


def test_a_logicpad_file_is_used_and_broken_rules_warn(tmp_path: pathlib.Path) -> None:
    pad = tmp_path / "pad.yaml"
    pad.write_text(
        "atomic_predicates:\n  tracker:\n    - Vehicles(x)\nderived_predicates:\n"
        "  - name: Fast\n    logic: \"∀x : Vehicles(x) ∧ ¬Slow(x) ==> Fast(x)\"\n"
    )
    with pytest.warns(UserWarning, match="has 1 error"):
        eng = logicrag.Engine(logicpad=pad)
    src = eng.open("sim:urban_crossing")
    text = "Fast(x)"
    lines = cli_json_lines("ask", "--json", "--logicpad", str(pad), text)
    got = src.ask(text)
    for py, c in zip(got["results"], lines[:-1]):
        assert_same(py, c, text)
    assert_same(got["summary"], lines[-1], text)


# --- documentation -----------------------------------------------------------


def test_help_reads_well() -> None:
    text = pydoc.plain(pydoc.render_doc(logicrag.Engine))
    for words in ["LogicPad", "open(", "logicpad=None", "sequence=None", "ValueError", "OSError"]:
        assert words in text, words
    text = pydoc.plain(pydoc.render_doc(logicrag.Source))
    for words in ["ask(", "facts(", "answer(", "context(", "ask --json", "docs/formats.md"]:
        assert words in text, words
    assert "Ray" in (logicrag.answer_video.__doc__ or "")
    pkg = pathlib.Path(logicrag.__file__).parent
    assert (pkg / "py.typed").is_file() and (pkg / "_native.pyi").is_file()


def test_the_package_docstring_runs() -> None:
    failures, tried = doctest.testmod(logicrag, raise_on_error=False)
    assert tried > 0 and failures == 0
