"""Spectra figures (pipelines): OAS panels and equivalent-block error maps."""

import numpy as np

from rocklab.models import overturning_curve, overturning_spectrum, pulse_motion
from rocklab.pipelines import plot_oas, plot_overturning_curve
from rocklab.pipelines.spectra._plots_spectra import plot_wall_error_maps


def test_wall_error_maps_fig3_trends(tmp_path):
    r = plot_wall_error_maps(tmp_path / "wall.png", alphas=[0.05, 0.2, 0.4], ratios=[0.1, 0.9], accs=[1.1, 3.0])
    assert (tmp_path / "wall.png").stat().st_size > 10_000
    T, t1, t2 = r["period_ratio"], r["t_ratio_kappa1"], r["t_ratio_kappa2"]
    # Fig. 3: the linearised block rocks faster (ratio < 1); error grows with alpha, shrinks near phi_cr
    assert np.all(T < 1) and np.all(np.diff(T[:, 0]) < 0) and np.all(T[:, 1] > T[:, 0])
    # kappa choice matters most near u/(g lambda) = 1; kappa2 is the better one there
    assert np.all(abs(1 - t2[:, 0]) < abs(1 - t1[:, 0]))
    assert abs(t1[:, 1] - t2[:, 1]).max() < abs(t1[:, 0] - t2[:, 0]).max()


def test_oas_and_curve_figures(tmp_path):
    m = pulse_motion("half-sine", 0.3, 1.0, dt_s=0.005, pad_s=0.1)
    o = overturning_spectrum(m, 12, levels=10, sizes=25, refine=4)
    plot_oas(o, tmp_path / "oas.png")
    c = overturning_curve("half-sine", 8, np.geomspace(0.3, 5, 8), np.linspace(1, 20, 30), refine=4)
    plot_overturning_curve(c, tmp_path / "oc.png")
    for f in ("oas.png", "oc.png"):
        assert (tmp_path / f).read_bytes()[:4] == b"\x89PNG"
    # half-sine: the overturning curve falls towards 1 as the pulse gets long (Fig. 33a)
    a = c.a_min_ratio
    assert np.all(np.diff(a[np.isfinite(a)]) < 0) and a[-1] < 1.5
