"""Tracking config (track.toml) schema: the brief's example, round trip, one-line errors."""

from __future__ import annotations

import pytest

from rocklab import InputError
from rocklab.config import TrackConfig, load_track_config

EXAMPLE = """\
[video]
fps = 50                     # optional when the container has it
[targets]
style = "aruco"              # aruco | apriltag | dots | edges | region
dictionary = "DICT_4X4_50"   # aruco/apriltag
marker_size_m = 0.03         # side length of the printed marker (gives the scale)
[reference]
level = "table"
[[objects]]
id = "block_1"
kind = "block"
markers = [1]
[[objects]]
id = "table"
kind = "table"
markers = [0]
"""


def test_brief_example_loads_and_round_trips(tmp_path):
    p = tmp_path / "track.toml"
    p.write_text(EXAMPLE)
    cfg = load_track_config(p)
    assert cfg.video.fps == 50.0
    assert cfg.targets.marker_size_m == 0.03
    assert [o.id for o in cfg.objects] == ["block_1", "table"]
    assert cfg.table.markers == (0,)
    q = tmp_path / "again.toml"
    q.write_text(cfg.to_toml())
    again = load_track_config(q)
    assert again.objects == cfg.objects and again.targets == cfg.targets
    assert again.reference == cfg.reference and again.video == cfg.video


@pytest.mark.parametrize(
    "edit, key, line",
    [
        (("markers = [0]", "markers = [0]\nfoo = 3"), "objects[1].foo", 17),
        (('style = "aruco"', 'style = "qr"'), "targets.style", 4),
        (('dictionary = "DICT_4X4_50"', 'dictionary = "DICT_9X9"'), "targets.dictionary", 5),
        (("markers = [1]", "markers = [0]"), "objects[1].markers", 16),
        (("fps = 50", "fps = -5"), "video.fps", 2),
    ],
)
def test_errors_name_key_and_line(tmp_path, edit, key, line):
    p = tmp_path / "track.toml"
    p.write_text(EXAMPLE.replace(*edit, 1) if edit[0] != "markers = [0]" else EXAMPLE.replace(*edit))
    with pytest.raises(InputError) as e:
        load_track_config(p)
    msg = str(e.value)
    assert "\n" not in msg and f"'{key}'" in msg and f"line {line}" in msg


def test_dots_need_two_and_edges_need_roi():
    with pytest.raises(InputError, match="at least two"):
        TrackConfig.from_dict({"targets": {"style": "dots"}, "objects": [{"id": "b", "dots": [[0.0, 0.0]]}]})
    with pytest.raises(InputError, match="roi"):
        TrackConfig.from_dict({"targets": {"style": "edges"}, "objects": [{"id": "b"}]})
    cfg = TrackConfig.from_dict({"targets": {"style": "dots"}, "objects": [{"id": "b", "dots": [[0, 0], [0.1, 0.05]]}]})
    assert cfg.objects[0].dots == ((0.0, 0.0), (0.1, 0.05))
    assert cfg.reference.level == "table"  # kept as written: tracking warns W-LEVEL-NONE (no table)


def test_schema_page_and_examples():
    """docs/track-toml.md carries the generated reference; every example in examples/ loads."""
    from pathlib import Path

    from rocklab.config import load_track_config
    from rocklab.config import schema_markdown

    root = Path(__file__).resolve().parents[1]
    assert (root / "docs" / "track-toml.md").read_text(encoding="utf-8").endswith(schema_markdown())
    loaded = {p.name: load_track_config(p) for p in sorted((root / "examples").glob("track_*.toml"))}
    assert set(loaded) == {"track_aruco.toml", "track_markerless.toml", "track_mixed.toml"}
    assert loaded["track_mixed.toml"].object("table").style == "markerless"
    assert loaded["track_markerless.toml"].targets.style == "markerless"


def test_a_region_outside_the_frames_is_refused_when_tracking(tmp_path, sine_session, run_cli):
    """``track init`` refuses a box past the frame's edge; the same roi written into track.toml by
    hand was tracked (and reported ok on every frame)."""
    text = (sine_session / "track.toml").read_text()
    cfg = tmp_path / "t.toml"
    cfg.write_text(
        text.replace('id = "block_1"\n', 'id = "block_1"\nstyle = "region"\nroi = [900.0, 200.0, 120.0, 100.0]\n', 1)
    )
    rc, _, err = run_cli("track", sine_session / "video.mkv", "--config", cfg, "-o", tmp_path / "tr.csv")
    assert rc == 2 and "block_1" in err and "960x540" in err and "roi" in err
    assert not (tmp_path / "tr.csv").exists()
