"""Phone exports (phyphox, Sensor Logger: a phone on the block): one CSV per sensor, each with its
own sample times.

Synthetic truth: a simulated rocking block's IMU log at 400 Hz; the phone's gyroscope writes
every sample, its accelerometer every other one and starting 0.1 s later (phyphox starts the
sensors one by one). Read back, the faster sensor's times and values are the truth's, the
slower one is interpolated; the block's rotation equals the one read from the truth itself.
Real: a phone bouncing on a trampoline (soerenarlt/Bounce-Analyzer-App, no licence stated: read
from the mirror, never shipped), which is no rocking block.
"""

from __future__ import annotations

import shutil
import zipfile

import numpy as np
import pytest

from rocklab import Block, G, InputError
from rocklab._diagnostics import collecting
from rocklab.models import simulate
from rocklab.synth import simulate_imu_log
from rocklab.tracking import ImuLog, block_rotation, read_imu

from _mirror import mirror_file

FS = 400.0


def _write(path, t, cols: dict) -> None:
    """A phyphox CSV: quoted header, scientific values, no final newline."""
    head = ",".join(f'"{c}"' for c in ["Time (s)", *cols])
    rows = [",".join(f"{v:.9E}" for v in vals) for vals in zip(t, *cols.values())]
    path.write_text(head + "\n" + "\n".join(rows))


@pytest.fixture(scope="module")
def truth():
    block = Block(b_m=0.1, h_m=0.4)
    res = simulate(block, theta0_rad=0.6 * block.alpha_rad, duration_s=4.0, dt_s=1e-4)
    return simulate_imu_log(
        res.t_s, res.theta_rad, block, omega_rad_s=res.omega_rad_s, rate_hz=FS, rest_before_s=1.0, rest_after_s=1.0
    )


def _export(folder, log: ImuLog, acc_step=2, acc_start=40, gyro_cols=None):
    folder.mkdir(exist_ok=True)
    t = log.t_s - log.t_s[0]
    gyro = gyro_cols or {f"Gyroscope {a} (rad/s)": log.gyro_rad_s[:, k] for k, a in enumerate("xyz")}
    _write(folder / "Gyroscope.csv", t, gyro)
    sel = np.arange(acc_start, len(t), acc_step)  # from 0.1 s at 400 Hz
    _write(
        folder / "Accelerometer.csv",
        t[sel],
        {f"Acceleration {a} (m/s^2)": log.acc_m_s2[sel, k] for k, a in enumerate("xyz")},
    )
    return folder


def test_a_phyphox_folder_and_its_zip_read_as_one_log_on_the_gyroscope_times(tmp_path, truth):
    folder = _export(tmp_path / "phone", truth)
    with collecting() as found:
        log = read_imu(folder)
    assert [d.code for d in found] == []
    assert log.format == "phyphox" and log.rate_hz == pytest.approx(FS, rel=1e-6)
    keep = np.zeros(truth.n, bool)
    keep[40 : np.arange(40, truth.n, 2)[-1] + 1] = True
    assert log.n == int(keep.sum())  # the span both sensors cover, on the faster one's times
    np.testing.assert_allclose(log.gyro_rad_s, truth.gyro_rad_s[keep], rtol=1e-8, atol=1e-12)
    # the accelerometer interpolated halfway between its samples: within the signal's change
    # over one of its periods (plus its noise), never a shifted or scaled copy
    err = np.abs(log.acc_m_s2 - truth.acc_m_s2[keep])
    assert np.median(err) < 0.02 * G and np.percentile(err, 99) < 0.3 * G
    with zipfile.ZipFile(tmp_path / "phone.zip", "w") as zf:
        for f in ("Accelerometer.csv", "Gyroscope.csv"):
            zf.write(folder / f, f)
        zf.writestr("meta/device.csv", '"property","value"\n"deviceModel","test"\n')
    z = read_imu(tmp_path / "phone.zip")
    assert z.format == "phyphox" and z.source == str(tmp_path / "phone.zip")
    np.testing.assert_array_equal(z.acc_m_s2, log.acc_m_s2)
    np.testing.assert_array_equal(z.gyro_rad_s, log.gyro_rad_s)


