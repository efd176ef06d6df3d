"""A log that is not a rocking block is flagged whatever ``--release`` says; rocking stays clean.

- x-io's foot-mounted gait logs (xioTechnologies/Gait-Tracking-With-x-IMU,
  read from its mirror when present): ``rocklab imu straightLine --rate 256 --release none`` (the
  option the swing-growth message suggested) gave no W-IMU-NOT-ROCKING, 41 "impacts", only
  W-IMU-NO-REST: a forced run skipped the only test that caught the foot. A rocking edge stays
  put along itself, released or on a shake table, so the specific force along the rocking axis
  keeps its rest value while the block turns (rotation about the axis accelerates the sensor
  only across it); the foot swings sideways: 0.41 g RMS (straightLine, development), 0.51 and
  0.52 g (spiralStairs, stairsAndCorridor: validation), against 5-15 mg of accelerometer noise
  on simulated rocking. Bound 0.15 g.
- A table pulse that uplifts a block within 0.1 s of its start (the synthetic sessions' 0.6 s
  pulse on a squat block, three stacked blocks) was read as a thread release from upright whose
  swings "grow": W-IMU-NOT-ROCKING on rocking blocks. A block resting upright and pushed by its
  table before it turns is a forced run; read as a forced run, a block that turns unpushed (the
  tests' strides, a release) is flagged.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from rocklab import Block
from rocklab._diagnostics import collecting
from rocklab.blocks import G
from rocklab.models import simulate
from rocklab.series import BaseMotion
from rocklab.synth import simulate_imu_log
from rocklab.tracking import ImuLog, block_rotation, read_imu
from rocklab.tracking.imu import _validity

GAIT = ("/work/.mirror/xioTechnologies+Gait-Tracking-With-x-IMU/repo", "Gait Tracking With x-IMU/Datasets")
OSC = "/work/.mirror/xioTechnologies+Oscillatory-Motion-Tracking-With-x-IMU/repo"
#: measured RMS specific force along the pitch axis while turning, g (development: straightLine)
GAIT_LATERAL_G = {"straightLine": 0.412, "spiralStairs": 0.511, "stairsAndCorridor": 0.521}
FS = 256.0


def _mirror_csv(repo: str, path: str, dest: Path) -> Path:
    if not Path(repo).is_dir():
        pytest.skip(f"{repo} is not mirrored here")
    out = subprocess.run(["git", f"--git-dir={repo}", "show", f"HEAD:{path}"], capture_output=True, check=True)
    dest.write_bytes(out.stdout)
    return dest


@pytest.fixture(scope="module")
def gait_logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("gait")
    repo, folder = GAIT
    return {
        name: read_imu(_mirror_csv(repo, f"{folder}/{name}_CalInertialAndMag.csv", d / f"{name}.csv"), rate_hz=FS)
        for name in GAIT_LATERAL_G
    }


@pytest.mark.parametrize("release", ["none", "auto", "thread"])
def test_gait_logs_are_not_rocking_whatever_the_release(gait_logs, release):
    for name, log in gait_logs.items():
        with collecting() as found:
            rot = block_rotation(log, release=release)
        assert "W-IMU-NOT-ROCKING" in [d.code for d in found] and rot.status == "suspect", (name, release)
        assert rot.rocking.lateral_acc_m_s2 / G == pytest.approx(GAIT_LATERAL_G[name], abs=0.005)
        assert any("along that axis" in r for r in rot.rocking.reasons)
        # every other test but the share (spiralStairs: 83 %, turning) passes a foot: the pitch axis is level
        assert np.rad2deg(rot.rocking.axis_tilt_rad) < 0.5


@pytest.mark.parametrize("f", [0.5, 2.0])
def test_gait_verdict_holds_with_the_lateral_bound_halved_or_doubled(gait_logs, monkeypatch, f):
    monkeypatch.setattr(_validity, "LATERAL_ACC_MAX_M_S2", _validity.LATERAL_ACC_MAX_M_S2 * f)
    with collecting() as found:
        rot = block_rotation(gait_logs["straightLine"], release="none")
    assert [d.code for d in found] == ["W-IMU-NOT-ROCKING"] and rot.status == "suspect"


def test_cli_gait_release_none_text_says_what_is_meaningless(gait_logs, run_cli, tmp_path):
    repo, folder = GAIT
    p = _mirror_csv(repo, f"{folder}/straightLine_CalInertialAndMag.csv", tmp_path / "straightLine.csv")
    rc, out, err = run_cli("imu", p, "--rate", "256", "--release", "none")
    assert rc == 0 and "W-IMU-NOT-ROCKING" in err and "0.412 g RMS" in err
    assert "--release none" not in err  # the message no longer points at an option
    assert "forced run, no release (as --release none says)" in out
    assert re.search(r"41 impacts .* \(meaningless: not a rocking block\)", out)
    assert "status suspect: a warning above (W-IMU-NOT-ROCKING)" in out
    assert re.search(r"0\.4124 g RMS along it while turning \(< 0\.15 g\)", out)
    rc, _, _ = run_cli("--strict", "imu", p, "--rate", "256", "--release", "none")
    assert rc == 4


def test_oscillatory_motion_log_still_flagged(tmp_path):
    p = _mirror_csv(OSC, "LoggedData/LoggedData_CalInertialAndMag.csv", tmp_path / "osc.csv")
    for release in ("auto", "none"):
        with collecting() as found:
            rot = block_rotation(read_imu(p, rate_hz=FS), release=release)
        assert "W-IMU-NOT-ROCKING" in [d.code for d in found] and rot.status == "suspect"


def _forced(lateral_g: float, seed: int = 4):
    """A 0.06 x 0.225 m block on a 2 Hz sine burst (test_imu_forced's run), its sensor mounted 3 deg
    askew, and a table acceleration of ``lateral_g`` g RMS along the rocking edge (a sine at 3.1 Hz
    while the table shakes) added to the accelerometer: what a table moving along the edge gives."""
    block = Block(b_m=0.06, h_m=0.225)
    tb = np.arange(0.0, 4.0 + 5e-4, 1e-3)
    win = np.where((tb >= 1.0) & (tb <= 3.0), np.sin(np.pi * (tb - 1.0) / 2.0) ** 2, 0.0)
    base = BaseMotion.from_arrays(tb, 3.0 * win * np.sin(2 * np.pi * 2.0 * (tb - 1.0)), "m/s2")
    res = simulate(block, base=base, duration_s=10.0, dt_s=1e-4, restitution="constant", eta=0.9)
    S = Rotation.from_rotvec(np.deg2rad(3.0) * np.array([0.6, 0.0, 0.8])).as_matrix()
    log = simulate_imu_log(
        res.t_s, res.theta_rad, block, omega_rad_s=res.omega_rad_s, rate_hz=FS, t_start_s=-1.0,
        rest_after_s=2.0, base=base, sensor_rotation=S, seed=seed,
    )  # fmt: skip
    t = log.t_s
    side = np.where((t >= 1.0) & (t <= 3.0), np.sqrt(2) * lateral_g * G * np.sin(2 * np.pi * 3.1 * t), 0.0)
    acc = log.acc_m_s2 + np.outer(side, S @ [0.0, 1.0, 0.0])  # along the block's y: the rocking edge
    return ImuLog(t, log.gyro_rad_s, acc, FS, 0, None, "simulated", "forced"), side


def test_lateral_acceleration_is_measured_and_bounded():
    clean, _ = _forced(0.0)
    with collecting() as found:
        rot = block_rotation(clean, release="none")
    assert found == [] and rot.status == "ok" and rot.rocking.lateral_acc_m_s2 / G < 0.01
    for lateral_g, flagged in ((0.05, False), (0.3, True)):
        log, side = _forced(lateral_g)
        with collecting() as found:
            rot = block_rotation(log, release="none")
        # the RMS over the turning samples: the added sine's RMS there (an independent sum)
        w = log.gyro_rad_s - rot.gyro_bias_rad_s
        from rocklab.tracking.imu._motion_windows import moving_average, rownorm

        turning = moving_average(rownorm(w), round(0.05 * FS)) > np.deg2rad(2.0)
        truth = float(np.sqrt(np.mean(side[turning] ** 2)))
        assert rot.rocking.lateral_acc_m_s2 == pytest.approx(truth, rel=0.15, abs=0.01 * G)
        assert ("W-IMU-NOT-ROCKING" in [d.code for d in found]) == flagged, lateral_g


def _pulse_log(h_m: float, seed: int):
    """The synthetic sessions' table pulse (0.6 s, 45 mm, 1.06 g peak: ``synth --table sine``) under a
    0.1 m wide block: it uplifts within 0.1 s of the table's start (g tan alpha ~ 0.45 g)."""
    block = Block(b_m=0.1, h_m=h_m)
    tb = np.arange(0.0, 6.0, 1e-3)
    x = 2 * np.pi * np.clip(tb - 1.0, 0.0, 0.6) / 0.6
    a = np.where(
        (tb >= 1.0) & (tb <= 1.6), 0.045 / 0.6495 / 2 * (2 * np.pi / 0.6) ** 2 * (2 * np.sin(2 * x) - np.sin(x)), 0.0
    )
    base = BaseMotion.from_arrays(tb, a, "m/s2")
    res = simulate(block, base=base, duration_s=6.0, dt_s=1e-4, restitution="constant", eta=0.75)
    return simulate_imu_log(
        res.t_s, res.theta_rad, block, omega_rad_s=res.omega_rad_s, rate_hz=FS, t_start_s=-1.0,
        rest_after_s=1.0, base=base, seed=seed, drop_bursts=1,
    ), res  # fmt: skip


@pytest.mark.parametrize("h_m,seed", [(0.22, 1), (0.21, 2), (0.2, 3)])
def test_a_table_pulse_that_uplifts_at_once_is_a_forced_run_not_a_growing_release(h_m, seed):
    log, res = _pulse_log(h_m, seed)
    assert np.rad2deg(np.max(np.abs(res.theta_rad))) > 5.0  # it rocks
    with collecting() as found:
        rot = block_rotation(log)
    assert found == [] and rot.status == "ok" and rot.run_kind == "forced", [d.message for d in found]
    th = np.interp(rot.t_s, res.t_s, res.theta_rad)
    m = (rot.t_s >= 0.0) & (rot.t_s <= res.t_s[-1])
    # the sign of theta is the data's (axis found): compare magnitudes of the history
    assert np.rad2deg(np.sqrt(np.mean((np.abs(rot.theta_rad[m]) - np.abs(th[m])) ** 2))) < 0.5


def test_strides_and_a_release_read_as_forced_runs_are_flagged_by_the_missing_push():
    """A forced run's block rides its table until the table uplifts it: the accelerometer leaves its
    rest before the rotation starts (>= 3.1 times its stillness on the simulated table runs above
    and in the synthetic sessions). The tests' planar strides (no sideways motion: the lateral test
    passes them) and a block released from a held tilt start to turn unpushed (<= 1.06): read with
    --release none they are flagged, and the message sends them to --release auto, which flags the
    strides (growing half swings) and reads the release clean."""
    import test_imu_validity as v

    for log, auto_codes in ((v._gait_log(), ["W-IMU-NOT-ROCKING"]), (v._free_log(2)[0], [])):
        with collecting() as found:
            rot = block_rotation(log, release="none")
        assert [d.code for d in found] == ["W-IMU-NOT-ROCKING"] and rot.status == "suspect"
        push = float(re.search(r"left its rest by ([\d.]+) times", found[0].message).group(1))
        assert push < 1.2 and "--release auto, which keeps every test" in found[0].message
        with collecting() as found:
            block_rotation(log, release="auto")
        assert [d.code for d in found] == auto_codes
    # a table run read as one: pushed
    for h_m, seed in ((0.22, 1), (0.2, 3)):
        with collecting() as found:
            rot = block_rotation(_pulse_log(h_m, seed)[0], release="none")
        assert found == [] and rot.status == "ok"
    with collecting() as found:
        block_rotation(_forced(0.0)[0], release="none")
    assert found == []


def test_cli_text_names_the_kind_of_run_the_impacts_and_the_checks(run_cli, tmp_path):
    from rocklab.synth import write_ximu3_csv

    log, _ = _pulse_log(0.22, 1)
    write_ximu3_csv(log, tmp_path / "log")
    rot = block_rotation(read_imu(tmp_path / "log"))  # the file as the command reads it
    rc, out, err = run_cli("--strict", "imu", tmp_path / "log")
    assert rc == 0 and err == ""
    # the data, not the option, made it a forced run (it used to say "the table moved before the
    # block turned" also when --release none said so)
    assert "forced run, no release (the table moved the block from rest upright)" in out
    n = len(rot.impact_t_s)
    assert n >= 3
    listed = f"{n} impacts (theta crosses 0 with a spike or a rate step), " + (
        "at " + ", ".join(f"{x:.4f}" for x in rot.impact_t_s) if n <= 6 else f"first {rot.impact_t_s[0]:.4f}"
    )
    assert listed in out and "meaningless" not in out
    lateral = float(re.search(r"([\d.e-]+) g RMS along it while turning \(< 0\.15 g\)", out).group(1))
    assert lateral == pytest.approx(rot.rocking.lateral_acc_m_s2 / G, rel=1e-3) and lateral < 0.01
    assert "status ok: rests found before and after, gyro and accelerometer agree, the rocking checks pass" in out
    rc, out, err = run_cli("imu", tmp_path / "log", "--release", "none")
    assert rc == 0 and err == "" and "forced run, no release (as --release none says)" in out
