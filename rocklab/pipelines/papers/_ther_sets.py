"""Ther's thesis §5.3: a record set's spectra together (Figs. 44, 48-50, 53), for the records given."""

from __future__ import annotations

import numpy as np

from .._plotting import pyplot as _plt
from .._plotting import save_png as _save
from ._gallery import Built, number

__all__ = ["BUILDERS", "NEEDS_RECORDS"]

#: The OAS grid of the set figures (coarser than the default: a whole record set in seconds).
GRID = dict(levels=30, sizes=60)


def _records(ctx):
    """Every record under ``--records``, read as ``rocklab oas FOLDER --recursive --units g`` reads it."""
    from ...models import load_base_motion
    from ..spectra import expand_records

    return [load_base_motion(p, units="g") for _, p, err in expand_records([ctx.records], recursive=True) if not err]


_CACHE: dict = {}


def _spectra(ctx):
    from ...models import overturning_spectrum, pulse_parameters

    key = str(ctx.records)
    if key not in _CACHE:
        recs = _records(ctx)
        _CACHE[key] = [(r, overturning_spectrum(r, 12.0, **GRID), pulse_parameters(r).t_p_s) for r in recs]
    return _CACHE[key]


def _scope(n) -> str:
    return f"drawn for the {n} records given with --records (the thesis's 44 far-field and near-field records are not shipped)"


def fig44(ctx) -> Built:
    from ...models.spectra import characteristic_oas

    sp = _spectra(ctx)
    c = characteristic_oas([o for _, o, _ in sp], 0.16)
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True, sharey=True)
    for r, o, _ in sp:
        ax[0].plot(1 / o.p_min_rad_s, o.levels, lw=0.9, label=r.name)
    ax[1].plot(1 / c.p_min_rad_s, c.levels, "k-", lw=1.5, label="characteristic, 16 % exceedance")
    ax[0].set(xlabel="1/p [s]", ylabel="a_p / a_p,min", title="OAS of the records")
    ax[1].set(xlabel="1/p [s]", title="characteristic OAS")
    ax[0].legend(fontsize=6)
    ax[1].legend(fontsize=7)
    _save(fig, ctx.png("ther:Fig. 44"))
    note = (
        "per level, the block size 1/p that 16 % of the records exceed (the thesis leaves the statistics open: "
        "'a theoretical curve'); " + _scope(len(sp))
    )
    return Built(c.to_frame(), {"n_records": number(None, len(sp), "")}, note)


def fig47(ctx) -> Built:
    import pandas as pd

    from ...models.spectra import characteristic_oas, normalised_critical_impulse, simplified_oas

    sp = _spectra(ctx)
    c = characteristic_oas([o for _, o, _ in sp], 0.16)
    f = c.levels * c.p_min_rad_s
    icr = normalised_critical_impulse(float(sp[0][1].alpha_rad))
    f_min = float(np.nanmin(f))
    t_I = icr / f_min  # Eq. 20: the vertical line of the simplified transformed OAS
    p = np.geomspace(np.nanmin(c.p_min_rad_s) / 2, np.nanmax(c.p_min_rad_s) * 2, 200)
    simple = simplified_oas(p, t_I, i_cr=icr)
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True, sharey=True)
    ax[0].plot(c.p_min_rad_s, c.levels, "k.-", label="characteristic OAS (16 % exceedance)")
    ax[0].plot(p, simple, "k--", label=f"simplified (Eq. 21), t_I = {t_I:.3g} s")
    ax[1].plot(f, c.levels, "k.-", label="transformed characteristic OAS")
    ax[1].axvline(f_min, color="k", ls="--", label=f"f_min = i_cr / t_I = {f_min:.3g} 1/s")
    ax[0].set(xscale="log", xlabel="p [1/s]", ylabel="a_p / a_p,min", ylim=(0, float(c.levels.max()) * 1.05))
    ax[1].set(xlabel="f = p a_p/a_p,min [1/s]")
    for a_ in ax:
        a_.legend(fontsize=7)
    _save(fig, ctx.png("ther:Fig. 47"))
    df = pd.DataFrame({"level": c.levels, "p_min_rad_s": c.p_min_rad_s, "f_rad_s": f})
    nums = {"t_I_s": number(None, t_I, "s"), "f_min_rad_s": number(None, f_min, "1/s")}
    note = (
        f"the characteristic OAS of Fig. 44 transformed (f = p a_p/a_p,min) and its simplified form, the vertical "
        f"line at f_min (t_I = {t_I:.3g} s, Eq. 20-21); the thesis's curve is an example without printed values; "
        + _scope(len(sp))
    )
    return Built(df, nums, note)


