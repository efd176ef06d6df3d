"""The table IMU fused with the film's table displacement (``rocklab.tracking.fuse_table_motion``),
on synthetic tables with known truth: the IMU log from the IMU simulator through
``table_acceleration`` (gravity removed at its rest), the film's displacement at 50 fps with a
960×540 tracker's noise (0.02 mm) through ``table_motion``, the clocks found by ``sync_offset``,
as ``rocklab run`` does (``fuse_with_video``)."""

import numpy as np
import pytest

from rocklab._diagnostics import collecting

SIGMA_X_M = 2e-5  # the demo's tracked table: noise floor 0.020 mm (960x540, H.264)


def _tables():
    from rocklab.fitting import catalogue_block
    from rocklab.models import bundled_record
    from rocklab.synth._scripted_motion import record_table, sine_pulse_table

    up = catalogue_block("B5L").uplift_acc_m_s2
    return {
        "sine": (sine_pulse_table(1.0, 0.6, 0.045), 3.0),  # thesis Fig. 31's pulse
        "sine_slow": (sine_pulse_table(1.0, 0.8, 0.045), 3.0),
        "elcentro": (record_table(bundled_record("elcentro"), 0.6, 6.9, 0.01, 1.6 * up), 8.0),  # the demo's B5L
    }


TABLES = _tables()


def _measure(table, seed, T, *, bias_g=0.0, scale=1.0, lead_s=None):
    """(video TableMotion, IMU t on its own clock, IMU acceleration) of one synthetic run."""
    from rocklab.synth._imu_sim import simulate_imu_log
    from rocklab.tracking import table_acceleration, table_motion

    rng = np.random.default_rng(seed)
    t0 = -rng.uniform(0.5, 1.5) if lead_s is None else -lead_s  # the IMU log starts before the film
    tg = np.arange(t0 - 0.1, T + 0.1, 1e-3)
    log = simulate_imu_log(
        np.array([t0, T]), np.zeros(2), None, rate_hz=256.0, t_start_s=t0, base=(tg, scale * table.a(tg)),
        drop_bursts=2, seed=seed, acc_bias_g=[bias_g, 0.0, 0.0], gyro_bias_deg_s=0.5, clock_offset_s=0.3,
    )  # fmt: skip
    ta = table_acceleration(log, axis=None)
    tv = np.arange(int(T * 50)) / 50.0
    video = table_motion(tv, table.u(tv) + SIGMA_X_M * rng.standard_normal(tv.size))
    return video, ta.t_s, ta.acc_m_s2


def _rel_rms(t, a, table, T):
    m = (t >= 0) & (t <= T - 0.1) & np.isfinite(a)
    true = table.a(t[m])
    return float(np.sqrt(np.mean((a[m] - true) ** 2)) / np.sqrt(np.mean(true**2)))


def _fuse(name, seed, **kw):
    from rocklab.pipelines.experiment._measure import fuse_with_video

    table, T = TABLES[name]
    video, ti, ai = _measure(table, seed, T, **kw)
    with collecting() as diags:
        motion, sync, fusion = fuse_with_video(ti, ai, video, max_offset_s=2.0)
    return table, T, video, (ti - sync.offset_s) / (1 + sync.drift), ai, motion, fusion, diags


@pytest.mark.parametrize("name, seed", [("sine", 0), ("sine", 1), ("sine", 2), ("sine_slow", 0)])
def test_fused_sine_pulse_table_within_one_percent(name, seed):
    table, T, video, ti, ai, motion, fusion, diags = _fuse(name, seed)
    e_f = _rel_rms(motion.t_s, motion.ax_m_s2, table, T)
    # measured 0.51 / 0.51 / 0.49 % (IMU alone 1.8 %, film alone 3.0-3.5 %); the 0.8 s pulse 0.69 %
    # (IMU 2.8 %, film 2.5 %)
    assert e_f <= 0.01
    assert e_f < 0.5 * _rel_rms(ti, ai, table, T)
    assert e_f < 0.4 * _rel_rms(video.t_s, video.ax_m_s2, table, T)
    assert motion.source == "fused" and fusion.status == "ok" and not diags


