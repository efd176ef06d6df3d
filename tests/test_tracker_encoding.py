"""Tracker projects whose XML declaration names the wrong encoding, and the ones that cannot be read.

Tracker writes ``<?xml ... encoding="UTF-8"?>`` but some of its projects hold their text in the
platform's 8-bit encoding: ``examples/car-full-JS.trz`` and ``car-clip-22-JS.trz`` of the
OpenSourcePhysics/tracker repository have the author ``Jal\\xf3n`` as one Latin-1 byte. rocklab
said "not valid XML" for both; they now import with a note, and their marks equal those of
``car.trz``, the same project saved in UTF-8 (an independent reference: another file's bytes).
Every other Tracker file of that repository imports, or fails with one line naming the file and
the reason (an empty file, a project holding only model tracks, a ``.trz`` holding several).
"""

from __future__ import annotations

import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rocklab._diagnostics import collecting
from rocklab._errors import InputError
from rocklab.tracking.imports import read_trk

TRK = Path(__file__).parent / "data" / "importers" / "diabolo_rotation.trk"
#: The Tracker repository's mirror (GPL-3.0; its example projects are read from it when present).
TRACKER = ("/work/.mirror/OpenSourcePhysics+tracker/repo", "cc8888206d5b15b968716d4014c999d431630d16")


def _latin1_copy(tmp_path: Path, name: str = "masa A", new: str = "masa \u00c1") -> Path:
    """The diabolo project with one track renamed ``new`` and the whole text stored as Latin-1
    under its unchanged ``encoding="UTF-8"`` declaration (what the car-*-JS projects hold)."""
    text = TRK.read_text(encoding="utf-8")
    assert text.count(f">{name}<") >= 1 and 'encoding="UTF-8"' in text[:100]
    p = tmp_path / "latin1.trk"
    p.write_bytes(text.replace(f">{name}<", f">{new}<").encode("latin-1", errors="replace"))
    return p


def test_latin1_text_under_a_utf8_declaration_imports_with_a_note(tmp_path):
    ref = read_trk(TRK)
    p = _latin1_copy(tmp_path)
    raw = p.read_bytes()
    with pytest.raises(UnicodeDecodeError):
        raw.decode("utf-8")  # the file is what the test says: not UTF-8
    with collecting() as found:
        pts = read_trk(p)
    assert found == []
    # the accented name decoded as written, the other unchanged, every mark and time the same
    assert pts.labels == ("masa \u00c1", "masa B") and ref.labels == ("masa A", "masa B")
    assert np.array_equal(pts.xy_px, ref.xy_px, equal_nan=True)
    assert np.array_equal(pts.xy_m, ref.xy_m, equal_nan=True) and np.array_equal(pts.t_s, ref.t_s)
    line = raw[: raw.index(b"\xc1")].count(b"\n") + 1
    (note,) = [n for n in pts.notes if "declares" in n]
    assert f"declares UTF-8 but byte 0xc1 at line {line} is not UTF-8" in note and "Windows-1252" in note
    # a valid UTF-8 file gets no such note; nor does a Latin-1 file that declares it
    assert not [n for n in ref.notes if "declares" in n]
    q = tmp_path / "declared.trk"
    q.write_bytes(raw.replace(b'encoding="UTF-8"', b'encoding="ISO-8859-1"', 1))
    decl = read_trk(q)
    assert decl.labels == pts.labels and not [n for n in decl.notes if "declares" in n]


