"""Calibration from checkerboard and ChArUco pictures: rendered truth, and real sets with published calibrations.

Real sets (tests/data/calib/README.md): Bouguet's stereo example (OpenCV's left/right samples),
published baseline 99.808 mm; OpenCV's ChArUco tutorial photos, published fx 452.51, fy 456.77 px.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rocklab._diagnostics import collecting
from rocklab._errors import InputError
from rocklab.tracking.calib import calibrate_lens, load_lens, open_views, parse_board
from rocklab.tracking.stereo import calibrate_stereo

DATA = Path(__file__).parent / "data" / "calib"
#: Bouguet's published stereo translation (after optimisation), mm, and its baseline.
BOUGUET_T_MM = np.array([-99.80198, 1.12443, 0.05041])
BOUGUET_BASELINE_M = float(np.linalg.norm(BOUGUET_T_MM)) / 1e3
BOUGUET_FC_LEFT = (533.00371, 533.15260)
#: OpenCV's tutorial_camera_charuco.yml (from the same four photos).
CHARUCO_FX, CHARUCO_FY = 452.51072219637672, 456.76707935146891

SIZE = (640, 480)
K_TRUE = np.array([[780.0, 0.0, 331.0], [0.0, 786.0, 236.5], [0.0, 0.0, 1.0]])
DIST_TRUE = np.array([-0.12, 0.08, 0.0, 0.0, 0.0])
SQUARE = 0.025
BOARD = "checkerboard,9x6,0.025"


def _render(K, dist, R, t, seed, cols=9, rows=6, sq=SQUARE, noise=1.0):
    """A checkerboard of ``cols x rows`` inner corners (corner (0, 0) at the board's origin) seen by a
    camera ``K, dist`` with the board at pose ``R, t`` (board -> camera): every pixel's ray traced to
    the board, the texture sampled there (blurred against aliasing), Gaussian noise added."""
    import cv2

    ppm = 4000.0  # texture px per m
    tex = np.full((int((rows + 3) * sq * ppm), int((cols + 3) * sq * ppm)), 235, np.uint8)
    for i in range(rows + 1):
        for j in range(cols + 1):
            if (i + j) % 2 == 0:
                y0, x0 = int((i + 0.5) * sq * ppm), int((j + 0.5) * sq * ppm)
                tex[y0 : int((i + 1.5) * sq * ppm), x0 : int((j + 1.5) * sq * ppm)] = 20
    tex = cv2.GaussianBlur(tex, (0, 0), 2.0)
    W, H = SIZE
    ray = _rays(K, dist)
    s = (R[:, 2] @ t) / (ray @ R[:, 2])
    B = (ray * s[:, None] - t) @ R  # board coordinates, m
    # inner corner (0, 0) sits 1.5 squares in from the texture's edge
    mx = ((B[:, 0] + 1.5 * sq) * ppm).reshape(H, W).astype(np.float32)
    my = ((B[:, 1] + 1.5 * sq) * ppm).reshape(H, W).astype(np.float32)
    img = cv2.remap(tex, mx, my, cv2.INTER_LINEAR, borderValue=128).astype(float)
    img += np.random.default_rng(seed).normal(0, noise, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


_RAYS: dict = {}


def _rays(K, dist):
    """Every pixel's ray (x/z, y/z, 1) of the camera ``K, dist``, shape (H * W, 3)."""
    import cv2

    key = (K.tobytes(), dist.tobytes())
    if key not in _RAYS:
        W, H = SIZE
        uu, vv = np.meshgrid(np.arange(W, dtype=np.float64), np.arange(H, dtype=np.float64))
        pix = np.column_stack((uu.ravel(), vv.ravel())).reshape(-1, 1, 2)
        crit = (cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 40, 1e-12)
        n = cv2.undistortPoints(pix, K, dist, None, None, None, crit).reshape(-1, 2)
        _RAYS[key] = np.column_stack((n, np.ones(len(n))))
    return _RAYS[key]


def _poses(n, seed=0):
    """Board poses 0.45-0.6 m away, tilted up to ~35 degrees in varied directions, centred in view."""
    import cv2

    rng = np.random.default_rng(seed)
    out = []
    centre = np.array([4 * SQUARE, 2.5 * SQUARE, 0.0])
    for k in range(n):
        ang = np.deg2rad(35) * np.array([np.cos(2.4 * k), np.sin(2.4 * k), 0.0]) * (0.5 + 0.5 * rng.random())
        ang[2] = rng.uniform(-0.3, 0.3)
        R = cv2.Rodrigues(ang)[0]
        t = np.array([rng.uniform(-0.03, 0.03), rng.uniform(-0.02, 0.02), rng.uniform(0.45, 0.6)]) - R @ centre
        out.append((R, t))
    return out


def _write(folder, name, imgs, numbers):
    import cv2

    folder.mkdir(parents=True, exist_ok=True)
    for k, img in zip(numbers, imgs):
        cv2.imwrite(str(folder / f"{name}{k:02d}.png"), img)


def test_synthetic_checkerboard_lens_from_a_folder_without_rate(tmp_path):
    # a folder of photos with a gap in its numbering (a deleted photo) and no timestamps: no rate needed
    poses = _poses(12)
    imgs = [_render(K_TRUE, DIST_TRUE, R, t, seed=k) for k, (R, t) in enumerate(poses)]
    nums = [k + 1 for k in range(12)]
    nums[5:] = [k + 2 for k in range(5, 12)]
    _write(tmp_path / "cam", "IMG_", imgs, nums)
    lens = calibrate_lens(tmp_path / "cam", BOARD)
    assert lens.n_views == 12 and lens.status == "ok"
    assert lens.rms_px < 0.15
    assert lens.K[0, 0] == pytest.approx(K_TRUE[0, 0], rel=3e-3)
    assert lens.K[1, 1] == pytest.approx(K_TRUE[1, 1], rel=3e-3)
    assert abs(lens.K[0, 2] - K_TRUE[0, 2]) < 1.5 and abs(lens.K[1, 2] - K_TRUE[1, 2]) < 1.5
    assert lens.dist[0] == pytest.approx(DIST_TRUE[0], abs=0.02)
    # the non-square pixels are seen: fy/fx to 1e-3 of the truth's 786/780
    assert lens.K[1, 1] / lens.K[0, 0] == pytest.approx(786 / 780, abs=1e-3)
    # the fit's own 1-sigma covers the error within 4 sigma
    assert abs(lens.K[0, 0] - K_TRUE[0, 0]) < 4 * lens.sigma_px["fx"] + 0.5
    out = lens.save(tmp_path / "lens.json")
    back = load_lens(out)
    np.testing.assert_allclose(back.K, lens.K)
    assert json.loads(out.read_text())["format"] == "rocklab-lens/1"


def test_synthetic_stereo_checkerboard_baseline(tmp_path, run_cli):
    import cv2

    # camera 2: 0.12 m to the right of camera 1, turned 5 degrees towards the board between them
    R12 = cv2.Rodrigues(np.array([0.0, np.deg2rad(5), 0.01]))[0]
    c2 = np.array([0.12, 0.004, 0.0])  # camera 2's centre in camera 1's axes
    T12 = -R12 @ c2
    K2 = np.array([[800.0, 0.0, 318.0], [0.0, 803.0, 242.0], [0.0, 0.0, 1.0]])
    d2 = np.array([-0.08, 0.03, 0.0, 0.0, 0.0])
    poses = _poses(10, seed=1)
    left = [_render(K_TRUE, DIST_TRUE, R, t + np.array([0.04, 0, 0]), seed=k) for k, (R, t) in enumerate(poses)]
    right = [
        _render(K2, d2, R12 @ R, R12 @ (t + np.array([0.04, 0, 0])) + T12, seed=100 + k)
        for k, (R, t) in enumerate(poses)
    ]
    _write(tmp_path / "pairs", "left", left, range(1, 11))
    _write(tmp_path / "pairs", "right", right, range(1, 11))
    rig = calibrate_stereo(str(tmp_path / "pairs" / "left*.png"), str(tmp_path / "pairs" / "right*.png"), BOARD)
    assert rig.n_frames == 10 and rig.board == BOARD
    assert rig.baseline_m == pytest.approx(np.linalg.norm(c2), rel=3e-3)
    np.testing.assert_allclose(rig.T, T12, atol=1.5e-3)
    assert rig.K2[0, 0] == pytest.approx(800.0, rel=3e-3)
    assert rig.rms_px["stereo"] < 0.2
    # photos paired wrongly (the right camera's numbered one off): the stereo fit cannot close, said
    # (six of the pairs: each picture's corner search is what this test spends its time on)
    _write(tmp_path / "shifted", "left", left[:6], range(1, 7))
    _write(tmp_path / "shifted", "right", right[:6], [(k + 1) % 6 + 1 for k in range(6)])
    with collecting() as diags:
        bad = calibrate_stereo(str(tmp_path / "shifted" / "left*.png"), str(tmp_path / "shifted" / "right*.png"), BOARD)
    assert bad.rms_px["stereo"] > 1.0 and [d.code for d in diags] == ["W-CALIB-WEAK"]
    # a pair whose partner is missing is named, not silently shifted
    (tmp_path / "shifted" / "right04.png").unlink()
    with pytest.raises(InputError, match=r"no picture numbered 4, which .*left\*\.png has"):
        calibrate_stereo(str(tmp_path / "shifted" / "left*.png"), str(tmp_path / "shifted" / "right*.png"), BOARD)
    # the folder of both cameras' photos is not one camera's
    with pytest.raises(InputError, match=r"named in 2 ways \(leftN, rightN\); .*'.*left\*\.png'"):
        calibrate_lens(tmp_path / "pairs", BOARD)
    # the same pictures as two lossless films, through the CLI: the same rig
    from _render import write_video

    write_video(tmp_path / "left.mkv", left, 25.0)
    write_video(tmp_path / "right.mkv", right, 25.0)
    rc, out, err = run_cli(
        "stereo", "calibrate", tmp_path / "left.mkv", tmp_path / "right.mkv", "--board", BOARD, "--json"
    )
    assert rc == 0, err
    s = json.loads(out)
    assert s["n_frames"] == 10 and s["baseline_m"] == pytest.approx(rig.baseline_m, rel=1e-9)
    assert s["board"] == BOARD and (tmp_path / "stereo.json").is_file()


def test_real_checkerboard_pairs_match_bouguets_published_baseline():
    d = DATA / "bouguet_stereo"
    rig = calibrate_stereo(str(d / "left*.jpg"), str(d / "right*.jpg"), "checkerboard,9x6,0.03")
    assert rig.n_frames == 13
    # published 99.808 mm; measured 99.821 mm (+0.013 %)
    assert rig.baseline_m == pytest.approx(BOUGUET_BASELINE_M, rel=5e-3)
    np.testing.assert_allclose(rig.T * 1e3, BOUGUET_T_MM, atol=0.5)
    assert max(rig.rms_px.values()) <= 0.5
    assert rig.K1[0, 0] == pytest.approx(BOUGUET_FC_LEFT[0], rel=5e-3)
    # one camera alone, k3 held at 0 as Bouguet's toolbox does: the published left focal lengths
    lens = calibrate_lens(str(d / "left*.jpg"), "checkerboard,9x6,0.03", fix_k3=True)
    assert lens.K[0, 0] == pytest.approx(BOUGUET_FC_LEFT[0], rel=5e-3)
    assert lens.K[1, 1] == pytest.approx(BOUGUET_FC_LEFT[1], rel=5e-3)
    assert lens.rms_px <= 0.5 and lens.status == "ok"


def test_real_charuco_photos_match_opencvs_published_focal_lengths():
    with collecting() as diags:
        lens = calibrate_lens(DATA / "charuco_opencv", "charuco,5x7,0.04,0.02,DICT_6X6_250")
    assert lens.n_views == 4
    assert lens.K[0, 0] == pytest.approx(CHARUCO_FX, rel=0.02)  # measured +1.06 %
    assert lens.K[1, 1] == pytest.approx(CHARUCO_FY, rel=0.02)  # measured +1.00 %
    assert lens.rms_px < 0.3
    # four views fix the focal length to 3.5 % only: reported, not hidden
    assert lens.status == "weak" and lens.sigma_px["fx"] / lens.K[0, 0] > 0.01
    assert [d.code for d in diags] == ["W-CALIB-WEAK"]


@pytest.mark.parametrize(
    "spec, match",
    [
        ("checkerbord,9x6,0.025", "not a board"),
        ("checkerboard,9x6", "checkerboard is checkerboard,COLSxROWS,SQUARE_M"),
        ("checkerboard,9by6,0.025", "two whole numbers"),
        ("checkerboard,9x6,25", "must be in metres"),
        ("checkerboard,1x6,0.025", "at least 2x2 inner corners"),
        ("charuco,9x6,0.03,0.04,DICT_5X5_100", "smaller than the square side"),
        ("charuco,9x6,0.03,0.02,DICT_5X5", "unknown ArUco dictionary"),
    ],
)
def test_bad_board_specs_are_one_line_errors(spec, match):
    with pytest.raises(InputError, match=match) as e:
        parse_board(spec)
    assert "\n" not in str(e.value)


def test_board_specs_and_corner_conventions():
    b = parse_board("checkerboard,9x6,0.025")
    assert (b.kind, b.n_corners, b.spec) == ("checkerboard", 54, "checkerboard,9x6,0.025")
    assert np.allclose(b.object_points()[-1], [8 * 0.025, 5 * 0.025, 0])
    c = parse_board("charuco,9x6,0.03,0.022,DICT_5X5_100")
    assert c.n_corners == 40 and len(c.object_points()) == 40
    assert parse_board("9x6,0.03,0.022,DICT_5X5_100") == c  # the legacy stereo form


def test_cli_calibrate_lens_file_feeds_track_toml(tmp_path, run_cli):
    from rocklab.config import TrackConfig
    from rocklab.tracking import make_plane_map

    d = DATA / "bouguet_stereo"
    out = tmp_path / "lens.json"
    rc, stdout, err = run_cli("calibrate", d / "left*.jpg", "--board", "checkerboard,9x6,0.03", "-o", out, "--json")
    assert rc == 0, err
    s = json.loads(stdout)
    assert s["n_views"] == 13 and s["size_px"] == [640, 480] and s["rms_px"] < 0.5
    assert s["fx_px"] == pytest.approx(BOUGUET_FC_LEFT[0], rel=5e-3)
    cfg = TrackConfig.from_dict({"video": {"calibration": str(out)}, "objects": [{"id": "b", "markers": [1]}]})
    pm = make_plane_map(cfg, 640, 480)
    np.testing.assert_allclose(pm.K, s["camera_matrix"])
    # a film of another size: the lens does not apply
    with pytest.raises(InputError, match=r"calibrated on 640x480 px pictures, the film is 1280x720"):
        make_plane_map(cfg, 1280, 720)
    # the wrong corner count: the board is never found, and the message says how corners are counted
    # (three of the pictures: a search that finds nothing scans the whole picture)
    rc, _, err = run_cli(
        "calibrate", d / "left0[1-3].jpg", "--board", "checkerboard,10x7,0.03", "-o", tmp_path / "x.json"
    )
    assert rc == 2 and "10x7 counts INNER corners (a board of 11x8 squares)" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "x.json").exists()


