"""Rerun output is read back with rerun's own reader (rerun.chunk.RrdReader), no mocks."""

import numpy as np

from rocklab.pipelines.experiment._rerun import (
    experiment_blueprint,
    log_events,
    log_series,
    open_recording,
    read_rrd_scalars,
    read_rrd_summary,
)


def test_series_and_events_round_trip(tmp_path):
    path = tmp_path / "s.rrd"
    rec = open_recording("rocklab_test", path, recording_id="t")
    t = np.linspace(0, 2, 401)
    th = 0.1 * np.exp(-t) * np.cos(9 * t)
    th_nan = th.copy()
    th_nan[10:20] = np.nan  # lost frames are not logged, never invented
    assert log_series(rec, "experiment/block_1/theta/measured_video", t, th_nan) == 391
    log_series(rec, "experiment/block_1/theta/sim_housner", t, th)
    log_events(rec, "experiment/block_1/impacts", [0.3, 0.7], ["impact 1", "impact 2"], values=[0.0, 0.0])
    rec.send_blueprint(experiment_blueprint(["experiment/block_1"], has_video=False))
    rec.flush()
    rec.disconnect()

    rows = read_rrd_summary(path)
    assert rows["/experiment/block_1/theta/measured_video"] == 391
    assert rows["/experiment/block_1/impacts"] == 2
    tt, vv = read_rrd_scalars(path, "experiment/block_1/theta/sim_housner")
    assert tt.size == 401
    assert np.allclose(tt, t, atol=1e-9) and np.allclose(vv, th, rtol=0, atol=1e-12)


def test_review_opens_on_the_impact_with_the_largest_residual(tmp_path):
    import pandas as pd

    from rocklab.pipelines.experiment._log_experiment import _focus

    t = np.linspace(0, 3, 3001)
    sim = 0.05 * np.cos(6 * t)
    impacts = pd.DataFrame({"t_s": [0.25, 0.77, 1.30, 1.82, 2.35]})
    measured = sim.copy()
    measured[(t > 1.75) & (t < 1.86)] += 0.004  # the model misses most around the 4th impact
    ref = {"t_s": t, "theta_rad": sim, "impacts": impacts}
    t_imp, t0, t1 = _focus(ref, t, measured - sim)
    assert t_imp == 1.82 and (t0, t1) == (0.77, 2.35)  # two half-cycles either side
    assert _focus(None, t, measured - sim) is None
    # the blueprint carries that window to the time panel and the plots
    path = tmp_path / "b.rrd"
    rec = open_recording("rocklab_test", path, recording_id="b")
    log_series(rec, "experiment/block_1/theta/measured_video", t, measured)
    rec.send_blueprint(experiment_blueprint(["experiment/block_1"], has_video=True, focus=(t_imp, t0, t1)))
    rec.flush()
    rec.disconnect()
    assert read_rrd_summary(path)["/experiment/block_1/theta/measured_video"] == t.size
    import rerun.chunk as rc

    reader = rc.RrdReader(str(path))
    (bp,) = reader.blueprints()
    sel = []
    for ch in reader.stream(store=bp).collect().stream():
        rb = ch.to_record_batch()
        if "TimePanelBlueprint:time_selection" in rb.schema.names:
            sel += rb.column(rb.schema.names.index("TimePanelBlueprint:time_selection")).to_pylist()
    assert sel == [[{"min": int(t0 * 1e9), "max": int(t1 * 1e9)}]]
