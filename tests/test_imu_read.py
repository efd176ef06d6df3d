"""IMU readers: real x-io logs, generated x-IMU3 / x-IMU fixtures, bad input."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from rocklab import G, InputError
from rocklab._diagnostics import collecting
from rocklab.tracking import ImuLog, ahrs_quaternions, read_imu, ximu_rate_from_registers
from rocklab.synth import simulate_imu_log, write_ximu3_csv, write_ximu_csv

XIMU = "imu/x-imu-matlab-library-example"


# ----------------------------------------------------------------------------- real files
def test_ximu_example_rate_register_is_address_69_not_54(shared_data):
    # DISCREPANCY (issue 3 and data README say "register 54: fs = 2^(value-1) Hz"):
    # in this export (firmware 7.0) address 54 is MagnetometerHardIronBiasZ (value 65386);
    # the inertial rate is the row named InertialAndMagneticDataRate at address 69
    # (value 9 -> 256 Hz).  x-IMU-MATLAB-Library xIMUdataClass.m reads address 54 for the
    # old _CalInertialMagnetic firmware and address 69 for _CalInertialAndMag; the reader
    # looks the register up by name, falling back to those addresses.
    regs = shared_data / XIMU / "00000_Registers.csv"
    df = pd.read_csv(regs)
    row54 = df[df["Address"] == 54].iloc[0]
    assert row54["Name"] == "MagnetometerHardIronBiasZ"
    assert ximu_rate_from_registers(regs) == 256.0
    # Packet-number span / sample count = packets per inertial sample; with inertial 256 Hz,
    # quaternion 128 Hz (register 70 value 8), battery 4 Hz (68: 3), date 1 Hz (67: 1):
    # (256 + 128 + 4 + 1) / 256 = 1.5195 -- an independent check that 256 Hz is right.
    log = read_imu(shared_data / XIMU)
    per = (log.packet[-1] - log.packet[0]) / (log.n - 1)
    assert per == pytest.approx(389 / 256, rel=2e-3)


def test_ximu_example_parses(shared_data):
    log = read_imu(shared_data / XIMU)
    assert log.format == "ximu-gui" and log.n == 6959 and log.rate_hz == 256.0
    assert log.dropped_samples == 0
    assert log.t_s[-1] == pytest.approx(6958 / 256)
    # First row: gyro -0.9375 deg/s, acc z 0.9780273 g (SI conversion at the boundary).
    assert log.gyro_rad_s[0, 0] == pytest.approx(np.deg2rad(-0.9375))
    assert log.acc_m_s2[0, 2] == pytest.approx(0.9780273 * G)
    # At rest at the start: |acc| ~ 1 g.
    assert np.linalg.norm(log.acc_m_s2[:100].mean(axis=0)) == pytest.approx(G, rel=0.02)


def test_ximu_example_orientation_agrees_with_device_ahrs(shared_data):
    """imufusion on the logged gyro+acc vs the device's own on-board AHRS output.

    Measured (imufusion 1.3, gain 0.5, no magnetometer, after 3 s start-up):
    tilt (gravity direction) difference RMS 0.33 deg, max 0.85 deg; pitch from
    _EulerAngles.csv RMS 0.24 deg, max 0.84 deg.  Roll/yaw are not compared:
    the log passes through pitch +-89.6 deg (gimbal lock) and yaw needs the
    magnetometer.  The x-IMU quaternion describes the earth frame relative to
    the sensor (the conjugate of imufusion's).
    """
    from scipy.spatial.transform import Rotation

    d = shared_data / XIMU
    log = read_imu(d)
    q_ours = ahrs_quaternions(log, gain=0.5)
    qd = pd.read_csv(d / "00000_Quaternion.csv")
    pk = qd.iloc[:, 0].to_numpy()
    idx = np.searchsorted(log.packet, pk) - 1
    ok = (idx >= 0) & (log.t_s[np.maximum(idx, 0)] > 3.0)
    ours = Rotation.from_quat(q_ours[idx[ok]][:, [1, 2, 3, 0]])
    dev = Rotation.from_quat(qd.iloc[:, 1:5].to_numpy()[ok][:, [1, 2, 3, 0]]).inv()
    up_ours = ours.inv().apply([0, 0, 1])
    up_dev = dev.inv().apply([0, 0, 1])
    ang = np.rad2deg(np.arccos(np.clip(np.sum(up_ours * up_dev, axis=1), -1, 1)))
    assert np.sqrt(np.mean(ang**2)) < 0.5
    assert ang.max() < 1.2
    eul = pd.read_csv(d / "00000_EulerAngles.csv").iloc[:, 2].to_numpy()[ok]
    pitch = np.rad2deg(ours.as_euler("ZYX")[:, 1])
    assert np.max(np.abs(pitch - eul)) < 1.2


def test_fusion_example_parses(shared_data):
    log = read_imu(shared_data / "imu/fusion-example/sensor_data.csv")
    assert log.format == "fusion" and log.n == 13514
    # ~100 Hz nominal; 10 gaps of ~30 ms = 2 missing samples each (counted by hand from diff).
    assert log.rate_hz == pytest.approx(99.2, abs=0.3)
    assert log.dropped_samples == 20
    assert np.all(np.diff(log.t_s) > 0)


# ----------------------------------------------------------------------------- fixtures
def _rest_then_spin(seconds=6.0, spin_deg_s=90.0):
    t = np.arange(0.0, seconds, 1e-3)
    th = np.deg2rad(spin_deg_s) * np.clip(t - 2.0, 0.0, 1.0) ** 2 * 0.5
    return t, th


def test_ximu3_fixture_drops_and_high_g(tmp_path):
    t = np.arange(0.0, 10.0, 1e-3)
    log0 = simulate_imu_log(
        t, np.zeros_like(t), None, rate_hz=400.0, drop_bursts=3, seed=3, gyro_noise_deg_s=0.1, acc_noise_g=0.005
    )
    # An impact: 30 g on x for 5 samples -- beyond the main accelerometer's 16 g.
    acc = log0.acc_m_s2.copy()
    acc[2000:2005, 0] = 30 * G
    log0 = ImuLog(log0.t_s, log0.gyro_rad_s, acc, log0.rate_hz, log0.dropped_samples)
    write_ximu3_csv(log0, tmp_path)
    head = (tmp_path / "Inertial.csv").read_text().splitlines()[0]
    assert head.startswith("Timestamp (us),Gyroscope X (deg/s)")
    log = read_imu(tmp_path)
    assert log.format == "ximu3" and log.n == log0.n
    assert log.dropped_samples == log0.dropped_samples > 0
    assert log.rate_hz == pytest.approx(400.0, rel=1e-3)
    assert np.count_nonzero(log.saturated) == 5 and log.high_g_samples == 5
    # Saturated samples come from the high-g channel (0.02 g noise), not the clipped 16 g.
    assert np.allclose(log.acc_m_s2[log.saturated, 0], 30 * G, atol=0.1 * G)


def test_ximu_gui_fixture_round_trip_with_lost_bursts(tmp_path):
    t, th = _rest_then_spin()
    log0 = simulate_imu_log(t, np.zeros_like(t), None, rate_hz=256.0, drop_bursts=2, drop_max=8, seed=11)
    inert, regs = write_ximu_csv(log0, tmp_path / "00000")
    assert inert.name == "00000_CalInertialAndMag.csv" and regs.name == "00000_Registers.csv"
    log = read_imu(tmp_path / "00000")  # base prefix accepted
    assert log.rate_hz == 256.0
    assert log.dropped_samples == log0.dropped_samples >= 6
    # Time from the sample index skips the lost samples: matches the truth clock.
    assert np.max(np.abs(log.t_s - (log0.t_s - log0.t_s[0]))) < 1e-9
    assert np.allclose(log.gyro_rad_s, log0.gyro_rad_s, atol=1e-6)


def test_legacy_calinertialmagnetic_name_uses_address_54(tmp_path):
    t = np.arange(0.0, 1.0, 1e-3)
    log0 = simulate_imu_log(t, np.zeros_like(t), None, rate_hz=128.0)
    inert, regs = write_ximu_csv(log0, tmp_path / "00001")
    old = inert.with_name("00001_CalInertialMagnetic.csv")
    inert.rename(old)
    # Old firmware registers without names: rate at address 54 (value 8 -> 128 Hz).
    regs.write_text("Packet number,Address,Value\n1,54,8\n2,69,3\n")
    log = read_imu(old)
    assert log.rate_hz == 128.0 and log.n == log0.n


# ----------------------------------------------------------------------------- mapping
def test_mapping_any_csv(tmp_path):
    rng = np.random.default_rng(0)
    n = 500
    df = pd.DataFrame(
        {"ms": np.arange(n) * 5.0, "wx": rng.normal(size=n), "wy": 0.0, "wz": 0.0, "ax": 0.0, "ay": 0.0, "az": 9.81}
    )
    p = tmp_path / "any.csv"
    df.to_csv(p, index=False)
    m = {
        "ms": "t:ms",
        "wx": "gyro_x:rad/s",
        "wy": "gyro_y:rad/s",
        "wz": "gyro_z:rad/s",
        "ax": "acc_x:m/s2",
        "ay": "acc_y:m/s2",
        "az": "acc_z:m/s2",
    }
    log = read_imu(p, mapping=m)
    assert log.format == "mapped" and log.rate_hz == pytest.approx(200.0)
    assert np.allclose(log.gyro_rad_s[:, 0], df["wx"]) and log.t_s[-1] == pytest.approx(2.495)
    with pytest.raises(InputError, match="unknown unit 'furlong'"):
        read_imu(p, mapping={**m, "ax": "acc_x:furlong"})


# ----------------------------------------------------------------------------- bad input
HEAD = (
    "Packet number,Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
    "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)"
)


def _gui(
    tmp_path,
    body,
    head=HEAD,
    regs="Packet number,Address,Value,Fixed-point value,Name\n1,69,9,NaN,InertialAndMagneticDataRate\n",
):
    p = tmp_path / "00000_CalInertialAndMag.csv"
    p.write_text(head + "\n" + body)
    if regs is not None:
        (tmp_path / "00000_Registers.csv").write_text(regs)
    return p


ROWS = "1,0,0,0,0,0,1\n3,0,0,0,0,0,1\n4,0,0,0,0,0,1\n"


@pytest.mark.parametrize(
    "case, match",
    [
        ("missing_col", r"missing columns Accelerometer Z"),
        ("units", r"line 1, 'Gyroscope X \(rpm\)': unknown unit 'rpm'"),
        ("decreasing", r"line 3, 'Packet number': decreasing"),
        ("duplicate", r"line 4, 'Packet number': duplicate"),
        ("empty", r"empty file"),
        ("header_only", r"line 2: no data rows"),
        ("not_number", r"line 3, 'Gyroscope Y \(deg/s\)'.*'abc' is not a number"),
        ("no_rate_register", r"00000_Registers.csv: no inertial rate register .*--rate"),
        ("no_registers", r"no <base>_Registers.csv .*--rate"),
    ],
)
def test_bad_input_one_line_naming_file_and_line(tmp_path, case, match):
    kw = {}
    if case == "missing_col":
        p = _gui(tmp_path, "1,0,0,0,0,0\n", head=HEAD.rsplit(",", 1)[0])
    elif case == "units":
        p = _gui(tmp_path, ROWS, head=HEAD.replace("X (deg/s)", "X (rpm)"))
    elif case == "decreasing":
        p = _gui(tmp_path, "5,0,0,0,0,0,1\n4,0,0,0,0,0,1\n")
    elif case == "duplicate":
        p = _gui(tmp_path, "1,0,0,0,0,0,1\n3,0,0,0,0,0,1\n3,0,0,0,0,0,1\n")
    elif case == "empty":
        p = tmp_path / "x.csv"
        p.write_text("")
    elif case == "header_only":
        p = _gui(tmp_path, "")
    elif case == "not_number":
        p = _gui(tmp_path, "1,0,0,0,0,0,1\n2,0,abc,0,0,0,1\n")
    elif case == "no_rate_register":
        p = _gui(
            tmp_path,
            ROWS,
            regs="Packet number,Address,Value,Fixed-point value,Name\n55,54,65386,-0.07,MagnetometerHardIronBiasZ\n",
        )
    else:
        p = _gui(tmp_path, ROWS, regs=None)
    with pytest.raises(InputError, match=match) as ei:
        read_imu(p, **kw)
    assert "\n" not in str(ei.value)


def test_rate_argument_replaces_missing_register(tmp_path):
    p = _gui(tmp_path, ROWS, regs=None)
    log = read_imu(p, rate_hz=100.0)
    assert log.t_s[-1] == pytest.approx(0.02)


def test_timestamp_errors_name_the_line(tmp_path):
    p = tmp_path / "Inertial.csv"
    p.write_text(
        "Timestamp (us),Gyroscope X (deg/s),Gyroscope Y (deg/s),Gyroscope Z (deg/s),"
        "Accelerometer X (g),Accelerometer Y (g),Accelerometer Z (g)\n"
        "100,0,0,0,0,0,1\n200,0,0,0,0,0,1\n150,0,0,0,0,0,1\n"
    )
    with pytest.raises(InputError, match=r"Inertial.csv, line 4, 'Timestamp \(us\)': decreasing"):
        read_imu(p)


# ----------------------------------------------------------------------------- CLI
def test_cli_json_and_csv_on_real_log(shared_data, run_cli, tmp_path):
    out = tmp_path / "imu.csv"
    rc, so, se = run_cli("imu", shared_data / XIMU, "--json", "-o", out)
    assert rc == 0, se
    d = json.loads(so)
    assert d["format"] == "ximu-gui" and d["sample_rate_hz"] == 256.0
    assert d["n_samples"] == 6959 and d["dropped_samples"] == 0
    assert len(d["gyro_bias_rad_s"]) == 3 and isinstance(d["impact_t_s"], list)
    # The log starts with ~0.7 s of rest (rates within +-2 deg/s) and ends while moving.
    assert d["release_t_s"] == pytest.approx(0.68, abs=0.1)
    assert np.all(np.abs(np.rad2deg(d["gyro_bias_rad_s"])) < 2.0)
    # moved by hand, not rocking: suspect (was reported with its 6 "impacts" as no_rest_after)
    assert d["status"] == "suspect" and "still moving at the end" in d["message"]
    assert [w["code"] for w in d["warnings"]] == ["W-IMU-NOT-ROCKING"]
    df = pd.read_csv(out)
    assert list(df.columns) == ["t_s", "theta_rad", "omega_rad_s", "acc_x_m_s2", "acc_y_m_s2", "acc_z_m_s2"]
    assert len(df) == 6959


def test_cli_bad_input_exit_2(run_cli, tmp_path):
    p = _gui(tmp_path, ROWS, regs=None)
    rc, so, se = run_cli("imu", p)
    assert rc == 2 and se.count("\n") == 1 and "--rate" in se


def test_fast_numeric_scanner_matches_pandas(shared_data):
    from rocklab.tracking.imu._fastcsv import parse_numeric_csv

    p = shared_data / XIMU / "00000_CalInertialAndMag.csv"
    names, vals = parse_numeric_csv(p)
    ref = pd.read_csv(p)
    assert names == list(ref.columns) and vals.shape == ref.shape
    # Correctly rounded for short decimals: identical doubles.
    assert np.array_equal(vals, ref.to_numpy(dtype=float))
    # Not all-numeric (the registers file has names and NaN): declined, pandas takes over.
    assert parse_numeric_csv(shared_data / XIMU / "00000_Registers.csv") is None


def test_cli_table_mode(run_cli, tmp_path):
    t = np.arange(0.0, 8.0, 1e-3)
    a = np.where(t > 2, 1.0 * np.sin(2 * np.pi * 2.0 * (t - 2)), 0.0)
    log = simulate_imu_log(t, np.zeros_like(t), None, base=(t, a), rate_hz=400.0, seed=9)
    write_ximu3_csv(log, tmp_path)
    out = tmp_path / "table.csv"
    rc, so, se = run_cli("imu", tmp_path, "--table", "--axis", "x", "-o", out, "--json")
    assert rc == 0, se
    d = json.loads(so)
    assert d["format"] == "ximu3" and d["pga_m_s2"] == pytest.approx(1.0, abs=0.25)  # peak incl. 5 mg noise
    df = pd.read_csv(out)
    assert list(df.columns) == ["t_s", "acc_m_s2"]
    err = df["acc_m_s2"] - np.interp(df["t_s"] - df["t_s"][0], t, a)
    assert np.sqrt(np.mean(err**2)) < 0.06


def test_fusion_example_rest_bias_and_first_motion(shared_data):
    from rocklab.tracking import block_rotation

    p = shared_data / "imu/fusion-example/sensor_data.csv"
    raw = pd.read_csv(p)
    t = raw.iloc[:, 0].to_numpy()
    # Independent look at the raw file: still (std ~0.1 deg/s) until ~12.7 s, then
    # motion (std 17 deg/s in the 13th second).
    rest_mean = raw.iloc[:, 1:4].to_numpy()[t < 12.0].mean(axis=0)
    with collecting():  # a spin about the vertical, not a rocking block (test_imu_validity)
        rot = block_rotation(read_imu(p))
    assert 12.0 < rot.release_t_s < 13.0
    assert np.allclose(np.rad2deg(rot.gyro_bias_rad_s), rest_mean, atol=0.02)


def _phyphox(tmp_path, cols, n=300, end="", rate_hz=100.0):
    """A phyphox-style export (quoted header, scientific values, no final newline by default):
    gyroscope axes 0.5 sin, 0.3 cos, 0.1 (rad/s); accelerometer (0, 0, G) m/s^2."""
    t = np.arange(n) / rate_hz
    vals = {
        "Gyroscope x (rad/s)": 0.5 * np.sin(2 * np.pi * t),
        "Gyroscope y (rad/s)": 0.3 * np.cos(2 * np.pi * t),
        "Gyroscope z (rad/s)": np.full(n, 0.1),
        "Accelerometer X (m/s^2)": np.zeros(n),
        "Accelerometer Y (m/s^2)": np.zeros(n),
        "Accelerometer Z (m/s^2)": np.full(n, G),
    }
    names = ["Time (s)"] + cols
    rows = [",".join(f"{v:.9E}" for v in [t[i]] + [vals[c][i] for c in cols]) for i in range(n)]
    p = tmp_path / "Raw Data.csv"
    p.write_text(",".join(f'"{c}"' for c in names) + "\n" + "\n".join(rows) + end)
    return p, vals


def test_a_gyroscope_only_log_is_refused_saying_an_accelerometer_is_needed(tmp_path):
    p, _ = _phyphox(tmp_path, [f"Gyroscope {a} (rad/s)" for a in "xyz"])
    with collecting() as found, pytest.raises(InputError) as e:
        read_imu(p)
    msg = str(e.value)
    assert "\n" not in msg and str(p) in msg and "gyroscope only (rad/s)" in msg and "accelerometer" in msg
    # no fix that cannot be done (renaming accelerometer columns there are none of), no deg/s names
    assert "rename" not in msg and "deg/s" not in msg
    assert [d.code for d in found] == []  # its last line is whole: not called incomplete


def test_a_whole_last_line_without_newline_is_kept_and_rad_s_stays_rad_s(tmp_path):
    cols = [f"Gyroscope {a} (rad/s)" for a in "xyz"] + [f"Accelerometer {a} (m/s^2)" for a in "XYZ"]
    for end in ("", "\n"):
        p, vals = _phyphox(tmp_path, cols, end=end)
        with collecting() as found:
            log = read_imu(p)
        assert [d.code for d in found] == [] and log.n == 300
        # the last row is read, in rad/s as written (deg/s would scale it by 1/57.3)
        assert log.gyro_rad_s[-1, 0] == pytest.approx(vals["Gyroscope x (rad/s)"][-1], rel=1e-8)
        assert log.gyro_rad_s[-1, 1] == pytest.approx(vals["Gyroscope y (rad/s)"][-1], rel=1e-8)
        assert log.acc_m_s2[-1, 2] == pytest.approx(G, rel=1e-8)
        assert log.rate_hz == pytest.approx(100.0, rel=1e-6)
    text = p.read_text().rstrip("\n")
    for cut, n_fields in ((text.rsplit(",", 2)[0], 5), (text.rsplit(",", 1)[0] + ",", 7)):
        p.write_text(cut)  # the logger stopped mid-line: fields missing, or the last one empty
        with collecting() as found:
            log = read_imu(p)
        assert [d.code for d in found] == ["W-IMU-TRUNCATED"] and log.n == 299
        assert f"line 301: last line cut short ({n_fields} of 7 fields" in found[0].message


def test_missing_columns_name_a_unit_for_each_suggested_column(tmp_path):
    cols = [f"Gyroscope {a} (rad/s)" for a in "xyz"] + [f"Accelerometer {a} (m/s^2)" for a in "XY"]
    p, _ = _phyphox(tmp_path, cols, end="\n")
    with pytest.raises(InputError) as e:
        read_imu(p)
    msg = str(e.value)
    assert "missing columns Accelerometer Z;" in msg
    assert "'Gyroscope X (rad/s)' (or '(deg/s)')" in msg and "'Accelerometer Z (m/s^2)' (or '(g)')" in msg