def test_the_block_rotation_from_the_phone_export_is_the_truths(tmp_path, truth):
    log = read_imu(_export(tmp_path / "phone", truth))
    keep = np.arange(truth.n) >= 40
    cut = ImuLog(truth.t_s[keep], truth.gyro_rad_s[keep], truth.acc_m_s2[keep], FS, source="t", format="sim")
    a, b = block_rotation(log), block_rotation(cut)
    assert a.status == "ok" and b.status == "ok"
    assert a.release_t_s == pytest.approx(b.release_t_s - b.t_s[0] + a.t_s[0], abs=2.0 / FS)
    # impacts: the same instants, but in the chattering tail (impacts 0.02-0.07 s apart, spikes a
    # sample long) the accelerometer at half the rate finds 28 where the truth's finds 31
    ia, ib = a.impact_t_s - a.t_s[0], b.impact_t_s - b.t_s[0]
    assert len(ib) >= 20 and abs(len(ia) - len(ib)) <= 0.15 * len(ib)
    np.testing.assert_allclose(ia[:15], ib[:15], atol=2.0 / FS)
    n = min(len(a.theta_rad), len(b.theta_rad))
    assert np.rad2deg(np.sqrt(np.mean((a.theta_rad[:n] - b.theta_rad[:n]) ** 2))) < 0.1


def test_phyphox_errors_name_the_file_and_the_fix(tmp_path, truth):
    folder = _export(tmp_path / "slow", truth, acc_step=8)  # 50 Hz beside 400 Hz
    with collecting() as found:
        read_imu(folder)
    assert [d.code for d in found] == ["W-IMU-RATE"] and "50 Hz" in found[0].message
    # a gyroscope that stopped before the accelerometer started: nothing to merge
    late = _export(tmp_path / "late", truth)
    lines = (late / "Gyroscope.csv").read_text().splitlines()
    (late / "Gyroscope.csv").write_text("\n".join(lines[:30]))
    with pytest.raises(InputError, match=r"late: the accelerometer \(0\.1-.* share no time span"):
        read_imu(late)
    lin = _export(tmp_path / "lin", truth)
    text = (lin / "Accelerometer.csv").read_text().replace('"Acceleration', '"Linear Acceleration')
    (lin / "Accelerometer.csv").write_text(text)
    with pytest.raises(InputError) as e:
        read_imu(lin)
    msg = str(e.value)
    assert "\n" not in msg and str(lin / "Accelerometer.csv") in msg and "gravity taken out" in msg
    with zipfile.ZipFile(tmp_path / "lin.zip", "w") as zf:
        for f in ("Accelerometer.csv", "Gyroscope.csv"):
            zf.write(lin / f, f)
    with pytest.raises(InputError, match=r"lin\.zip!Accelerometer\.csv, line 1: missing columns"):
        read_imu(tmp_path / "lin.zip")


def test_a_one_file_phyphox_table_with_acceleration_columns_reads(tmp_path, truth):
    t = truth.t_s - truth.t_s[0]
    cols = {f"Acceleration {a} (m/s^2)": truth.acc_m_s2[:, k] for k, a in enumerate("xyz")}
    cols |= {f"Gyroscope {a} (rad/s)": truth.gyro_rad_s[:, k] for k, a in enumerate("xyz")}
    _write(tmp_path / "Raw Data.csv", t, cols)
    log = read_imu(tmp_path / "Raw Data.csv")
    np.testing.assert_allclose(log.acc_m_s2, truth.acc_m_s2, rtol=1e-8, atol=1e-12)
    lin = {k.replace("Acceleration", "Linear Acceleration"): v for k, v in cols.items()}
    _write(tmp_path / "lin.csv", t, lin)
    with pytest.raises(InputError, match="gravity taken out"):
        read_imu(tmp_path / "lin.csv")


