"""IMU logs that used to give status ok with wrong numbers now warn or fail (issue: never silently wrong)."""

import numpy as np
import pandas as pd
import pytest

from rocklab import Block, InputError
from rocklab._diagnostics import collecting
from rocklab.models import simulate
from rocklab.tracking import block_rotation, read_imu
from rocklab.synth import simulate_imu_log, write_ximu3_csv

FS = 256.0


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    block = Block(b_m=0.1, h_m=0.4)
    res = simulate(block, theta0_rad=0.9 * block.alpha_rad, duration_s=8.0, dt_s=1e-4)
    log = simulate_imu_log(
        res.t_s,
        res.theta_rad,
        block,
        omega_rad_s=res.omega_rad_s,
        rate_hz=FS,
        rest_before_s=2.0,
        rest_after_s=2.0,
        gyro_noise_deg_s=0.1,
        gyro_bias_deg_s=np.array([0.5, -0.5, 0.5]),
        acc_noise_g=0.005,
        seed=2,
    )
    d = tmp_path_factory.mktemp("imu")
    write_ximu3_csv(log, d)
    return d, 0.9 * block.alpha_rad


def _variant(folder, tmp_path, edit):
    src, _ = folder
    df = pd.read_csv(src / "Inertial.csv")
    out = tmp_path / "v"
    out.mkdir()
    text = edit(df)
    (out / "Inertial.csv").write_text(text if isinstance(text, str) else text.to_csv(index=False))
    return out


def test_clean_log_is_ok_and_silent(folder):
    d, th0 = folder
    rot = block_rotation(read_imu(d), "y")  # filterwarnings=error: any W- warning fails here
    assert rot.status == "ok" and rot.theta0_rad == pytest.approx(th0, abs=0.005)


def _swap_xy(df):
    cx, cy = "Gyroscope X (deg/s)", "Gyroscope Y (deg/s)"
    return df.rename(columns={cx: cy, cy: cx})[df.columns]


def test_swapped_gyro_axes(folder, tmp_path):
    v = _variant(folder, tmp_path, _swap_xy)
    with collecting() as found:
        rot = block_rotation(read_imu(v))
    # was status ok with theta0 = -0.0008 rad (truth 0.35)
    assert "W-IMU-AXES" in [d.code for d in found] and rot.status == "suspect"


def test_gyro_in_rad_s_under_deg_s_headers(folder, tmp_path):
    def to_rad(df):
        for ax in "XYZ":
            df[f"Gyroscope {ax} (deg/s)"] = np.deg2rad(df[f"Gyroscope {ax} (deg/s)"])
        return df

    v = _variant(folder, tmp_path, to_rad)
    with collecting() as found:
        rot = block_rotation(read_imu(v), "y")
    assert "W-IMU-AXES" in [d.code for d in found] and rot.status != "ok"


def test_clock_jump_and_missing_rows(folder, tmp_path):
    def jump(df):
        df.loc[df.index >= 1500, "Timestamp (us)"] += 5_000_000  # a 5 s clock jump mid-rocking
        return df

    v = _variant(folder, tmp_path, jump)
    with collecting() as found:
        block_rotation(read_imu(v), "y")
    assert "W-IMU-CLOCK" in [d.code for d in found]

    def missing(df):
        return df.drop(index=range(700, 700 + int(1.2 * FS)))  # 1.2 s of rows lost while rocking

    v2 = tmp_path / "w"
    v2.mkdir()
    (v2 / "Inertial.csv").write_text(missing(pd.read_csv(folder[0] / "Inertial.csv")).to_csv(index=False))
    with collecting() as found:
        block_rotation(read_imu(v2), "y")
    assert "W-IMU-CLOCK" in [d.code for d in found]


def test_rate_option_disagreeing_with_timestamps(folder):
    with collecting() as found:
        log = read_imu(folder[0], rate_hz=100.0)
    assert [d.code for d in found] == ["W-IMU-RATE"] and log.rate_hz == pytest.approx(FS, rel=1e-3)


def test_timestamps_in_ms_under_us_header(folder, tmp_path):
    def ms(df):
        df["Timestamp (us)"] = (df["Timestamp (us)"] / 1000.0).round(3)
        return df

    v = _variant(folder, tmp_path, ms)
    with pytest.raises(InputError, match="not an IMU sample rate"):
        read_imu(v)


def test_truncated_final_line_dropped_with_a_note(folder, tmp_path):
    src, th0 = folder
    text = (src / "Inertial.csv").read_text()
    cut = text[:-20]  # the logger died mid-line: no final newline, a partial row
    v = tmp_path / "t"
    v.mkdir()
    (v / "Inertial.csv").write_text(cut)
    with collecting() as found:
        log = read_imu(v)
    assert [d.code for d in found] == ["W-IMU-TRUNCATED"] and found[0].severity == "note"
    assert log.n == text.count("\n") - 2  # header and the cut row dropped
    rot = block_rotation(log, "y")
    assert rot.theta0_rad == pytest.approx(th0, abs=0.005)


def test_real_logs_raise_only_not_rocking(shared_data):
    # neither real log is a rocking block (test_imu_validity); the reader and the rest
    # windows raise nothing else on them
    for p in (shared_data / "imu/fusion-example/sensor_data.csv", shared_data / "imu/x-imu-matlab-library-example"):
        with collecting() as found:
            block_rotation(read_imu(p))
        assert [d.code for d in found] == ["W-IMU-NOT-ROCKING"]


@pytest.mark.parametrize("given_hz", [240.0, 280.0, 512.0])
def test_a_rate_option_against_the_rate_register_warns_and_the_register_wins(shared_data, given_hz):
    # x-IMU GUI times come from packet numbers and the rate: --rate 280 on a 256 Hz export moved
    # the release and every impact by 9 % with status ok and no warning
    folder = shared_data / "imu/x-imu-matlab-library-example"
    with collecting() as diags:
        log = read_imu(folder, rate_hz=given_hz)
    assert log.rate_hz == 256.0
    assert [d.code for d in diags if d.code == "W-IMU-RATE"] == ["W-IMU-RATE"]
    with collecting() as diags:
        assert read_imu(folder, rate_hz=257.0).rate_hz == 257.0  # within 2 %: the option stands
    assert not [d for d in diags if d.code == "W-IMU-RATE"]
