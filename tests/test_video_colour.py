"""Rerun video in colour: the frames kept while tracking (``track_video(on_frame=...)``) are
JPEG-encoded from the decoded colour picture, with the right channel order, and stay one
channel for a grey source; the overlays (tracked pixels) still land on the picture."""

import cv2
import numpy as np
import pytest

W, H, N = 320, 200, 6  # non-square, so a transposed frame would show
BLUE, RED = (200, 60, 30), (30, 40, 220)  # BGR
MARKER = (180, 60, 64)  # ArUco id 1: left, top, side (px)


def _frame(i):
    img = np.empty((H, W, 3), np.uint8)
    img[:] = BLUE
    x0 = 20 + 4 * i  # the square moves: a frame kept under the wrong index would show
    img[20:80, x0 : x0 + 60] = RED
    u, v, s = MARKER
    q = s // 8
    img[v - q : v + s + q, u - q : u + s + q] = 255
    m = cv2.aruco.generateImageMarker(cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_4X4_50), 1, s)
    img[v : v + s, u : u + s] = m[..., None]
    return img


@pytest.fixture(scope="module")
def videos(tmp_path_factory):
    d = tmp_path_factory.mktemp("colour")
    out = {}
    for kind in ("colour", "grey"):
        p = d / f"{kind}.mkv"
        vw = cv2.VideoWriter(str(p), cv2.VideoWriter_fourcc(*"FFV1"), 50.0, (W, H), kind == "colour")
        assert vw.isOpened()
        for i in range(N):
            f = _frame(i)
            vw.write(f if kind == "colour" else cv2.cvtColor(f, cv2.COLOR_BGR2GRAY))
        vw.release()
        out[kind] = p
    return out


def _track(path, decimation=2, codec="jpeg"):
    """Track the clip while the review film is made; (tracking, [(index, JPEG)]) or, for AV1,
    (tracking, ReviewVideo)."""
    from rocklab.pipelines.experiment._review_video import ReviewFilm
    from rocklab.config import TrackConfig
    from rocklab.tracking import track_video

    cfg = TrackConfig.from_dict(
        {
            "targets": {"style": "aruco", "marker_size_m": 0.05},
            "reference": {"level": "none"},  # rendered level
            "objects": [{"id": "block_1", "markers": [1]}],
        }
    )
    film = ReviewFilm(50.0, decimation, codec=codec)
    tr = track_video(path, cfg, fps=50.0, on_frame=film)
    out = film.finish()
    return tr, (out if codec != "jpeg" else list(zip(out.frame_index, out.stills)))


def _decode(data):
    return cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)


def test_colour_source_gives_colour_jpeg_through_rrd(videos, tmp_path):
    from rocklab.pipelines.experiment._rerun import log_video_frames, open_recording
    import rerun.chunk as rc

    tr, jpeg = _track(videos["colour"])
    assert [i for i, _ in jpeg] == [0, 2, 4]
    # end to end: the bytes Rerun stores are the JPEG we made (EncodedImage keeps the file as is;
    # a JPEG is YCbCr, decoded to RGB by the viewer, so BGR vs RGB cannot get swapped there)
    rrd = tmp_path / "v.rrd"
    rec = open_recording("test_colour", rrd)
    log_video_frames(rec, "experiment/video", ((i, i / 50.0, b) for i, b in jpeg))
    rec.flush()
    rec.disconnect()
    stored = []
    for ch in rc.RrdReader(str(rrd)).stream().collect().stream():
        if str(ch.entity_path) == "/experiment/video":
            rb = ch.to_record_batch()
            stored += [bytes(x[0]) for x in rb.column(rb.schema.names.index("EncodedImage:blob")).to_pylist()]
    assert stored == [b for _, b in jpeg]
    for i, data in jpeg:
        bgr = _decode(data)
        assert bgr.shape == (H, W, 3)  # overlays are pixels of this frame size
        x0 = 20 + 4 * i
        b, g, r = bgr[25:75, x0 + 5 : x0 + 55].reshape(-1, 3).mean(axis=0)
        assert r > 150 and b < 80 and g < 80, (i, b, g, r)  # red square, truth (30, 40, 220) BGR
        b, g, r = bgr[120:190, 20:150].reshape(-1, 3).mean(axis=0)
        assert b > 150 and r < 80, (i, b, g, r)  # blue background, truth (200, 60, 30)
        # the square is where frame i has it, not where another frame has it
        assert bgr[50, x0 + 2, 2] > 150 and bgr[50, x0 - 3, 0] > 150
    # overlays: the tracked marker centre maps back to where it was drawn, and there the
    # colour picture shows the (black/white, achromatic) marker, not the blue background
    u, v, s = MARKER
    for i, data in jpeg:
        px = tr.to_pixels("block_1", i, [[0.0, 0.0]])[0]
        assert px == pytest.approx([u + s / 2 - 0.5, v + s / 2 - 0.5], abs=0.5)
        patch = _decode(data)[v + 4 : v + s - 4, u + 4 : u + s - 4].astype(float)
        assert np.abs(patch[..., 0] - patch[..., 2]).mean() < 25  # background: |B - R| = 170


