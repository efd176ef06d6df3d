"""Units of a record are never guessed or overridden (issue #31, item 3).

A unit the file states (a CSV column name, an AT2 units field) is used; ``--units`` applies
only to files that state none; a single file whose stated units disagree with ``--units`` is
a one-line error (exit 2). In a folder, ``--units`` is the default of the files that state
none, and every file keeps its own. Before: ``pulse ff1_ms2.csv --units g`` was 9.81x too
large, an AT2 in g read with ``--units m/s2`` 9.81x too small, and ``oas folder --units g``
applied g to a CSV in m/s2.
"""

import numpy as np
import pytest

from rocklab import InputError
from rocklab.blocks import G
from rocklab.models import load_base_motion

FEMA = "records/fema-p695-far-field/SortedEQFile_120111.txt"
AT2 = "records/RSN6_IMPVALL.I_I-ELC180.AT2"


@pytest.fixture
def ff1(shared_data, tmp_path):
    """The FEMA FF-1 record (headerless, g) and the same record as a t_s,acc_m_s2 CSV."""
    src = shared_data / FEMA
    arr = np.loadtxt(src)
    csv = tmp_path / "ff1_ms2.csv"
    csv.write_text("t_s,acc_m_s2\n" + "".join(f"{t:.6g},{a * G:.9g}\n" for t, a in arr[1:]))
    return src, csv


def test_csv_column_units_win(ff1):
    src, csv = ff1
    ref = load_base_motion(src, units="g")
    for u in (None, "m/s2", "m/s^2"):  # no option, or the same unit spelled two ways
        r = load_base_motion(csv, units=u)
        assert r.pga_m_s2 == pytest.approx(ref.pga_m_s2, rel=1e-6)
    with pytest.raises(InputError, match=r"column 'acc_m_s2' states the units m/s2 but the units given are g"):
        load_base_motion(csv, units="g")
    # a default (a config's) never overrides a stated unit
    assert load_base_motion(csv, default_units="g").pga_m_s2 == pytest.approx(ref.pga_m_s2, rel=1e-6)


def test_at2_header_units_win(shared_data, tmp_path):
    p = shared_data / AT2
    ref = load_base_motion(p)
    raw = np.array(" ".join(p.read_text().splitlines()[4:]).split(), float)  # the values, in g
    assert ref.meta["units_from"] == "header" and ref.pga_m_s2 / G == pytest.approx(np.abs(raw).max(), rel=1e-9)
    assert load_base_motion(p, units="g").pga_m_s2 == ref.pga_m_s2
    with pytest.raises(InputError, match=r"header \(line 3\) states the units g but the units given are m/s2"):
        load_base_motion(p, units="m/s2")
    # the same file without its units field states none: --units then applies
    text = p.read_text().replace("IN UNITS OF G", "")
    bare = tmp_path / "bare.AT2"
    bare.write_text(text)
    r = load_base_motion(bare, units="m/s2")
    assert r.meta["units_from"] == "option"
    assert r.pga_m_s2 * G == pytest.approx(ref.pga_m_s2, rel=1e-9)
    assert load_base_motion(bare).meta["units_from"] == "PEER convention (g)"
    assert load_base_motion(bare, default_units="cm/s2").pga_m_s2 == pytest.approx(ref.pga_m_s2 / G / 100, rel=1e-9)


def test_headerless_needs_stated_units(ff1):
    src, _ = ff1
    with pytest.raises(InputError, match="headerless record"):
        load_base_motion(src)
    g = load_base_motion(src, units="g")
    assert load_base_motion(src, default_units="g").pga_m_s2 == g.pga_m_s2
    assert load_base_motion(src, units="cm/s2", default_units="g").pga_m_s2 == pytest.approx(g.pga_m_s2 / G / 100)


def test_cli_conflict_is_one_line_exit_2(ff1, shared_data, run_cli):
    src, csv = ff1
    for path, units in ((csv, "g"), (shared_data / AT2, "m/s2")):
        rc, out, err = run_cli("pulse", path, "--units", units)
        assert rc == 2 and out == "" and err.count("\n") == 1 and "states the units" in err
    rc, out, _ = run_cli("pulse", csv, "--json")
    rc2, out2, _ = run_cli("pulse", src, "--units", "g", "--json")
    import json

    assert rc == rc2 == 0
    assert json.loads(out)["a_max_m_s2"] == pytest.approx(json.loads(out2)["a_max_m_s2"], rel=1e-6)


def test_folder_units_apply_only_to_files_stating_none(ff1, monkeypatch):
    from rocklab.pipelines.spectra import _spectra_batch

    src, csv = ff1
    seen = {}

    def fake_oas(rec, slenderness, **kw):  # the OAS itself is tested elsewhere: record what it got
        seen[rec.name] = rec.pga_m_s2
        raise InputError("stop")

    monkeypatch.setattr("rocklab.models.overturning_spectrum", fake_oas)
    rows = [_spectra_batch.oas_summary_row(str(p), units="g") for p in (src, csv)]
    assert all(r["error"] == "stop" for r in rows)
    assert seen["ff1_ms2"] == pytest.approx(seen[src.stem], rel=1e-6)  # was 9.81x larger
    assert rows[0]["t_p_s"] == pytest.approx(rows[1]["t_p_s"])