def test_a_real_phone_bouncing_is_read_and_is_no_rocking_block(tmp_path_factory):
    repo = "soerenarlt/Bounce-Analyzer-App"
    folder = tmp_path_factory.mktemp("bounce")
    for f in ("Accelerometer.csv", "Gyroscope.csv", "LinearAcceleration.csv"):
        shutil.copy(mirror_file(tmp_path_factory, repo, f, "aa3b8bf94b4dc3429b358a5041fa0c43d074cf1a"), folder / f)
    log = read_imu(folder)
    # gyroscope first sample at -0.0758 s, accelerometer at 0: the span both cover, 100 Hz
    assert log.format == "phyphox" and log.t_s[0] == 0.0 and log.rate_hz == pytest.approx(100.0, rel=1e-3)
    assert np.median(np.linalg.norm(log.acc_m_s2, axis=1)) == pytest.approx(G, abs=0.1)  # gravity kept
    with collecting() as found:
        rot = block_rotation(log)
    assert "W-IMU-NOT-ROCKING" in [d.code for d in found] and rot.status == "suspect"


def _sensor_logger(folder, log: ImuLog, acc_name="TotalAcceleration.csv"):
    """Sensor Logger's layout: time (epoch ns), seconds_elapsed, z, y, x; accelerometer every other sample."""
    folder.mkdir(exist_ok=True)
    t = log.t_s - log.t_s[0]
    for name, vals, idx in (
        ("Gyroscope.csv", log.gyro_rad_s, np.arange(len(t))),
        (acc_name, log.acc_m_s2, np.arange(40, len(t), 2)),
    ):
        rows = [
            f"{1717009637503447000 + int(round(t[i] * 1e9))},{float(t[i])!r},{float(vals[i, 2])!r},{float(vals[i, 1])!r},{float(vals[i, 0])!r}"
            for i in idx
        ]
        (folder / name).write_text("time,seconds_elapsed,z,y,x\n" + "\n".join(rows) + "\n")
    return folder


def test_a_sensor_logger_export_reads_as_the_same_log_as_phyphox(tmp_path, truth):
    a = read_imu(_export(tmp_path / "phyphox", truth))
    b = read_imu(_sensor_logger(tmp_path / "logger", truth))
    assert b.format == "sensor-logger" and b.n == a.n
    np.testing.assert_allclose(b.t_s, a.t_s, atol=1e-9)
    np.testing.assert_allclose(b.gyro_rad_s, a.gyro_rad_s, rtol=1e-7, atol=1e-9)  # z, y, x put back in order
    np.testing.assert_allclose(b.acc_m_s2, a.acc_m_s2, rtol=1e-7, atol=1e-9)
    # its Accelerometer.csv has gravity taken out: without TotalAcceleration.csv the export is refused
    only = _sensor_logger(tmp_path / "linear", truth, acc_name="Accelerometer.csv")
    with pytest.raises(
        InputError, match=r"without TotalAcceleration.csv \(its Accelerometer.csv has gravity taken out"
    ):
        read_imu(only)
    # iOS: user acceleration + CoreMotion's gravity estimate add up to the accelerometer's reading
    ios = _sensor_logger(tmp_path / "ios", truth, acc_name="Accelerometer.csv")
    grav = np.zeros_like(truth.acc_m_s2)
    grav[:, 2] = G
    user = ImuLog(truth.t_s, truth.gyro_rad_s, truth.acc_m_s2 - grav, FS)
    _sensor_logger(ios, user, acc_name="Accelerometer.csv")
    g_only = ImuLog(truth.t_s, truth.gyro_rad_s, grav, FS)
    _sensor_logger(tmp_path / "g", g_only, acc_name="Gravity.csv")
    (ios / "Gravity.csv").write_text((tmp_path / "g" / "Gravity.csv").read_text())
    c = read_imu(ios)
    assert c.format == "sensor-logger" and c.n == a.n
    np.testing.assert_allclose(c.acc_m_s2, a.acc_m_s2, rtol=1e-7, atol=1e-9)


