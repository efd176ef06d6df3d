"""rocklab.config: one TOML reader (line finder, unknown-key rule) and schemas that write themselves."""

from __future__ import annotations

import dataclasses
import tomllib

import pytest

from rocklab import InputError
from rocklab.config import (
    EXAMPLE_TOML,
    ExperimentConfig,
    SourceImu,
    SourceTable,
    SourceVideo,
    TargetsConfig,
    TomlDoc,
    TrackConfig,
    dumps_toml,
    experiment_name,
    load_experiment_config,
    load_track_config,
)
from rocklab.config._experiment_toml import SCHEMA

TEXT = """\
name = "top"
# a comment with name = "no"
[block]
name = "inner"
b_m = 0.1

[sources]
primary = "video"
imu.axis = "y"
[sources.video]
path = "v.mkv"
[[objects]]
id = "a"
[[objects]]
id = "b"
markers = [1]
[reference.board]
kind = "charuco"
"""


@pytest.mark.parametrize(
    "key, line",
    [
        (("name",), 1),  # a root key: above the first header, not the [block] key of that name
        (("block", "name"), 4),
        (("block", "b_m"), 5),
        (("block", "h_m"), 3),  # absent: its table's header
        (("sources", "video", "path"), 11),
        (("sources", "video", "fps"), 10),  # absent under [sources.video]: that header
        (("sources", "primary"), 8),
        (("sources", "imu", "axis"), 9),  # a dotted key in its parent table
        (("objects", 0, "id"), 13),
        (("objects", 1, "id"), 15),
        (("objects", 1, "markers"), 16),
        (("objects", 1), 14),
        (("reference", "board", "kind"), 18),
        (("reference", "level"), None),  # neither [reference] nor the key in the text
        (("b_m",), None),  # a root key that is absent: not the [block] key of that name
    ],
)
def test_line_finder(key, line):
    assert TomlDoc(tomllib.loads(TEXT), TEXT).line_of(key) == line


def test_line_finder_reads_dotted_keys_in_a_parent_table():
    text = '[sources]\nprimary = "video"\nvideo.path = "v.mkv"\n'
    assert TomlDoc(tomllib.loads(text), text).line_of(("sources", "video", "path")) == 3


def test_a_table_that_is_a_value_is_an_error(tmp_path):
    p = tmp_path / "experiment.toml"
    p.write_text('name = "x"\nblock = 3\n')
    with pytest.raises(InputError, match=r"line 2: 'block' must be a table"):
        load_experiment_config(p)


def test_one_unknown_key_rule_for_both_files(tmp_path):
    (tmp_path / "v.mkv").write_bytes(b"")
    exp = tmp_path / "experiment.toml"
    exp.write_text('[block]\nb_m = 0.1\nh_m = 0.2\n[sources.video]\npath = "v.mkv"\nobjekt = "b"\n')
    trk = tmp_path / "track.toml"
    trk.write_text('[targets]\nstyle = "aruco"\nmarker_sise_m = 0.02\n[[objects]]\nid = "b"\nmarkers = [1]\n')
    msgs = []
    for load, path in ((load_experiment_config, exp), (load_track_config, trk)):
        with pytest.raises(InputError) as e:
            load(path)
        msgs.append(str(e.value))
    assert msgs[0].startswith(f"{exp}, line 6: 'sources.video.objekt' is not a known key of [sources.video]; ")
    assert "did you mean 'object'?" in msgs[0]
    assert msgs[1].startswith(f"{trk}, line 3: 'targets.marker_sise_m' is not a known key of [targets]; ")
    assert "did you mean 'marker_size_m'?" in msgs[1]
    # the same sentence after the key, the same fix
    assert all(m.endswith("fix or remove the unknown key") for m in msgs)


def test_syntax_errors_read_alike(tmp_path):
    for name, load in (("experiment.toml", load_experiment_config), ("track.toml", load_track_config)):
        p = tmp_path / name
        p.write_text("[block]\nb_m = = 1\n")
        with pytest.raises(InputError, match=r"TOML syntax error \(.*line 2.*\); fix the syntax"):
            load(p)
        with pytest.raises(InputError, match="not found; check the path"):
            load(tmp_path / ("missing-" + name))


def test_track_defaults_come_from_the_dataclasses():
    cfg = TrackConfig.from_dict({"objects": [{"id": "b", "markers": [1]}]})
    assert cfg.targets == TargetsConfig()
    assert cfg.video == dataclasses.replace(cfg.video) and cfg.video.start_frame == 0
    # apriltag changes the dictionary's default, nothing else
    april = TrackConfig.from_dict({"targets": {"style": "apriltag"}, "objects": [{"id": "b", "markers": [1]}]})
    assert april.targets == TargetsConfig(style="apriltag", dictionary="DICT_APRILTAG_36h11")


def _files(tmp_path):
    for f in ("video.mkv", "track.toml", "truth.csv"):
        (tmp_path / f).write_text("x")
    for d in ("imu/block_1", "imu/table"):
        (tmp_path / d).mkdir(parents=True)
    return tmp_path


