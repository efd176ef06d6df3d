import tomllib

import pytest

from rocklab import InputError
from rocklab.config import EXAMPLE_TOML
from rocklab.pipelines import load_experiment


def _write(tmp_path, text, files=("tracks.csv",)):
    for f in files:
        (tmp_path / f).write_text("t_s,theta_rad\n0,0.01\n")
    p = tmp_path / "experiment.toml"
    p.write_text(text)
    return p


def test_example_is_valid_toml_and_documents_every_section():
    d = tomllib.loads(EXAMPLE_TOML)
    assert {"block", "contact", "sources", "sync", "fit", "simulate", "output"} <= set(d)
    assert d["block"]["b_m"] == 0.045


def test_minimal_config_with_dimensions(tmp_path):
    p = _write(tmp_path, '[block]\nb_m = 0.045\nh_m = 0.2025\n[sources.track]\npath = "tracks.csv"\n')
    cfg = load_experiment(p)
    assert cfg.primary == "track" and cfg.block().alpha_rad == pytest.approx(0.2187, abs=1e-4)
    assert cfg.laws == ("housner", "eta_e", "modified")
    assert cfg.input_files() == [p.resolve(), (tmp_path / "tracks.csv").resolve()]


@pytest.mark.parametrize(
    "text,match",
    [
        (
            '[block]\nb_m = -0.045\nh_m = 0.2\n[sources.track]\npath = "tracks.csv"\n',
            r"line 2: 'block.b_m' must be positive",
        ),
        (
            '[block]\nb_m = 0.045\nh_m = 0.2\n[sources.track]\npath = "nope.csv"\n',
            r"line 5: 'sources.track.path' names 'nope.csv'",
        ),
        (
            '[block]\nb_m = 0.045\nh_m = 0.2\n[contact]\ntype = "edge"\n[sources.track]\npath = "tracks.csv"\n',
            r"'contact.l_c_m' is required for edge contact",
        ),
        (
            '[block]\nb_m = 0.045\nh_m = 0.2\n[sources.track]\npath = "tracks.csv"\n[fit]\nwindow = "best"\n',
            r"line 7: 'fit.window' must be one of middle50, all, first",
        ),
        (
            '[block]\nb_m = 0.045\nh_m = 0.2\n[sources.track]\npath = "tracks.csv"\n[simualte]\n',
            r"'simualte' is not a known",
        ),
        ("[block]\nb_m = 0.045\nh_m = = 0.2\n", r"TOML syntax error"),
        (
            '[block]\nb_m = 0.045\nh_m = 0.2\n[sources]\nprimary = "imu"\n[sources.track]\npath = "tracks.csv"\n',
            r"'sources.primary' = 'imu' but there is no \[sources.imu\]",
        ),
        ("[block]\nb_m = 0.045\nh_m = 0.2\n", r"\[sources\] needs at least one"),
    ],
)
def test_config_errors_name_key_and_line(tmp_path, text, match):
    p = _write(tmp_path, text)
    with pytest.raises(InputError, match=match) as e:
        load_experiment(p)
    assert "\n" not in str(e.value) and str(p) in str(e.value)


def test_fingerprint_follows_the_calibration_a_track_config_names(tmp_path):
    # a run is skipped when its fingerprint is unchanged: a new lens calibration named by
    # track.toml (not by experiment.toml) must change it, or a resume reuses a stale result
    from rocklab.pipelines.experiment._experiment import fingerprint

    (tmp_path / "v.mp4").write_bytes(b"\0" * 64)
    (tmp_path / "cal.npz").write_bytes(b"first")
    (tmp_path / "track.toml").write_text(
        '[video]\ncalibration = "cal.npz"\n[[objects]]\nid = "block_1"\nkind = "block"\nmarkers = [1]\n'
    )
    (tmp_path / "experiment.toml").write_text(
        'name = "x"\n[block]\nb_m = 0.045\nh_m = 0.2\n[sources.video]\npath = "v.mp4"\ntrack_config = "track.toml"\n'
    )
    cfg = load_experiment(tmp_path / "experiment.toml")
    assert (tmp_path / "cal.npz").resolve() in [p.resolve() for p in cfg.input_files()]
    before = fingerprint(cfg)
    assert fingerprint(cfg) == before
    (tmp_path / "cal.npz").write_bytes(b"second")
    assert fingerprint(cfg) != before