def test_phyphox_headers_separators_and_decimal_commas_of_other_app_versions(tmp_path, truth):
    """Older phyphox versions name the axes 'X (m/s^2)' / 'X (rad/s)'; its export options give tab-
    and semicolon-separated files with a decimal point or comma."""
    ref = read_imu(_export(tmp_path / "ref", truth))
    for sep, dec in ((",", "."), (";", "."), (";", ","), ("\t", ",")):
        folder = _export(tmp_path / f"v{ord(sep)}{ord(dec)}", truth)
        for name, unit in (("Accelerometer.csv", "m/s^2"), ("Gyroscope.csv", "rad/s")):
            lines = (folder / name).read_text().splitlines()
            head = f'"Time (s)"{sep}"X ({unit})"{sep}"Y ({unit})"{sep}"Z ({unit})"'
            rows = [r.replace(",", sep).replace(".", dec) if dec == "," else r.replace(",", sep) for r in lines[1:]]
            (folder / name).write_text("\n".join([head, *rows]))
        log = read_imu(folder)
        np.testing.assert_allclose(log.acc_m_s2, ref.acc_m_s2, rtol=1e-8, err_msg=f"{sep!r} {dec!r}")
        np.testing.assert_allclose(log.gyro_rad_s, ref.gyro_rad_s, rtol=1e-8, err_msg=f"{sep!r} {dec!r}")


def test_phone_exports_missing_a_sensor_say_which_and_sensors_from_two_recordings_are_flagged(tmp_path, truth):
    folder = _export(tmp_path / "gyro_only", truth)
    (folder / "Accelerometer.csv").unlink()
    with pytest.raises(InputError, match="a phyphox export without Accelerometer.csv"):
        read_imu(folder)
    (folder / "Linear Acceleration.csv").write_text('"Time (s)","Linear Acceleration x (m/s^2)"\n0,0\n')
    with pytest.raises(InputError, match="with Linear Acceleration.csv but no Accelerometer.csv: .*gravity taken out"):
        read_imu(folder)
    acc_only = _export(tmp_path / "acc_only", truth)
    (acc_only / "Gyroscope.csv").unlink()
    with zipfile.ZipFile(tmp_path / "acc_only.zip", "w") as zf:
        zf.write(acc_only / "Accelerometer.csv", "Accelerometer.csv")
    for p in (acc_only, tmp_path / "acc_only.zip"):
        with pytest.raises(InputError, match="without Gyroscope.csv"):
            read_imu(p)
    # a paused recording: the gyroscope stops after a third of the accelerometer's span
    paused = _export(tmp_path / "paused", truth)
    lines = (paused / "Gyroscope.csv").read_text().splitlines()
    (paused / "Gyroscope.csv").write_text("\n".join(lines[: len(lines) // 3]))
    with collecting() as found:
        read_imu(paused)
    assert [d.code for d in found] == ["W-IMU-CLOCK"] and "only the" in found[0].message


@pytest.mark.parametrize(
    "scale, unit, says",
    [
        (1.0 / G, "m/s^2", "values in g read as m/s^2"),  # g values under an m/s^2 header
        (1.0, "g", "values in m/s^2 read as g"),  # m/s^2 values under a (g) header
        (0.0, "m/s^2", "gravity is not in it"),  # a linear accelerometer (plus its noise below)
    ],
)
def test_an_accelerometer_that_does_not_read_gravity_is_refused(tmp_path, truth, scale, unit, says):
    t = truth.t_s - truth.t_s[0]
    rng = np.random.default_rng(3)
    acc = truth.acc_m_s2 * scale + (rng.normal(0, 0.05, truth.acc_m_s2.shape) if scale == 0 else 0)
    cols = {f"Gyroscope {a} (rad/s)": truth.gyro_rad_s[:, k] for k, a in enumerate("xyz")}
    cols |= {f"Accelerometer {a} ({unit})": acc[:, k] for k, a in enumerate("xyz")}
    _write(tmp_path / "log.csv", t, cols)
    with pytest.raises(InputError) as e:
        read_imu(tmp_path / "log.csv")
    msg = str(e.value)
    assert "\n" not in msg and str(tmp_path / "log.csv") in msg and says in msg
