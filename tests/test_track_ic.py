"""Inverse-compositional registration (the markerless tracker's full-resolution step) on exact truth."""

import math

import cv2
import numpy as np
import pytest

from rocklab.tracking.video.targets._ic import ICAffine, ICRigid


def _scene(seed=0, h=301, w=401):
    rng = np.random.default_rng(seed)
    img = cv2.GaussianBlur((rng.random((h, w)) * 255).astype(np.float32), (0, 0), 3)
    return cv2.normalize(img, None, 20, 235, cv2.NORM_MINMAX)


def _warp(img, W):
    """The picture seen through W (template px -> image px) as a new image of the same size."""
    return cv2.warpAffine(
        img,
        W,
        (img.shape[1], img.shape[0]),
        flags=cv2.INTER_CUBIC | cv2.WARP_INVERSE_MAP,
        borderMode=cv2.BORDER_REFLECT,
    )


U0, V0, TW, TH = 120, 90, 151, 97  # template box in the reference image (odd sizes)


@pytest.mark.parametrize(
    "cls, truth",
    [
        (ICRigid, (math.radians(1.5), 2.7, -1.9, 1.0, 0.0)),
        (ICAffine, (math.radians(-2.0), -1.3, 2.2, 1.004, 0.003)),  # + 0.4 % scale, 0.3 % shear
    ],
)
def test_recovers_the_true_warp_under_gain_and_offset(cls, truth):
    ref = _scene()
    th, tx, ty, sx, sh = truth
    c, s = math.cos(th), math.sin(th)
    # image pixel = A @ template pixel + t, about the template's own origin (U0, V0)
    A = np.array([[c, -s], [s, c]]) @ np.array([[sx, sh], [0.0, 1.0]])
    W_true = np.hstack((A, [[U0 + tx], [V0 + ty]])).astype(np.float32)
    tmpl = ref[V0 : V0 + TH, U0 : U0 + TW].copy()
    # the new picture: the template placed by W_true, then 1.3x gain and -20 offset (lighting)
    M = np.hstack((A, np.array([[U0 + tx], [V0 + ty]]))) @ np.array([[1, 0, -U0], [0, 1, -V0], [0, 0, 1.0]])
    big = cv2.warpAffine(ref, M, (ref.shape[1], ref.shape[0]), flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)
    img = 1.3 * big - 20.0
    start = np.array([[1, 0, U0], [0, 1, V0]], np.float32)  # a few pixels and degrees away
    W, cc = cls(tmpl).refine(img.astype(np.float32), start)
    corners = np.array([[0, 0], [TW - 1, 0], [0, TH - 1], [TW - 1, TH - 1]], float)
    got = corners @ W[:, :2].T + W[:, 2]
    true = corners @ W_true[:, :2].T + W_true[:, 2]
    assert np.abs(got - true).max() < 0.03, got - true  # px, at every corner
    assert cc > 0.999  # gain and offset do not lower the correlation


def test_no_contrast_is_none_not_a_number():
    tmpl = _scene()[:50, :60].copy()
    assert (
        ICRigid(tmpl).refine(np.full((200, 200), 90, np.float32), np.array([[1, 0, 5], [0, 1, 5]], np.float32)) is None
    )


def test_a_mask_leaves_a_covered_part_out_of_the_fit():
    """A flat bright patch (a hand) over the upper 60 % of the object after a known rigid motion:
    the fit on the whole template is pulled off (or fails); the fit on the uncovered part with
    ``mask`` finds the true pose to 0.05 px at every corner, its correlation measured on that
    part alone."""
    ref = _scene(seed=4)
    th, tx, ty = math.radians(0.8), 1.6, -1.1
    c, s = math.cos(th), math.sin(th)
    A = np.array([[c, -s], [s, c]])
    W_true = np.hstack((A, [[U0 + tx], [V0 + ty]])).astype(np.float32)
    tmpl = ref[V0 : V0 + TH, U0 : U0 + TW].copy()
    M = np.hstack((A, np.array([[U0 + tx], [V0 + ty]]))) @ np.array([[1, 0, -U0], [0, 1, -V0], [0, 0, 1.0]])
    img = cv2.warpAffine(ref, M, (ref.shape[1], ref.shape[0]), flags=cv2.INTER_CUBIC, borderMode=cv2.BORDER_REFLECT)
    cover = int(0.6 * TH)
    img[: V0 + cover, :] = 200.0  # the covering patch: everything above 60 % of the template's height
    mask = np.zeros((TH, TW), bool)
    mask[cover + 4 :, :] = True  # the part in view (a margin for the rotation)
    start = np.array([[1, 0, U0], [0, 1, V0]], np.float32)
    corners = np.array([[0, 0], [TW - 1, 0], [0, TH - 1], [TW - 1, TH - 1]], float)
    true = corners @ W_true[:, :2].T + W_true[:, 2]
    whole = ICRigid(tmpl).refine(img.astype(np.float32), start)
    assert whole is None or np.abs(corners @ whole[0][:, :2].T + whole[0][:, 2] - true).max() > 0.5
    W, cc = ICRigid(tmpl).refine(img.astype(np.float32), start, mask=mask)
    got = corners @ W[:, :2].T + W[:, 2]
    assert np.abs(got - true).max() < 0.05, got - true
    assert cc > 0.999