def test_grey_source_stays_one_channel(videos):
    tr, jpeg = _track(videos["grey"], decimation=3)
    assert [i for i, _ in jpeg] == [0, 3]
    assert tr.n_frames == N and (tr["block_1"].status == "ok").all()  # tracked as before
    for i, data in jpeg:
        img = _decode(data)
        assert img.shape == (H, W)  # one channel: a grey video is not blown up to three
        truth = cv2.cvtColor(_frame(i), cv2.COLOR_BGR2GRAY)
        x0 = 20 + 4 * i
        assert abs(img[25:75, x0 + 5 : x0 + 55].mean() - truth[25:75, x0 + 5 : x0 + 55].mean()) < 3


def test_is_grey_detects_colour_hidden_from_the_sample():
    from rocklab.pipelines.experiment._review_video import _is_grey

    g = np.random.default_rng(1).integers(0, 256, (H, W), dtype=np.uint8)
    img = cv2.merge([g, g, g])
    assert _is_grey(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY), img) and _is_grey(g, g)
    img[5, 7, 2] ^= 1  # one unit of red, off the 16-px sample grid
    assert not _is_grey(cv2.cvtColor(img, cv2.COLOR_BGR2GRAY), img)


def test_av1_film_has_every_frame_in_order_and_in_colour(videos, tmp_path):
    """The review film: one AV1 asset, a frame reference per frame, each frame the right picture."""
    import av
    import io

    import rerun.chunk as rc

    from rocklab.pipelines.experiment._rerun import log_video_asset, open_recording

    tr, film = _track(videos["colour"], codec="libsvtav1")
    assert film.kind == "av1" and film.frame_index == tuple(range(N)) and film.size_px == (W, H)
    # each decoded frame shows frame i's red square where frame i has it (not a neighbour's):
    # the square moves 4 px per frame, so a one-frame slip moves its left edge by 4 px
    with av.open(io.BytesIO(film.data)) as c:
        dec = [f.to_ndarray(format="bgr24") for f in c.decode(video=0)]
    assert len(dec) == N
    for i, bgr in enumerate(dec):
        bgr = bgr[:H, :W]
        x0 = 20 + 4 * i
        b, g, r = bgr[25:75, x0 + 5 : x0 + 55].reshape(-1, 3).mean(axis=0)
        assert r > 150 and b < 90 and g < 90, (i, b, g, r)
        assert bgr[50, x0 + 2, 2] > 150 and bgr[50, x0 - 3, 0] > 150, i
    rrd = tmp_path / "v.rrd"
    rec = open_recording("test_av1", rrd)
    assert log_video_asset(rec, "experiment/video", film.data, film.frame_index, 50.0) == N
    rec.flush()
    rec.disconnect()
    refs, asset = 0, 0
    for ch in rc.RrdReader(str(rrd)).stream().collect().stream():
        if str(ch.entity_path) == "/experiment/video":
            names = ch.to_record_batch().schema.names
            refs += ch.num_rows if any("VideoFrameReference" in n for n in names) else 0
            asset += ch.num_rows if any("AssetVideo:blob" in n for n in names) else 0
    assert refs == N and asset == 1
    with pytest.raises(ValueError, match="frames"):
        log_video_asset(open_recording("x", tmp_path / "x.rrd"), "v", film.data, film.frame_index[:-1], 50.0)
