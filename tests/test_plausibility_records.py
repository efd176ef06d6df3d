"""Records: units only from a units field, truncated files, exact-zero crossings, plausibility warnings."""

import math

import numpy as np
import pytest

from rocklab import G, InputError
from rocklab._diagnostics import RocklabWarning, collecting
from rocklab.series import BaseMotion
from rocklab.models import load_base_motion, pulse_parameters, simulate
from rocklab.models import lobe_impulses

VALUES = [f"{v: .7E}" for v in 0.1 * np.sin(np.linspace(0, 6, 40))]


def _at2(
    tmp_path,
    station="El Centro Array #9, 180",
    units_line="ACCELERATION TIME SERIES IN UNITS OF G",
    values=VALUES,
    name="r.AT2",
    npts=None,
):
    rows = [" ".join(values[i : i + 5]) for i in range(0, len(values), 5)]
    text = (
        "\n".join(
            [
                "PEER NGA STRONG MOTION DATABASE RECORD",
                f"Imperial Valley-02, 5/19/1940, {station}",
                units_line,
                f"NPTS= {npts or len(values):6d}, DT=   .0100 SEC,",
            ]
            + rows
        )
        + "\n"
    )
    p = tmp_path / name
    p.write_text(text)
    return p


@pytest.mark.parametrize("station", ["Galway, Ireland", "Portugal - Lisbon CM/S station", "GAL 12"])
def test_units_never_guessed_from_free_text(tmp_path, station):
    rec = load_base_motion(_at2(tmp_path, station=station))
    # the units line says g: a_max is 0.1 g whatever the station line says (was read as Gal: 981x too small)
    assert rec.pga_m_s2 == pytest.approx(0.1 * G * np.max(np.abs(np.sin(np.linspace(0, 6, 40)))), rel=1e-6)
    assert rec.meta["units_from"] == "header"


@pytest.mark.parametrize(
    "line, factor",
    [("ACCELERATION TIME SERIES IN UNITS OF CM/S/S", 0.01), ("The units are (g)", G), ("UNITS: m/s2", 1.0)],
)
def test_units_field_forms(tmp_path, line, factor):
    rec = load_base_motion(_at2(tmp_path, units_line=line))
    assert rec.pga_m_s2 == pytest.approx(factor * 0.1 * np.max(np.abs(np.sin(np.linspace(0, 6, 40)))), rel=1e-6)


@pytest.mark.parametrize(
    "line, words",
    [
        ("VELOCITY TIME SERIES IN UNITS OF CM/S", "velocity"),
        ("DISPLACEMENT TIME SERIES IN UNITS OF CM", "displacement"),
        ("TIME SERIES IN UNITS OF CM/S", "velocity"),
        ("TIME SERIES IN UNITS OF FURLONGS", "unknown units"),
    ],
)
def test_not_acceleration_is_an_error(tmp_path, line, words):
    with pytest.raises(InputError, match=words) as e:
        load_base_motion(_at2(tmp_path, units_line=line))
    assert "\n" not in str(e.value) and "line 3" in str(e.value)


def test_value_cut_mid_token_is_an_error(tmp_path):
    vals = list(VALUES)
    vals[-1] = vals[-1].strip()[:7]  # "-.17901" for "-.1790158E-03": NPTS still matches
    with pytest.raises(InputError, match="cut off"):
        load_base_motion(_at2(tmp_path, values=vals))
    # an intact file of the same values reads
    assert load_base_motion(_at2(tmp_path, name="ok.AT2")).t_s.size == 40


def test_exact_zero_crossings_split_lobes():
    # a sampled sine with exact zeros at its crossings: each half cycle is its own lobe
    n, f, dt = 2000, 1.0, 1e-3
    t = np.arange(n) * dt
    a = np.sin(2 * np.pi * f * t)
    a[np.abs(a) < 1e-9] = 0.0
    a[::500] = 0.0
    imp, ts, te = lobe_impulses(a, dt)
    big = np.abs(imp) > 1e-6
    assert big.sum() == 4
    trapz = dt * np.sum(np.sin(np.pi * np.arange(501) / 500))  # the polyline's area of one half cycle
    assert np.abs(imp[big][:3]) == pytest.approx(trapz, rel=1e-9)  # the 4th is cut by the record end
    p = pulse_parameters(BaseMotion.from_samples(a, dt))
    assert p.t_p_s == pytest.approx(0.5 / f, rel=1e-4)  # was 0.001 s when zeros merged the lobes
    # a plateau of zeros between pulses of one sign keeps them apart too
    b = np.concatenate((np.sin(np.linspace(0, np.pi, 101)), np.zeros(50), np.sin(np.linspace(0, np.pi, 101))))
    imp, _, _ = lobe_impulses(b, 0.01)
    assert np.sort(np.abs(imp))[-2:] == pytest.approx(
        [np.sum(np.sin(np.linspace(0, np.pi, 101))[:-1]) * 0.01] * 2, rel=1e-3
    )


