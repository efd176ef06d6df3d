"""Configs and videos: typos, impossible geometry and cut files are errors or warnings, never ignored."""

import pytest

from rocklab import InputError
from rocklab._diagnostics import collecting
from rocklab.pipelines import load_experiment
from rocklab.config import load_track_config
from rocklab.tracking import track_video


def _exp(tmp_path, extra_video="", extra=""):
    (tmp_path / "v.mkv").write_bytes(b"")
    p = tmp_path / "experiment.toml"
    p.write_text(f'name = "x"\n[block]\nb_m = 0.1\nh_m = 0.2\n[sources.video]\npath = "v.mkv"\n{extra_video}{extra}')
    return p


def test_typo_inside_a_section_is_an_error(tmp_path):
    p = _exp(tmp_path, extra_video="fsp = 50\n")
    with pytest.raises(InputError) as e:
        load_experiment(p)
    msg = str(e.value)
    assert "line 7" in msg and "'sources.video.fsp'" in msg and "did you mean 'fps'" in msg and "\n" not in msg
    p = _exp(tmp_path, extra="[simulate]\nduraton_s = 3\n")
    with pytest.raises(InputError, match="did you mean 'duration_s'"):
        load_experiment(p)


def test_negative_duration_is_an_error(tmp_path):
    with pytest.raises(InputError, match="duration_s.*>= 0"):
        load_experiment(_exp(tmp_path, extra="[simulate]\nduration_s = -3\n"))


@pytest.mark.parametrize(
    "section, key, value, words",
    [
        ("video", "camera_matrix", "[[0, 0, 320], [0, 900, 180], [0, 0, 1]]", "fx, fy > 0"),
        ("reference", "homography", "[[1, 2, 0], [2, 4, 0], [0, 0, 1]]", "singular"),
    ],
)
def test_impossible_geometry_is_an_error(tmp_path, section, key, value, words):
    p = tmp_path / "track.toml"
    p.write_text(
        f'[{section}]\n{key} = {value}\n\n[[objects]]\nid = "block_1"\nkind = "block"\n'
        'style = "aruco"\nids = [0]\nmarker_size_m = 0.02\n'
    )
    with pytest.raises(InputError, match=words) as e:
        load_track_config(p)
    assert "\n" not in str(e.value) and key in str(e.value)


def test_video_cut_in_half_warns(tmp_path):
    from rocklab.synth import synth_session

    out = tmp_path / "s"
    synth_session(out, seed=1, size=(480, 270), duration_s=2.0, imu=False, mp4=False)
    full = track_video(out / "video.mkv", load_track_config(out / "track.toml"))  # no warning
    cut = tmp_path / "cut.mkv"
    data = (out / "video.mkv").read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    with collecting() as found:
        res = track_video(cut, load_track_config(out / "track.toml"))
    assert res.n_frames < 0.8 * full.n_frames
    assert [d.code for d in found] == ["W-VIDEO-SHORT"] and f"{full.n_frames} frames" in found[0].message
    assert found[0].severity == "note"


def test_no_level_reference_warns(tmp_path):
    """level = 'table' (the default) without a table used to fall back to 0 silently."""
    from rocklab.synth import synth_session

    out = tmp_path / "s"
    synth_session(out, seed=2, size=(480, 270), duration_s=0.6, imu=False, mp4=False)
    text = (out / "track.toml").read_text()
    # drop the table object and the plane homography: nothing left to level from
    head, _, objs = text.partition("[[objects]]")
    blocks = "[[objects]]" + "[[objects]]".join(o for o in objs.split("[[objects]]") if 'kind = "table"' not in o)
    head = "\n".join(ln for ln in head.splitlines() if not ln.startswith("homography"))
    (out / "t.toml").write_text(head + "\n" + blocks)
    cfg = load_track_config(out / "t.toml")
    assert cfg.table is None and cfg.reference.level == "table"
    with collecting() as found:
        track_video(out / "video.mkv", cfg)
    assert "W-LEVEL-NONE" in [d.code for d in found]
    assert "no object of kind 'table'" in [d for d in found if d.code == "W-LEVEL-NONE"][0].message