def test_views_of_a_folder_keep_the_numbers_order(tmp_path):
    import cv2

    for n in (10, 2, 1):
        cv2.imwrite(str(tmp_path / f"shot{n}.png"), np.zeros((8, 8), np.uint8))
    v = open_views(tmp_path)
    assert v.labels == ("shot1.png", "shot2.png", "shot10.png") and v.numbers == (1, 2, 10)


def test_track_init_writes_the_lens_and_refuses_one_of_another_size(tmp_path, run_cli, sine_session):
    import tomllib

    import pandas as pd

    from rocklab.tracking.calib import Lens

    s = sine_session
    v = tomllib.loads((s / "track.toml").read_text())["video"]  # the render's own lens
    K, dist = np.array(v["camera_matrix"]), np.array(v["dist_coeffs"])
    Lens(K, dist, (960, 540), 0.1, {}, "synthetic", ("truth",)).save(tmp_path / "lens.json")
    Lens(K, dist, (1280, 720), 0.1, {}, "synthetic", ("truth",)).save(tmp_path / "hd.json")
    cfg = tmp_path / "t.toml"
    rc, _, err = run_cli(
        "track", "init", s / "video.mkv", "--lens", tmp_path / "lens.json", "--marker-size", 0.06, "-o", cfg
    )
    assert rc == 0, err
    assert tomllib.loads(cfg.read_text())["video"]["calibration"] == "lens.json"
    rc, _, err = run_cli("track", s / "video.mkv", "--config", cfg, "-o", tmp_path / "tr.csv")
    assert rc == 0, err
    tr, truth = pd.read_csv(tmp_path / "tr.csv"), pd.read_csv(s / "truth.csv")
    b = tr[tr.object == "block_1"].sort_values("frame")
    tb = truth[truth.object == "block_1"].sort_values("frame")
    assert np.sqrt(np.mean(np.degrees(b.theta_rad.to_numpy() - tb.theta_rad.to_numpy()) ** 2)) < 0.2  # 0.093 deg
    rc, _, err = run_cli("track", "init", s / "video.mkv", "--lens", tmp_path / "hd.json", "-o", tmp_path / "u.toml")
    assert rc == 2 and "calibrated on 1280x720 px pictures, the film is 960x540 px" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "u.toml").exists()