def test_plausibility_warnings(tmp_path):
    big = [f"{v: .7E}" for v in 60 * np.sin(np.linspace(0, 6, 40))]  # 60 g: a unit error
    with pytest.warns(RocklabWarning, match="W-RECORD-PGA"):
        load_base_motion(_at2(tmp_path, values=big))
    coarse = tmp_path / "coarse.txt"
    coarse.write_text("\n".join(f"{0.5 * i} {0.1 * math.sin(i)}" for i in range(40)))
    with collecting() as found:
        load_base_motion(coarse, units="g")
    assert [d.code for d in found] == ["W-RECORD-DT"] and found[0].severity == "suspect"
    two = tmp_path / "two.txt"
    two.write_text("0 0.1\n0.01 -0.1\n")
    with collecting() as found:
        rec = load_base_motion(two, units="g")
    assert [d.code for d in found] == ["W-RECORD-SHORT"]
    with pytest.raises(InputError, match="needs at least 16"):
        pulse_parameters(rec)


def test_real_records_raise_no_warning(shared_data):
    # pytest runs with filterwarnings=error: any W- warning here fails the test
    for f in sorted((shared_data / "records").glob("*.AT2")):
        pulse_parameters(load_base_motion(f))
    for f in sorted((shared_data / "records" / "fema-p695-far-field").glob("*.txt")):
        load_base_motion(f, units="g")


def test_step_checked_against_block_frequency():
    from rocklab import Block

    blk = Block(0.045, 0.2025)  # p = 8.42 rad/s
    with pytest.raises(InputError, match="too coarse") as e:
        simulate(blk, theta0_rad=0.05, duration_s=10, dt_s=1.0)  # p dt = 8: was "overturned", theta = 29 rad
    assert "\n" not in str(e.value)
    with pytest.raises(InputError, match="too coarse"):
        simulate(Block(1e-9, 2e-9), theta0_rad=1e-10, duration_s=1)  # a 1 nm block at the default dt
    with pytest.warns(RocklabWarning, match="W-SIM-DT"):
        simulate(blk, theta0_rad=0.05, duration_s=2, dt_s=0.005)
    with pytest.raises(InputError, match="GiB of memory"):
        simulate(blk, theta0_rad=0.05, duration_s=1e9)


def test_warning_codes_documented():
    """docs/warnings.md lists every code with its severity (regenerate with codes_markdown())."""
    from pathlib import Path

    from rocklab._diagnostics import WARNING_CODES, codes_markdown

    page = (Path(__file__).resolve().parents[1] / "docs" / "warnings.md").read_text(encoding="utf-8")
    assert page.endswith(codes_markdown())
    # every code is raised somewhere in the package (no dead entries)
    src = "".join(
        p.read_text(encoding="utf-8")
        for p in (Path(__file__).resolve().parents[1] / "rocklab").rglob("*.py")
        if p.name != "_diagnostics.py"
    )
    assert [c for c in WARNING_CODES if f'"{c}"' not in src] == []


def test_given_units_decide_over_an_unknown_header(tmp_path):
    """The error for unknown header units says 'give --units'; given, they decide (velocity stays an error)."""
    p = _at2(tmp_path, units_line="TIME SERIES IN UNITS OF FURLONGS")
    rec = load_base_motion(p, units="g")
    assert rec.pga_m_s2 == pytest.approx(0.1 * G * np.max(np.abs(np.sin(np.linspace(0, 6, 40)))), rel=1e-6)
    assert rec.meta["units_from"] == "option"
    with pytest.raises(InputError, match="velocity"):
        load_base_motion(_at2(tmp_path, units_line="VELOCITY TIME SERIES IN UNITS OF CM/S", name="v.AT2"), units="g")
