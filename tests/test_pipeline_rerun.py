"""Rerun output is read back with rerun's own reader (rerun.chunk.RrdReader), no mocks."""

import numpy as np

from rocklab.pipelines.experiment._rerun import (experiment_blueprint, log_events, log_series, open_recording,
                                      read_rrd_scalars, read_rrd_summary)


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