#: record -> (bound on the fused error, on its ratio to the IMU's alone, to the film's alone)
RECORD_BOUNDS = {"elcentro": (0.024, 0.4, 0.3), "sfern": (0.03, 0.6, 0.25)}


@pytest.mark.parametrize("name, seed", [("elcentro", 0), ("elcentro", 1), ("sfern", 2)])
def test_fused_record_table_beats_each_source_and_its_sigma_holds(name, seed, request):
    """Records on the demo's sensors. El Centro: the Wiener bound with the true spectrum is 2.0 % (the
    IMU's 5 mg per sample over the record's 2-15 Hz, for a stationary signal), so 1 % is out of reach;
    the fusion gets 2.0-2.1 % (IMU alone 6.1-6.5 %, film alone 8.3-9.4 %). San Fernando (Pacoima,
    ../shared): 2.5 % (IMU 4.8 %, film 12.5 %)."""
    from rocklab.pipelines.experiment._measure import fuse_with_video

    if name == "sfern":
        shared = request.getfixturevalue("shared_data")  # skips without ../shared
        from rocklab.models import load_base_motion
        from rocklab.synth._scripted_motion import record_table

        rec = load_base_motion(str(shared / "records" / "RSN68_SFERN_PEL090.AT2"))
        table, T = record_table(rec, 0.6, 6.9, 0.01, TABLES["elcentro"][0].info["target_pga_m_s2"]), 8.0
    else:
        table, T = TABLES[name]
    video, ti, ai = _measure(table, seed, T)
    with collecting() as diags:
        motion, sync, fusion = fuse_with_video(ti, ai, video, max_offset_s=2.0)
    ti = (ti - sync.offset_s) / (1 + sync.drift)
    e_f = _rel_rms(motion.t_s, motion.ax_m_s2, table, T)
    bound, vs_imu, vs_film = RECORD_BOUNDS[name]
    assert e_f <= bound
    assert e_f < vs_imu * _rel_rms(ti, sync.sign * ai, table, T)
    assert e_f < vs_film * _rel_rms(video.t_s, video.ax_m_s2, table, T)
    m = (motion.t_s > 0) & (motion.t_s < T - 0.1)
    z = (motion.ax_m_s2 - table.a(motion.t_s))[m] / motion.sigma_ax_m_s2[m]
    assert 0.5 < np.sqrt(np.mean(z**2)) < 1.3  # the smoother's sigma is the error's scale (El Centro 0.82-0.86)
    assert fusion.status == "ok" and not diags
    # the table's displacement within a few film noise levels of the truth
    x_true = table.u(motion.t_s[m]) - table.u(0.0)
    assert np.sqrt(np.mean((motion.x_m[m] - x_true) ** 2)) < 3 * SIGMA_X_M
    assert motion.columns()["sigma_acc_m_s2"].shape == motion.t_s.shape


@pytest.mark.parametrize("bias_g", [0.02, -0.01])
def test_offset_imu_is_flagged_and_taken_out(bias_g):
    """An IMU that reads an offset after its rest (gravity leaking through a tilt: 0.01 g is 0.6°):
    flagged W-TABLE-FUSION; the offset is found and the fused table keeps the film's truth."""
    table, T = TABLES["sine"]
    video, ti, ai = _measure(table, 4, T)
    t_rest = ti[0] + 0.5
    ai = ai + np.where(ti > t_rest, bias_g * 9.80665, 0.0)  # the table tilts after the rest
    from rocklab.pipelines.experiment._measure import fuse_with_video

    with collecting() as diags:
        motion, _, fusion = fuse_with_video(ti, ai, video, max_offset_s=2.0)
    assert fusion.status == "suspect" and [d.code for d in diags] == ["W-TABLE-FUSION"]
    assert "offset" in fusion.message
    late = motion.t_s > 0.5
    assert np.median(fusion.imu_bias_m_s2[late]) == pytest.approx(bias_g * 9.80665, rel=0.05)
    assert _rel_rms(motion.t_s, motion.ax_m_s2, table, T) <= 0.015


