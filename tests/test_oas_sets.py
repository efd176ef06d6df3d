"""A record set's spectra together: characteristic OAS, convex hulls, t_I-t_p regression (thesis §5.3)."""

import numpy as np
import pytest

from rocklab import InputError
from rocklab.models import bundled_record
from rocklab.models.spectra import (
    characteristic_oas,
    oas_convex_hull,
    overturning_spectrum,
    pulse_motion,
    tI_tp_regression,
)


@pytest.fixture(scope="module")
def spectra():
    kw = dict(levels=20, sizes=40)
    return [
        overturning_spectrum(bundled_record("elcentro"), 12.0, **kw),
        overturning_spectrum(pulse_motion("full-sine", 0.4, 1.0), 12.0, **kw),
        overturning_spectrum(pulse_motion("half-sine", 0.8, 1.0), 12.0, **kw),
    ]


def test_characteristic_oas_is_a_per_level_quantile(spectra):
    size = np.array([np.where(np.isfinite(o.p_min_rad_s), 1 / o.p_min_rad_s, 0.0) for o in spectra])
    for q in (0.16, 0.5):
        c = characteristic_oas(spectra, q)
        cs = np.where(np.isfinite(c.p_min_rad_s), 1 / c.p_min_rad_s, 0.0)
        # no more than the share q of the records reaches past it (up to one record of interpolation)
        beyond = (size > cs + 1e-12).mean(axis=0)
        assert np.all(beyond <= q + 1 / len(spectra) + 1e-12)
        assert np.all(cs <= size.max(axis=0) + 1e-12) and np.all(cs >= size.min(axis=0) - 1e-12)
    same = characteristic_oas([spectra[0], spectra[0]], 0.3)
    np.testing.assert_allclose(same.p_min_rad_s, spectra[0].p_min_rad_s)
    with pytest.raises(InputError, match="exceedance"):
        characteristic_oas(spectra, 1.5)
    with pytest.raises(InputError, match="set of records"):
        characteristic_oas(spectra[:1])


def test_convex_hull_normalised_and_convex(spectra):
    o = spectra[0]
    h = oas_convex_hull(o)
    assert h[:, 0].min() == pytest.approx(1.0)  # normalised by the lowest horizontal coordinate (Fig. 49)
    assert h[:, 1].min() == pytest.approx(np.nanmin(o.levels[np.isfinite(o.f_rad_s)]))
    # every boundary point lies inside or on its hull
    from matplotlib.path import Path

    ok = np.isfinite(o.f_rad_s)
    pts = np.c_[o.f_rad_s[ok] / np.nanmin(o.f_rad_s), o.levels[ok]]
    assert Path(h).contains_points(pts, radius=1e-9).all() or Path(h[::-1]).contains_points(pts, radius=1e-9).all()


def test_tI_tp_regression_recovers_a_line():
    rng = np.random.default_rng(1)
    tp = rng.uniform(0.2, 1.5, 44)
    r = tI_tp_regression(tp, 0.8 * tp + 0.05)
    assert (r.slope, r.intercept, r.r, r.n) == pytest.approx((0.8, 0.05, 1.0, 44))
    noisy = tI_tp_regression(np.r_[tp, np.nan], np.r_[0.8 * tp + rng.normal(0, 0.05, 44), 1.0])
    assert noisy.n == 44 and 0.9 < noisy.r < 1.0 and abs(noisy.slope - 0.8) < 3 * noisy.slope_stderr + 0.02
    with pytest.raises(InputError, match="3 or more"):
        tI_tp_regression([0.1, 0.2], [0.1, 0.2])
