"""Property tests (hypothesis): readers read any valid text to its numbers and fail cleanly on
damaged text; the simulator keeps its invariants for any block, release and restitution."""

from __future__ import annotations

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from rocklab import Block, G, InputError  # noqa: E402
from rocklab._diagnostics import collecting  # noqa: E402
from rocklab.models import load_base_motion, simulate  # noqa: E402
from rocklab.tracking import read_imu  # noqa: E402

SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow]
)

values = st.lists(st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False), min_size=16, max_size=120)
UNITS = [
    ("ACCELERATION TIME SERIES IN UNITS OF G", G),
    ("UNITS OF CM/S/S", 0.01),
    ("The units are (g)", G),
    ("UNITS: m/s2", 1.0),
    ("no units named here", G),
]


def _at2_text(vals, units_line, fmt, per_line, dt):
    toks = [fmt.format(v) for v in vals]
    rows = [" ".join(toks[i : i + per_line]) for i in range(0, len(toks), per_line)]
    return "\n".join(
        [
            "PEER NGA STRONG MOTION DATABASE RECORD",
            "Somewhere, 1/1/2000, Station 1",
            units_line,
            f"NPTS= {len(vals):6d}, DT= {dt:.4f} SEC,",
        ]
        + rows
    ) + "\n", toks


@SETTINGS
@given(
    vals=values,
    unit=st.sampled_from(UNITS),
    fmt=st.sampled_from(["{: .7E}", "{:10.5f}", "{:.6e}"]),
    per_line=st.integers(1, 8),
    dt=st.sampled_from([0.005, 0.01, 0.02]),
)
def test_at2_reads_any_valid_file_to_its_numbers(tmp_path_factory, vals, unit, fmt, per_line, dt):
    text, toks = _at2_text(vals, unit[0], fmt, per_line, dt)
    p = tmp_path_factory.mktemp("at2") / "r.AT2"
    p.write_text(text)
    with collecting():  # plausibility notes (e.g. an all-small record) are not the point here
        try:
            rec = load_base_motion(p)
        except InputError as e:
            # the only valid reason to refuse a well-formed file: nothing but zeros written
            assert "zeros" in str(e) or "0 samples" in str(e), e
            return
    expect = np.array([float(t) for t in toks]) * unit[1]
    np.testing.assert_allclose(rec.acc_m_s2, expect, rtol=0, atol=1e-12)
    assert rec.dt_s == pytest.approx(dt, rel=1e-9)


@SETTINGS
@given(
    vals=values,
    cut=st.integers(0, 10_000),
    junk=st.binary(min_size=1, max_size=12),
    mode=st.sampled_from(["insert", "truncate", "replace"]),
)
def test_at2_damaged_text_reads_or_fails_cleanly(tmp_path_factory, vals, cut, junk, mode):
    text, _ = _at2_text(vals, UNITS[0][0], "{: .7E}", 5, 0.01)
    data = text.encode()
    i = cut % len(data)
    data = {
        "insert": data[:i] + junk + data[i:],
        "truncate": data[:i],
        "replace": data[:i] + junk + data[i + len(junk) :],
    }[mode]
    p = tmp_path_factory.mktemp("bad") / "r.AT2"
    p.write_bytes(data)
    with collecting():
        try:
            rec = load_base_motion(p)
        except InputError as e:
            assert "\n" not in str(e)  # one line
            return
    # it read: then every value must be one of the file's own numbers, NPTS of them
    assert np.all(np.isfinite(rec.acc_m_s2)) and rec.t_s.size == len(vals)


IMU_HEAD = (
    "Timestamp (us),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
    "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)"
)


@SETTINGS
@given(
    n=st.integers(20, 200),
    rate=st.sampled_from([100.0, 256.0, 400.0]),
    seed=st.integers(0, 2**16),
    cut=st.integers(0, 10_000),
    damage=st.booleans(),
)
def test_imu_csv_reads_or_fails_cleanly(tmp_path_factory, n, rate, seed, cut, damage):
    rng = np.random.default_rng(seed)
    t_us = 1000 + np.rint(np.arange(n) / rate * 1e6).astype(np.int64)
    gyro = rng.normal(0, 20, (n, 3))
    acc = rng.normal(0, 0.3, (n, 3)) + [0, 0, 1]
    rows = [
        f"{t},{g[0]:.6f},{g[1]:.6f},{g[2]:.6f},{a[0]:.6f},{a[1]:.6f},{a[2]:.6f}" for t, g, a in zip(t_us, gyro, acc)
    ]
    text = IMU_HEAD + "\n" + "\n".join(rows) + "\n"
    d = tmp_path_factory.mktemp("imu")
    if damage:
        i = cut % len(text)
        text = text[:i] + text[i + 3 :]
    (d / "Inertial.csv").write_text(text)
    with collecting():
        try:
            log = read_imu(d)
        except InputError as e:
            assert damage and "\n" not in str(e)
            return
    if not damage:
        np.testing.assert_allclose(log.gyro_rad_s, np.deg2rad(np.round(gyro, 6)), atol=1e-9)
        np.testing.assert_allclose(log.acc_m_s2, np.round(acc, 6) * G, atol=1e-9)
        assert log.rate_hz == pytest.approx(rate, rel=1e-3)
    else:
        assert log.n >= 1 and np.all(np.isfinite(log.gyro_rad_s)) and np.all(np.isfinite(log.acc_m_s2))


@settings(max_examples=40, deadline=None)
@given(b=st.floats(0.02, 0.5), hb=st.floats(1.5, 10.0), f=st.floats(0.1, 0.95), eta=st.floats(0.3, 0.99))
def test_simulator_invariants(b, hb, f, eta):
    """Energy never rises; at every impact |omega+ / omega-| equals the law's eta."""
    blk = Block(b, hb * b)
    res = simulate(blk, theta0_rad=f * blk.alpha_rad, duration_s=3.0, restitution="constant", eta=eta)
    E = res.energy_J
    assert np.all(np.diff(E) <= 1e-6 * E[0] + 1e-15)
    imp = res.impacts
    if len(imp):
        ratio = np.abs(imp["omega_after_rad_s"] / imp["omega_before_rad_s"]).to_numpy()
        np.testing.assert_allclose(ratio, eta, rtol=1e-9)
    h = simulate(blk, theta0_rad=f * blk.alpha_rad, duration_s=3.0, restitution="housner")
    if len(h.impacts):
        r = np.abs(h.impacts["omega_after_rad_s"] / h.impacts["omega_before_rad_s"]).to_numpy()
        np.testing.assert_allclose(r, blk.eta_H, rtol=1e-9)