def test_imu_scale_error_is_flagged():
    """An IMU reading 8 % high disagrees with the film's displacement at the shaking's frequencies."""
    _, _, _, _, _, _, fusion, diags = _fuse("sine", 5, scale=1.08)
    assert fusion.status == "suspect" and [d.code for d in diags] == ["W-TABLE-FUSION"]
    assert fusion.video_nis > 3.0


def _pitching_table_log(seed, pitch_deg):
    """A table IMU on a sine-pulse table that also pitches (``pitch_deg`` at 3 Hz while it shakes):
    the accelerometer reads gravity through the tilt, the gyro the pitch rate (with its bias)."""
    from rocklab.blocks import G
    from rocklab.tracking.imu import ImuLog

    table, _ = TABLES["sine"]
    rng = np.random.default_rng(seed)
    t = np.arange(-1.0, 3.0, 1 / 256.0)
    win = np.clip(np.sin(np.pi * (t - 1.0) / 1.6), 0.0, None) * ((t > 1.0) & (t < 2.6))
    psi = np.deg2rad(pitch_deg) * win * np.sin(2 * np.pi * 3.0 * (t - 1.0))
    dpsi = np.gradient(psi, t)
    a = table.a(t)
    c, s = np.cos(psi), np.sin(psi)
    acc = np.stack([c * a - s * G, np.zeros_like(t), s * a + c * G], -1)  # R_y(psi)^T (a, 0, G)
    gyro = np.stack([np.zeros_like(t), dpsi, np.zeros_like(t)], -1) + np.deg2rad([0.3, -0.5, 0.4])
    acc += 0.005 * G * rng.standard_normal(acc.shape)
    gyro += np.deg2rad(0.1) * rng.standard_normal(gyro.shape)
    return table, ImuLog(t, gyro, acc, 256.0, 0, None, "simulated", "simulated")


def test_gravity_leak_of_a_pitching_table_is_taken_out():
    """0.5 deg of pitch at 3 Hz leaks 0.086 m/s2 of gravity into the table's x: the gyro's rotation
    since the rest takes it out (the error falls to the accelerometer's noise)."""
    from rocklab.tracking import table_acceleration

    table, log = _pitching_table_log(0, 0.5)
    _, still = _pitching_table_log(0, 0.0)

    def err(ta):
        m = (ta.t_s > 1.0) & (ta.t_s < 2.6)  # while it shakes and pitches
        return float(np.sqrt(np.mean((ta.acc_m_s2[m] - table.a(ta.t_s[m])) ** 2)))

    raw, lev = table_acceleration(log, axis="x"), table_acceleration(log, axis="x", level=True)
    noise = err(table_acceleration(still, axis="x"))  # 0.049 m/s2: the sensor's own noise
    assert err(raw) > 1.2 * noise  # the leak is there (measured 0.064-0.066 against 0.047-0.050)
    assert err(lev) < 1.01 * noise  # measured within 0.1 % of the noise (seeds 0-2)
    # a level table is not made worse by the gyro (its noise integrates to 0.02 deg)
    assert err(table_acceleration(still, axis="x", level=True)) < 1.01 * noise


def test_a_long_log_is_fused_over_the_film_and_two_seconds():
    """An IMU logging 6 s before the film: the fusion covers the film's span and 2 s either side
    (memory stays bounded for long logs), and is as good as with a short lead."""
    from rocklab.pipelines.experiment._measure import fuse_with_video
    from rocklab.tracking import MARGIN_S

    table, T = TABLES["sine"]
    video, ti, ai = _measure(table, 1, T, lead_s=6.0)
    with collecting():
        motion, _, fusion = fuse_with_video(ti, ai, video, max_offset_s=8.0)
    assert motion.t_s[0] == pytest.approx(video.t_s[0] - MARGIN_S, abs=1 / 256)
    assert motion.t_s[-1] <= video.t_s[-1] + MARGIN_S
    assert _rel_rms(motion.t_s, motion.ax_m_s2, table, T) <= 0.0105 and fusion.status == "ok"


