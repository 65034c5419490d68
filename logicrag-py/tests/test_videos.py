"""The video list the fleet runners share (logicrag._videos): plain Python,
no cluster."""

from __future__ import annotations

import json

import pytest

from logicrag._videos import read_videos, video_rows


def test_defaults_reach_only_the_sources_that_take_them():
    rows = video_rows(
        ["sim:braking", {"source": "kitti:K", "sequence": "0003"}, "kitti:K", "json:tracks.json"],
        {"sequence": "0000", "noise": "high", "window": 5},
    )
    opts = [json.loads(r["options"]) for r in rows]
    # sim: keeps noise and window, not the KITTI sequence.
    assert opts[0] == {"noise": "high", "window": 5}
    # A video's own option wins; kitti: takes the sequence, not the noise.
    assert opts[1] == {"sequence": "0003", "window": 5}
    assert opts[2] == {"sequence": "0000", "window": 5}
    # json: track files hold several sequences too.
    assert opts[3] == {"sequence": "0000", "window": 5}
    assert [r["video_index"] for r in rows] == [0, 1, 2, 3]


def test_bad_videos_are_refused_with_their_position(tmp_path):
    with pytest.raises(ValueError, match="video 1: a dict needs a 'source'"):
        video_rows(["sim:braking", {"sequence": "0000"}], {})
    with pytest.raises(ValueError, match="video 0: unknown option"):
        video_rows([{"source": "sim:braking", "colour": "red"}], {})
    with pytest.raises(ValueError, match="no videos"):
        video_rows([], {})
    f = tmp_path / "v.txt"
    f.write_text('sim:braking\n# comment\n\n{"source": "kitti:K", "sequence": "0001"}\n', encoding="utf-8")
    assert read_videos(str(f)) == ["sim:braking", {"source": "kitti:K", "sequence": "0001"}]


def test_an_av2_log_takes_the_window_options_but_not_a_sequence():
    # An Argoverse 2 log is one sequence: a KITTI `sequence` default in the
    # same list must not reach it (the CLI would refuse it).
    rows = video_rows(
        ["av2:logs/3b3570b4", {"source": "av2:logs/3bffdcff", "stride": 5}],
        {"sequence": "0000", "window": 10, "config": "around.yaml"},
    )
    opts = [json.loads(r["options"]) for r in rows]
    assert [r["source"] for r in rows] == ["av2:logs/3b3570b4", "av2:logs/3bffdcff"]
    assert opts[0] == {"window": 10, "config": "around.yaml"}
    assert opts[1] == {"window": 10, "config": "around.yaml", "stride": 5}