def test_unknown_declared_encoding_and_empty_and_model_only_files_are_one_line_errors(tmp_path):
    text = TRK.read_text(encoding="utf-8")
    bad = tmp_path / "bad.trk"
    bad.write_text(text.replace('encoding="UTF-8"', 'encoding="no-such-codec"', 1), encoding="utf-8")
    with pytest.raises(InputError, match=r"bad.trk: the XML declaration names the encoding 'no-such-codec'"):
        read_trk(bad)
    empty = tmp_path / "empty.trz"
    empty.write_bytes(b"")
    with pytest.raises(InputError, match=r"empty.trz: empty file \(0 bytes\)"):
        read_trk(empty)
    # only a model track (Tracker's DynamicParticle simulation): named in the error
    assert 'class="org.opensourcephysics.cabrillo.tracker.PointMass"' in text
    model = tmp_path / "model.trk"
    model.write_text(text.replace("tracker.PointMass", "tracker.DynamicParticle"), encoding="utf-8")
    with pytest.raises(InputError, match=r"model.trk: no point-mass track.*DynamicParticle.*simulation"):
        read_trk(model)


def _mirror_blob(path: str, dest: Path) -> Path | None:
    repo, commit = TRACKER
    out = subprocess.run(["git", f"--git-dir={repo}", "show", f"{commit}:{path}"], capture_output=True)
    if out.returncode != 0:
        return None  # a blob the mirror lists but does not hold (its largest files)
    dest.write_bytes(out.stdout)
    return dest


def test_every_tracker_project_of_the_tracker_repository(tmp_path):
    """13 of its 15 .trk/.trz files are held by the mirror (two .trz blobs are absent). Before:
    9 imported, car-full-JS and car-clip-22-JS failed with "not valid XML". Now 11 import; the two
    others fail with one line naming the file: Diabolo.trz holds 3 projects (each imports with
    member=), asinewave.trk holds only a model track."""
    repo, commit = TRACKER
    if not Path(repo).is_dir():
        pytest.skip("the OpenSourcePhysics/tracker repository is not mirrored here")
    names = subprocess.run(
        ["git", f"--git-dir={repo}", "ls-tree", "-r", "--name-only", commit], capture_output=True, text=True, check=True
    ).stdout.splitlines()
    projects = [n for n in names if n.lower().endswith((".trk", ".trz"))]
    assert len(projects) == 15
    ok, failed = [], {}
    for i, name in enumerate(projects):
        p = _mirror_blob(name, tmp_path / f"{i}{Path(name).suffix}")
        if p is None:
            continue
        try:
            with collecting():
                read_trk(p)
            ok.append(name)
        except InputError as exc:
            msg = str(exc)
            assert "\n" not in msg and msg.startswith(str(p)), msg
            failed[name] = msg
    assert len(ok) + len(failed) == 13
    assert len(ok) == 11 and "examples/car-full-JS.trz" in ok and "examples/car-clip-22-JS.trz" in ok
    assert set(failed) == {"examples/Diabolo.trz", "examples/asinewave.trk"}
    assert "3 .trk files inside" in failed["examples/Diabolo.trz"]
    assert "DynamicParticle" in failed["examples/asinewave.trk"]
    diabolo = tmp_path / "diabolo.trz"
    _mirror_blob("examples/Diabolo.trz", diabolo)
    with zipfile.ZipFile(diabolo) as z:
        members = [n for n in z.namelist() if n.endswith(".trk")]
    assert [len(read_trk(diabolo, member=m).t_s) for m in members] == [173, 410, 173]


def test_car_full_js_equals_the_same_project_saved_in_utf8(tmp_path):
    if not Path(TRACKER[0]).is_dir():
        pytest.skip("the OpenSourcePhysics/tracker repository is not mirrored here")
    latin = read_trk(_mirror_blob("examples/car-full-JS.trz", tmp_path / "full.trz"))
    utf8 = read_trk(_mirror_blob("examples/car.trz", tmp_path / "car.trz"))
    assert latin.labels == utf8.labels == ("masa A",) and len(latin.t_s) == 53
    assert np.array_equal(latin.xy_px, utf8.xy_px, equal_nan=True)
    assert np.array_equal(latin.xy_m, utf8.xy_m, equal_nan=True) and np.array_equal(latin.t_s, utf8.t_s)
    assert any("byte 0xf3 at line 11" in n for n in latin.notes)