def test_experiment_config_round_trips_through_its_own_toml(tmp_path):
    d = _files(tmp_path)
    cfg = ExperimentConfig(
        path=(d / "experiment.toml").resolve(),
        name='run 1 "quoted"',
        b_m=0.045,
        h_m=0.2025,
        mass_kg=None,
        block_id="B6M",
        contact="edge",
        l_c_m=0.0015,
        primary="imu",
        video=SourceVideo(path=(d / "video.mkv").resolve(), track_config=(d / "track.toml").resolve(), fps=59.94),
        imu=SourceImu(path=(d / "imu" / "block_1").resolve(), axis="-y"),
        table=SourceTable(source="imu", imu=(d / "imu" / "table").resolve()),
        fit_restitution=False,
        fit_window="first",
        laws=("housner", "given"),
        eta_given=0.93,
        video_decimation=5,
        columns=("block_1",),
        column_cut_m=0.002,
        truth=(d / "truth.csv").resolve(),
        tags=(("config", "a"), ("repeat", 3), ("taped", True)),
    )
    text = cfg.to_toml(header=["written by a test"])
    assert text.startswith("# written by a test\n")
    cfg.path.write_text(text)
    assert load_experiment_config(cfg.path) == cfg
    assert 'imu = "imu/table"' in text and str(d) not in text  # paths relative to the file
    # keys at their default are left out; a changed one is written and read back
    assert "[sync]" not in text and "rrd" not in text
    other = dataclasses.replace(cfg, rrd=False, max_offset_s=2.5)
    cfg.path.write_text(other.to_toml())
    back = load_experiment_config(cfg.path)
    assert (back.rrd, back.max_offset_s) == (False, 2.5) and back == other


def test_experiment_defaults_come_from_the_dataclass(tmp_path):
    d = _files(tmp_path)
    p = d / "experiment.toml"
    p.write_text('[block]\nb_m = 0.1\nh_m = 0.2\n[sources.video]\npath = "video.mkv"\n')
    cfg = load_experiment_config(p)
    for f in dataclasses.fields(ExperimentConfig):
        if f.name in ("contact", "sync_method", "max_offset_s", "fit_window", "laws", "rrd", "column_impacts"):
            assert getattr(cfg, f.name) == (f.default if f.default is not dataclasses.MISSING else f.default_factory())
    assert cfg.video == SourceVideo(path=(d / "video.mkv").resolve()) and cfg.table == SourceTable()


def test_example_documents_exactly_the_schema():
    def leaves(node, pre=()):
        for k, v in node.items():
            free_form = (*pre, k) == ("experiment", "tags")  # a user's own names
            yield from leaves(v, (*pre, k)) if isinstance(v, dict) and not free_form else [(*pre, k)]

    documented = set(leaves(tomllib.loads(EXAMPLE_TOML)))
    schema = {(*t, k) for t, keys in SCHEMA.items() for k in keys if (*t, k) not in SCHEMA}
    assert documented == schema, documented ^ schema


def test_block_id_needs_the_catalogue_it_is_given(tmp_path):
    d = _files(tmp_path)
    p = d / "experiment.toml"
    p.write_text('[block]\nid = "B6M"\n[sources.video]\npath = "video.mkv"\n')
    cfg = load_experiment_config(p, block_catalogue=lambda: {"B6M": {"b_m": 0.045, "h_m": 0.2025, "mass_kg": 1.0}})
    assert (cfg.b_m, cfg.h_m, cfg.mass_kg, cfg.block_id) == (0.045, 0.2025, 1.0, "B6M")
    with pytest.raises(InputError, match=r"line 2: 'block.id' = 'B6M' is not in the .* catalogue"):
        load_experiment_config(p, block_catalogue=lambda: {})


def test_experiment_name(tmp_path):
    p = tmp_path / "run_a" / "experiment.toml"
    p.parent.mkdir()
    p.write_text('name = "x"\n')
    assert experiment_name(p) == "x"
    p.write_text("[block]\n")
    assert experiment_name(p) == "run_a"
    p.write_text("name = 3\n")
    assert experiment_name(p) is None
    p.write_text("name = \n")
    assert experiment_name(p) is None


def test_dumps_toml_is_read_back_equal():
    d = {
        "s": 'a "b" \\ c',
        "f": 0.1 + 0.2,
        "i": -3,
        "b": False,
        "arr": [[1.5, 2.0], [3.0, 4.0]],
        "t": {"x": 1, "sub": {"y": "z"}, "only": {"deep": {"k": 1.0}}},
        "objs": [{"id": "a", "m": [1, 2]}, {"id": "b"}],
        "skip": None,
    }
    back = tomllib.loads(dumps_toml(d, header=["h1", "h2"]))
    d.pop("skip")
    assert back == d


def test_corrections_toml_errors_name_the_line(tmp_path):
    from rocklab.tracking import load_corrections

    p = tmp_path / "fix.toml"
    p.write_text('[[corrections]]\nobject = "b"\nframe = 3\naction = "drop"\n\n[[corrections]]\nobject = "b"\n')
    with pytest.raises(InputError, match=r"fix.toml, line 6, correction 2"):
        load_corrections(p)


@pytest.mark.parametrize(
    "line, words",
    [
        ("tags = { config = 0.5 }", "config = 0.5: a tag must be a string"),
        ('tags = "a"', "must be a table of names and values"),
        ('tags = { "1x" = "a" }', "'1x', which is not usable"),
        ('tag = { a = "b" }', "did you mean 'tags'"),
    ],
)
def test_experiment_tags_are_checked_with_their_line(tmp_path, line, words):
    d = _files(tmp_path)
    p = d / "experiment.toml"
    p.write_text(f'[block]\nb_m = 0.1\nh_m = 0.2\n[sources.video]\npath = "video.mkv"\n[experiment]\n{line}\n')
    with pytest.raises(InputError, match="line 7") as e:
        load_experiment_config(p)
    assert words in str(e.value) and "\n" not in str(e.value)
