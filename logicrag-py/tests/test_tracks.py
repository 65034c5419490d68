"""`Engine.open_tracks`: a tracks table from any dataset (docs/formats.md,
"Tracks tables"), checked on a small synthetic table and against the
`av2:` source on a real Argoverse 2 log converted as a nuScenes or Waymo
user would convert theirs: a few lines of pandas."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pyarrow
import pyarrow.feather
import pytest

import logicrag

from conftest import ROOT, require

AV2_LOG = ROOT.parent / "shared" / "data" / "av2" / "scenario_mining" / "3b3570b4-7b0b-3268-a571-b0889dbf40b6"


@pytest.fixture(scope="module")
def engine() -> logicrag.Engine:
    return logicrag.Engine()


def synthetic() -> pyarrow.Table:
    """A car overtaking the ego on its left and a pedestrian standing ahead
    on the right, for 20 frames at 10 Hz (ego frame: x forward, y left)."""
    rows = []
    for f in range(20):
        rows.append(dict(frame=f, track_id=1, category="Car", x=-10.0 + 1.5 * f, y=3.5, z=0.8,
                         length=4.5, width=1.9, height=1.6, yaw=0.0))
        rows.append(dict(frame=f, track_id=2, category="PEDESTRIAN", x=25.0 - 0.5 * f, y=-4.0, z=0.9,
                         length=0.6, width=0.6, height=1.8, yaw=1.57))
    return pyarrow.Table.from_pandas(pd.DataFrame(rows), preserve_index=False)


def test_a_synthetic_table_opens_and_answers(engine: logicrag.Engine) -> None:
    src = engine.open_tracks(synthetic(), name="overtake", window=20)
    assert src.video == "tracks:overtake"
    assert src.windows == ["overtake_000000"]
    facts = src.facts().to_pandas()
    types = {tuple(a) for p, a in zip(facts["predicate"], facts["args"]) if p == "TypeOf"}
    assert ("car_1", "Car") in types and ("pedestrian_2", "Pedestrian") in types
    answer = lambda q: src.ask(q)["summary"]["summary"]["answer"]
    assert answer("Is there a pedestrian?") == "yes"
    # No colours in the table: a colour question is unknown, not no.
    assert answer("Is there a red car?") == "unknown"


def test_string_ids_name_objects_by_their_key(engine: logicrag.Engine) -> None:
    t = synthetic().to_pandas()
    t["track_id"] = t["track_id"].map({1: "0f3c9a1e-6b2d", 2: "a1b2c3d4-0000"})
    src = engine.open_tracks(pyarrow.Table.from_pandas(t, preserve_index=False), window=20)
    args = {a for arg in src.facts().column("args").to_pylist() for a in arg}
    assert "car_0f3c9a1e" in args and "pedestrian_a1b2c3d4" in args


def test_bad_values_raise_value_error_naming_column_and_row(engine: logicrag.Engine, tmp_path) -> None:
    t = synthetic().to_pandas()
    t.loc[3, "x"] = float("nan")
    # pandas' NaN is a null to pyarrow; a float NaN stays NaN.
    with pytest.raises(ValueError, match=r"tracks table row 3: `x` is null"):
        engine.open_tracks(pyarrow.Table.from_pandas(t, preserve_index=False))
    nan = synthetic().set_column(3, "x", pyarrow.array(t["x"].to_numpy(), from_pandas=False))
    with pytest.raises(ValueError, match=r"tracks table row 3: `x` is NaN, not a finite number"):
        engine.open_tracks(nan)
    with pytest.raises(ValueError, match=r"no column `yaw`"):
        engine.open_tracks(synthetic().drop_columns(["yaw"]))
    scene = tmp_path / "scene.json"
    scene.write_text('{"crosswalks": [{"id": 4, "polygon": [[0, 0], [1, 0], [1, 1]]}]}')
    with pytest.raises(ValueError, match=r"a map needs the ego's poses"):
        engine.open_tracks(synthetic(), map=scene)
    poses = pyarrow.table({"frame": list(range(20)), "x": [0.0] * 20, "y": [0.0] * 20, "yaw": [0.0] * 20})
    assert len(engine.open_tracks(synthetic(), map=scene, poses=poses)) == 2
    with pytest.raises(OSError):
        engine.open_tracks(synthetic(), map=tmp_path / "missing.json")


def av2_tables(log) -> tuple[pyarrow.Table, pyarrow.Table]:
    """The log's annotations and ego poses in the tracks schema: what a
    user of another dataset writes (rename, yaw from the quaternion)."""

    def yaw(df: pd.DataFrame) -> np.ndarray:
        w, x, y, z = (df[c].to_numpy() for c in ("qw", "qx", "qy", "qz"))
        return np.arctan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)

    ann = pyarrow.feather.read_table(log / "annotations_with_ego.feather").to_pandas()
    tracks = pd.DataFrame({
        "timestamp_ns": ann["timestamp_ns"].astype("int64"),
        "track_id": ann["track_uuid"].astype(str),
        "category": ann["category"].astype(str),
        "x": ann["tx_m"], "y": ann["ty_m"], "z": ann["tz_m"],
        "length": ann["length_m"], "width": ann["width_m"], "height": ann["height_m"],
        "yaw": yaw(ann),
    })
    pose = pyarrow.feather.read_table(log / "city_SE3_egovehicle.feather").to_pandas()
    poses = pd.DataFrame({
        "timestamp_ns": pose["timestamp_ns"].astype("int64"),
        "x": pose["tx_m"], "y": pose["ty_m"], "z": pose["tz_m"],
        "yaw": yaw(pose),
    })
    to = lambda df: pyarrow.Table.from_pandas(df.astype({c: "float64" for c in df.columns if c not in ("timestamp_ns", "track_id", "category")}), preserve_index=False)
    return to(tracks), to(poses)


def test_the_av2_log_by_hand_equals_the_av2_source(engine: logicrag.Engine) -> None:
    require(AV2_LOG / "annotations_with_ego.feather", "the AV2 logs of ../shared")
    tracks, poses = av2_tables(AV2_LOG)
    (map_file,) = sorted((AV2_LOG / "map").glob("log_map_archive_*.json"))
    mine = engine.open_tracks(tracks, poses=poses, map=map_file, name=AV2_LOG.name)
    # The EGO_VEHICLE rows are the constant `ego`: counted and said.
    with pytest.warns(UserWarning, match=r"skipped 157 .*EGO_VEHICLE"):
        theirs = engine.open(f"av2:{AV2_LOG}")
    assert mine.video == f"tracks:{AV2_LOG.name}"
    assert mine.windows == theirs.windows
    key = lambda t: sorted(zip(t.column("window").to_pylist(), t.column("predicate").to_pylist(),
                               map(tuple, t.column("args").to_pylist())))
    assert key(mine.facts()) == key(theirs.facts())
    for q in ["Is there a pedestrian?", "How many buses are there?", "Is a car moving?",
              "Vehicles(x) ^ Moving(x)"]:
        a = [r["answer"] for r in mine.ask(q, proofs=False)["results"]]
        b = [r["answer"] for r in theirs.ask(q, proofs=False)["results"]]
        assert a == b, q