def fig48(ctx) -> Built:
    import pandas as pd

    from ...models.spectra import oas_convex_hull

    r, o, _ = _spectra(ctx)[0]
    hp = oas_convex_hull(o, transformed=False, normalise=False)
    hf = oas_convex_hull(o, transformed=True, normalise=False)
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    ax[0].plot(o.p_min_rad_s, o.levels, "k.-", ms=3, label="OAS boundary")
    ax[0].fill(hp[:, 0], hp[:, 1], alpha=0.25, label="convex hull")
    ax[1].plot(o.f_rad_s, o.levels, "k.-", ms=3, label="transformed OAS")
    ax[1].fill(hf[:, 0], hf[:, 1], alpha=0.25, label="convex hull")
    ax[0].set(xlabel="p [1/s]", ylabel="a_p / a_p,min", title=f"OAS, {r.name}")
    ax[1].set(xlabel="f [1/s]", title="transformed OAS")
    ax[0].legend(fontsize=7)
    _save(fig, ctx.png("ther:Fig. 48"))
    df = pd.DataFrame({"hull_f_rad_s": hf[:, 0], "hull_level": hf[:, 1]})
    return Built(
        df,
        {"hull_vertices": number(None, int(len(hf)), "")},
        f"{r.name}: the overturning region and its convex hull in both planes",
    )


def fig49(ctx) -> Built:
    import pandas as pd

    from ...models.spectra import oas_convex_hull

    sp = _spectra(ctx)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.8), constrained_layout=True)
    frames = []
    for r, o, _ in sp:
        h = oas_convex_hull(o)
        ax.fill(h[:, 0], h[:, 1], alpha=0.15)
        ax.plot(np.r_[h[:, 0], h[0, 0]], np.r_[h[:, 1], h[0, 1]], lw=0.8, label=r.name)
        frames.append(pd.DataFrame({"record": r.name, "f_over_f_min": h[:, 0], "level": h[:, 1]}))
    ax.set(
        xlabel="f / f_min", ylabel="a_p / a_p,min", xlim=(0, 6), title="convex hulls of the transformed OAS, normalised"
    )
    ax.legend(fontsize=6)
    _save(fig, ctx.png("ther:Fig. 49"))
    return Built(
        pd.concat(frames),
        {"n_records": number(None, len(sp), "")},
        "each hull divided by its own f_min, so records compare (Fig. 49); " + _scope(len(sp)),
    )


def fig50(ctx) -> Built:
    import pandas as pd

    sp = _spectra(ctx)
    tI = np.array([o.t_I_s for _, o, _ in sp])
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 3.4), constrained_layout=True)
    ax.hist(tI[np.isfinite(tI)], bins=10, color="0.5")
    ax.set(xlabel="t_I [s]", ylabel="records", title="replacement impulse durations")
    _save(fig, ctx.png("ther:Fig. 50"))
    df = pd.DataFrame({"record": [r.name for r, _, _ in sp], "t_I_s": tI})
    nums = {"median_t_I_s": number(None, float(np.nanmedian(tI)), "s")}
    return Built(df, nums, "histogram of t_I (H/B = 12); " + _scope(len(sp)))


def fig53(ctx) -> Built:
    import pandas as pd

    from ...models.spectra import tI_tp_regression

    sp = _spectra(ctx)
    tp = np.array([t for _, _, t in sp])
    tI = np.array([o.t_I_s for _, o, _ in sp])
    reg = tI_tp_regression(tp, tI)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 4), constrained_layout=True)
    ax.plot(tp, tI, "o")
    x = np.linspace(0, max(tp.max(), tI.max()) * 1.1, 2)
    ax.plot(x, reg.slope * x + reg.intercept, "--", label=f"r = {reg.r:.3f}")
    ax.set(xlabel="t_p [s]", ylabel="t_I [s]", title="t_I against t_p")
    ax.legend()
    _save(fig, ctx.png("ther:Fig. 53"))
    df = pd.DataFrame({"record": [r.name for r, _, _ in sp], "t_p_s": tp, "t_I_s": tI})
    nums = {"r": number(None, reg.r, ""), "slope": number(None, reg.slope, "")}
    note = (
        f"t_I = {reg.slope:.3g} t_p + {reg.intercept:.3g} s, r = {reg.r:.3g} (`rocklab oas DIR` prints the same for any record set); "
        + _scope(len(sp))
    )
    return Built(df, nums, note)


BUILDERS = {44: fig44, 47: fig47, 48: fig48, 49: fig49, 50: fig50, 53: fig53}
NEEDS_RECORDS = set(BUILDERS)