def _linear_bounds(name, sigma_a_m_s2=0.005 * 9.80665):
    """The oracle linear smoothers' error on a table (``tests/_wiener.py``), on the demo's sensors
    by default: the IMU's 5 mg per sample at 256 Hz, the film's 0.02 mm per frame at 50 fps; the
    error over the span ``_rel_rms`` reads."""
    from _wiener import linear_smoother_bounds

    table, T = TABLES[name]
    t = np.arange(-1.0, T + 1.0, 1 / 1024.0)
    mask = (t >= 0) & (t <= T - 0.1)
    return linear_smoother_bounds(table.a(t), 1024.0, mask, sigma_a_m_s2, 256.0, SIGMA_X_M, 50.0)


def test_one_percent_is_below_what_any_linear_smoother_reaches_on_el_centro():
    """The demo's El Centro table on the demo's sensors: the Wiener smoother knowing the record's
    own spectrum (an oracle) leaves 1.89 % of the RMS; knowing its spectrum over every 0.25 / 0.5 s
    of the run, 1.60 / 1.56 %. Most of it is at 5-25 Hz, where El Centro (2-15 Hz, high-passed at
    2 Hz for the table's stroke) meets the IMU's noise (the film's twice-differentiated noise
    passes the IMU's above 5 Hz). A sine pulse's energy sits at 1.7 Hz, where the film is exact:
    0.44-0.71 %. With the x-IMU3's datasheet density (160 ug/sqrt(Hz), 2.8x below the synthetic
    IMU's 440) El Centro's would be 0.92 % (stationary) / 0.79-0.81 % (local)."""
    b = _linear_bounds("elcentro")
    assert 0.017 < b["lti"] < 0.021 and b["lti_drawn"] == pytest.approx(b["lti"], rel=0.1)
    assert min(b[0.25], b[0.5]) > 0.015  # 1 % is out of reach on these sensors
    sine = _linear_bounds("sine")
    assert max(sine["lti"], sine[0.25], sine[0.5]) < 0.008  # the same sensors reach 1 % on a pulse
    # the reference responds to the sensors: a quieter IMU lowers it, no film raises it
    quiet = _linear_bounds("elcentro", 160e-6 * 9.80665 * np.sqrt(128.0))
    assert quiet["lti"] < 0.6 * b["lti"]


@pytest.mark.parametrize("name, seed, factor", [("elcentro", 0, 1.5), ("elcentro", 1, 1.5), ("sine", 1, 1.3)])
def test_fused_table_is_within_a_factor_of_the_local_oracle(name, seed, factor):
    """The smoother knows neither the spectrum nor when the table moves; it comes within ``factor``
    of the oracle knowing the true spectrum over every 0.25 s (measured: El Centro 1.27-1.37x, the
    sine pulse 1.1-1.2x) and, having adapted to the run, beats the stationary oracle on a pulse
    (0.49-0.51 % against 0.71 %); on El Centro it is within 1.15x of it."""
    table, T, video, ti, ai, motion, fusion, diags = _fuse(name, seed)
    e = _rel_rms(motion.t_s, motion.ax_m_s2, table, T)
    b = _linear_bounds(name)
    local = min(b[0.25], b[0.5])
    assert local < e < factor * local  # above an oracle (else the reference is wrong), near it
    assert e < (1.15 if name == "elcentro" else 0.8) * b["lti"]


@pytest.mark.parametrize("name", ["elcentro", "sine"])
def test_two_sigma_band_covers_the_true_error_on_an_unseen_seed(name):
    """Seed 3 (no other test's, nothing tuned on it): the true acceleration lies within ±2σ of the
    fused one on 95 % of the samples where the table moves (measured: El Centro 97.0 %, the sine
    pulse 97.4 %; nominal 95.4 %); the same band at 0.6σ would not hold it."""
    table, T, video, ti, ai, motion, fusion, diags = _fuse(name, 3)
    at = table.a(motion.t_s)
    m = (motion.t_s > 0) & (motion.t_s < T - 0.1) & (np.abs(at) > 0)
    z = (motion.ax_m_s2 - at)[m] / motion.sigma_ax_m_s2[m]
    assert 0.93 <= np.mean(np.abs(z) < 2) <= 0.995
    assert np.mean(np.abs(z) < 1.2) < 0.9