def test_lens_from_a_charuco_film_recovers_the_rendered_camera(tmp_path):
    from rocklab.synth import synth_stereo

    r = synth_stereo(tmp_path / "s", size=(641, 463), f_px=800.0, n_board=12, seed=4, duration_s=0.2)
    cam = r["cameras"][0]
    film = r["paths"]["calib_cam1"]
    lens = calibrate_lens(film, "charuco,9x6,0.03,0.022,DICT_5X5_100")
    assert (lens.n_seen, lens.n_views, lens.status) == (12, 12, "ok")
    assert lens.K[0, 0] == pytest.approx(cam.K[0, 0], rel=0.01)  # 802.2 px for 800
    assert lens.K[1, 1] == pytest.approx(cam.K[1, 1], rel=0.01)
    assert abs(lens.K[0, 0] - cam.K[0, 0]) < 3 * lens.sigma_px["fx"]
    assert lens.dist[0] == pytest.approx(cam.dist[0], abs=0.02)
    assert lens.rms_px < 0.3
    # every other frame of the film: half the views (six views fix f to about 1 %: may be flagged weak)
    with collecting() as diags:
        half = calibrate_lens(film, "charuco,9x6,0.03,0.022,DICT_5X5_100", every=2)
    assert (half.n_seen, half.n_views) == (6, 6)
    assert {d.code for d in diags} <= {"W-CALIB-WEAK"} and (half.status == "weak") == bool(diags)


@pytest.mark.parametrize(
    "text, match",
    [
        ("{not json", "not a lens file"),
        ('{"camera_matrix": [[1, 0], [0, 1]], "dist_coeffs": [0, 0, 0, 0], "size_px": [640, 480]}', "'camera_matrix'"),
        (
            '{"camera_matrix": [[500, 0, 320], [0, 500, 240], [0, 0, 1]], "dist_coeffs": [0, 0, 0], "size_px": [640, 480]}',
            "'dist_coeffs' must be 4, 5, 8, 12 or 14",
        ),
        ('{"camera_matrix": [[500, 0, 320], [0, 500, 240], [0, 0, 1]], "dist_coeffs": [0, 0, 0, 0]}', "size_px"),
    ],
)
def test_damaged_lens_files_are_one_line_errors(tmp_path, text, match):
    f = tmp_path / "lens.json"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as e:
        load_lens(f)
    assert str(e.value).startswith(str(f)) and "rocklab calibrate" in str(e.value)
    with pytest.raises(InputError, match="lens file not found"):
        load_lens(tmp_path / "none.json")
