"""Ther's thesis: the figures and tables rocklab regenerates, and every other one with its reason."""

from __future__ import annotations

import numpy as np

from .._plotting import pyplot as _plt
from .._plotting import save_png as _save
from ._gallery import Built, Entry, number
from ._ther_spectra import BUILDERS as _SPECTRA
from ._ther_spectra import NEEDS_RECORDS as _SPECTRA_RECORDS
from ._ther_sets import BUILDERS as _SETS
from ._ther_sets import NEEDS_RECORDS as _SETS_RECORDS

__all__ = ["ENTRIES"]

#: The thesis's captions (shortened), figure number -> caption.
CAPTIONS = {
    1: "The ruined Szent Anna parish church after the earthquake in Dunaharaszti",
    2: "Housner's model for a rocking block",
    3: "Typical time-displacement curve of a rocking block according to Housner's model",
    4: "The reduction in speed (mu) and the loss of kinetic energy (1 - mu^2)",
    5: "Columns and arches, where Housner's model is applied",
    6: "Suggested signal shapes for generating OC",
    7: "Geometry of the rigid block",
    8: "Overturning curve (OC) for a single block subjected to a half sine pulse and a full sine",
    9: "Motion of the rocking block for different impulses",
    10: "Multi-block column",
    11: "Rocking block",
    12: "Loss in kinetic energy as a function of slenderness of the block for n bumps",
    13: "Comparison of Housner's model and the modification with an additional bump in the middle",
    14: "The rocking motion of a block: Housner's model and the proposed one (Northridge MUL009)",
    15: "Opening possibilities of an interface",
    16: "Possible motions of an interface after impact",
    17: "The degree of freedom of the model",
    18: "False opening solution of a two-block column",
    19: "Possible cases of a two-block column",
    20: "Configuration before, during and after the impact",
    21: "The possible rocking motions after impact",
    22: "A possible opening scheme of the investigated two-block system",
    23: "Picture and the sizes of granite blocks used in the experiments",
    24: "Configurations of a block applied in the tests",
    25: "Angle of rotation as a function of time, configuration d)",
    26: "Examples of the experimental results for configurations a), b) and c)",
    27: "Experimental results compared with Housner's model and with the refined model",
    28: "The initial inclination of the two-block system",
    29: "The recorded and the simulated rotations of the two-block system during free rocking",
    30: "The three-block column made of granite blocks",
    31: "The base excitation of the blocks (measured on the shaking table)",
    32: "The experimental and numerical results of a base excitation test",
    33: "Normalized overturning curve (OC) for a single block subjected to a half sine pulse",
    34: "The overturning curve and the overturning impulse curve for half and full sine pulses",
    35: "The OAS and the transformed OAS of a full-cycle sine with different impulse durations",
    36: "The Overturning Acceleration Spectrum (OAS) of a single block",
    37: "The OAS and the transformed OAS for an earthquake record (Northridge 1994)",
    38: "The dimensions of a single block and multi-block columns",
    39: "The normalized OC and OAS of a single block",
    40: "The overturning of columns (H = 12 m, B = 1 m) of 1, 2 and 3 blocks under full sine pulses",
    41: "The overturning of columns (H = 12 m, B = 1 m) of 1, 2 and 3 blocks under full sine pulses, with bumps",
    42: "Rotations of a three-block column excited by a sine pulse",
    43: "The OAS of columns of 1, 2 and 3 blocks with different energy dissipations",
    44: "OAS at a given location and the characteristic OAS",
    45: "The effect of block slenderness on OAS",
    46: "The transformed OAS for simple signals",
    47: "An example of the characteristic OAS and the transformed characteristic OAS",
    48: "An example OAS and transformed OAS with the corresponding convex hulls",
    49: "Convex hulls of transformed OAS for far-field and near-field earthquakes",
    50: "Histograms of replacement impulse durations t_I for the FF and NF records",
    51: "Values of alpha for different mass distributions",
    52: "An acceleration record, a_max and I_max, and the replacement sine",
    53: "The corresponding t_I and t_p values for the FF and NF records",
    54: "Representation of the overturning acceleration spectra for an arbitrary pulse",
    55: "OAS, transformed OAS and OAS against 1/p for the Northridge earthquake",
    56: "The OAS of three different earthquakes compared to single pulses",
    57: "OAS for the Northridge (NF-37) earthquake compared to Voyagaki et al.",
    58: "The OAS for the Northridge (NF-37) earthquake compared to two replacement pulses",
    59: "Housner's model for a block rotating about two axes of arbitrary position",
}
TABLES = {
    1: "Experimental results (Ogawa 1977; Prieto-Castrillo 2007; Elgawady et al. 2011) compared with Housner",
    2: "Energy loss of the granite blocks by configuration",
    3: "The relative energy loss between adjacent rockings in the experiments and in the calculation",
    4: "The investigated FF earthquakes and the calculated pulse durations",
    5: "The investigated NF earthquakes and the calculated pulse durations",
}
DRAWING = "a drawing or photograph: no data to regenerate"
EXPERIMENT = "measured data the thesis shows only as a plot (not given as numbers): not invented"
NF37 = (
    "needs the near-field record NF-37 (1994 Northridge, Rinaldi Receiving Station 228, FEMA P695), which "
    "neither rocklab nor ../shared/data/records holds; "
)
WHY = {
    **{k: DRAWING for k in (1, 2, 5, 6, 7, 10, 11, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 28, 30, 38, 51, 54, 59)},
    **{k: EXPERIMENT for k in (25, 26, 27, 31, 32)},
    57: NF37 + "with it, `rocklab oas NF37.AT2 --slenderness 12` and Voyagaki's triangular pulse of T_p/2 = 0.6 s "
    "(`rocklab oas --pulse`) give the two curves",
    58: NF37 + "and the two replacement signals' durations were read off the record's OAS and are drawn, not "
    "printed (Fig. 58b's Erzincan NF-26 is not held either)",
}


def fig4(ctx) -> Built:
    import pandas as pd

    from ...models import eta_housner

    hb = np.linspace(1.0, 10.0, 91)
    alpha = np.arctan(1.0 / hb)
    mu = eta_housner(alpha)
    df = pd.DataFrame({"h_over_b": hb, "mu": mu, "energy_loss": 1 - mu**2})
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 3.6), constrained_layout=True)
    ax.plot(hb, mu, label="mu (velocity ratio)")
    ax.plot(hb, 1 - mu**2, label="1 - mu^2 (kinetic energy lost)")
    ax.set(xlabel="H/B", ylabel="", title="Housner's impact (thesis Eq. 1-2)")
    ax.legend()
    _save(fig, ctx.png("ther:Fig. 4"))
    m4 = float(eta_housner(np.arctan(0.25)))
    return Built(
        df,
        {"mu_at_HB_4": number(None, m4, "")},
        f"Housner's mu and energy loss over H/B 1-10 (mu = {m4:.4g} at H/B = 4)",
    )


def fig12(ctx) -> Built:
    import pandas as pd

    from ...blocks import Block
    from ...models import eta_bumps, eta_housner

    hb = np.linspace(1.0, 10.0, 46)
    rows = []
    for n in (0, 1, 2, 3):
        for r in hb:
            eta = eta_bumps(Block(0.1, 0.1 * r), n) if n else float(eta_housner(np.arctan(1 / r)))
            rows.append({"n_bumps": n, "h_over_b": r, "eta": eta, "energy_loss": 1 - eta**2})
    df = pd.DataFrame(rows)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 3.6), constrained_layout=True)
    for n, g in df.groupby("n_bumps"):
        ax.plot(g["h_over_b"], g["energy_loss"], label=f"{n} bump(s)")
    ax.set(xlabel="H/B", ylabel="kinetic energy lost per impact", title="thesis Fig. 12 (App. A)")
    ax.legend()
    _save(fig, ctx.png("ther:Fig. 12"))
    more = bool((df[df.n_bumps == 1]["energy_loss"].to_numpy() < df[df.n_bumps == 0]["energy_loss"].to_numpy()).all())
    return Built(
        df,
        {"bump_loses_less": number(True, more, "")},
        "a bump in the middle loses less energy than Housner's single impact at every slenderness, as the thesis shows",
    )


def fig29(ctx) -> Built:
    import pandas as pd

    from ...blocks import Block
    from ...models import Column, simulate_column

    # two granite blocks 100 x 300 mm, edges cut to a 96 mm contact (2 mm a side), upper at 0.153 rad
    blocks = [Block(0.1, 0.3, density_kg_m3=2700.0, name=f"block_{i}") for i in range(2)]
    res = simulate_column(Column(blocks, cut_m=0.002), theta0_rad=[0.0, 0.153], duration_s=0.5, output_dt_s=1e-3)
    df = pd.DataFrame({"t_s": res.t_s, "theta1_rad": res.theta_rad[:, 0], "theta2_rad": res.theta_rad[:, 1]})
    conf = res.configurations
    opens = conf[(conf.joint == 0) & (conf.event == "opening")].t_s
    up = conf[(conf.joint == 1) & (conf.event == "impact")].t_s
    low = conf[(conf.joint == 0) & (conf.event == "impact")].t_s
    times = [float(opens.iloc[0]), float(up.iloc[0]), float(low.iloc[0])]
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.6), constrained_layout=True)
    ax.plot(df.t_s, df.theta1_rad, label="lower block")
    ax.plot(df.t_s, df.theta2_rad, label="upper block")
    for t in times:
        ax.axvline(t, color="0.6", lw=0.8)
    ax.set(xlabel="t [s]", ylabel="rotation [rad]", title="two granite blocks, upper released at 0.153 rad")
    ax.legend()
    _save(fig, ctx.png("ther:Fig. 29"))
    paper = (0.13, 0.187, 0.193)
    nums = {
        "lower_joint_opens_s": number(paper[0], times[0], "s"),
        "upper_impacts_s": number(paper[1], times[1], "s"),
        "lower_impacts_base_s": number(paper[2], times[2], "s"),
    }
    d = max(abs(a - b) for a, b in zip(paper, times))
    note = (
        f"the thesis's three events (0.13, 0.187, 0.193 s) within {d:.3g} s: "
        + ", ".join(f"{t:.4g}" for t in times)
        + " s (the recorded curves of Fig. 29a are not given as numbers)"
    )
    return Built(df, nums, note)


def _curve(ctx, key, kinds) -> Built:
    import pandas as pd

    from ...models import overturning_curve

    ptp = np.geomspace(0.5, 20.0, 24)
    levels = np.linspace(1.0, 10.0, 37)
    frames, nums = [], {}
    plt = _plt()
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
    for kind in kinds:
        c = overturning_curve(kind, 4.0, ptp, levels)
        frames.append(
            pd.DataFrame({"kind": kind, "p_tp": c.ptp, "a_min_ratio": c.a_min_ratio, "impulse_ratio": c.impulse_ratio})
        )
        ax[0].plot(c.ptp, c.a_min_ratio, label=kind)
        ax[1].plot(c.ptp, c.impulse_ratio, label=kind)
        nums[f"{kind}_i_cr"] = number(None, c.i_cr, "")
        nums[f"{kind}_a_min_ratio_at_ptp_20"] = number(None, float(c.a_min_ratio[-1]), "")
    ax[0].set(xlabel="p t_p", ylabel="a_p / a_p,min", title="overturning curve, H/B = 4")
    ax[1].set(xlabel="p t_p", ylabel="p I / a_p,min", title="overturning impulse curve")
    ax[0].legend()
    _save(fig, ctx.png(key))
    return Built(
        pd.concat(frames),
        nums,
        "curves of the block's own grid; the thesis plots them without printing values (long pulses tend to a_p,min, short ones to the impulse limit i_cr)",
    )


def fig14(ctx) -> Built:
    import pandas as pd

    from ...blocks import Block
    from ...models import simulate
    from ._ther_spectra import mul009

    rec = mul009(ctx)
    blk = Block(0.63, 2.52)  # the thesis's b = 0.315 m, h = 1.261 m are half sizes
    out, nums = {}, {}
    for law, kw in (("housner", {}), ("bumps", {"n": 1})):
        r = simulate(blk, duration_s=float(rec.t_s[-1]), base=rec, restitution=law, output_dt_s=0.01, **kw)
        out[law] = r
    h, b = out["housner"], out["bumps"]
    k = int(np.argmax(np.abs(h.theta_rad)))
    peak = float(np.abs(h.theta_rad[k]) / blk.alpha_rad)
    nums["housner_peak_over_alpha"] = number(0.80, peak, "")
    nums["housner_peak_t_s"] = number(9.0, float(h.t_s[k]), "s")
    t_over = float(b.overturn_t_s) if b.overturn_t_s is not None else float("nan")
    nums["bump_overturn_t_s"] = number(11.0, t_over, "s")
    n = min(h.t_s.size, b.t_s.size)
    df = pd.DataFrame({"t_s": h.t_s[:n], "theta_housner_rad": h.theta_rad[:n], "theta_bumps_rad": b.theta_rad[:n]})
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 3.6), constrained_layout=True)
    ax.plot(h.t_s, h.theta_rad / blk.alpha_rad, label="Housner")
    ax.plot(b.t_s, b.theta_rad / blk.alpha_rad, label="one bump")
    ax.set(xlabel="t [s]", ylabel="theta / alpha", title="Northridge MUL009, 2b = 0.63 m, 2h = 2.52 m")
    ax.legend()
    _save(fig, ctx.png("ther:Fig. 14"))
    note = (
        f"Housner: peak {peak:.2f} alpha at {h.t_s[k]:.3g} s (thesis: about 80 % at about 9 s); one bump overturns "
        f"at {t_over:.4g} s (about 11 s). The thesis's b = 0.315 m, h = 1.261 m are half sizes (diagonal 2.6 m)"
    )
    return Built(df, nums, note)


#: The widths (mm) at which Eq. A3 with 5 mm cut corners gives Table 2's printed 28.4 % and 17.7 %
#: for h/b = 2.79 and 3.70 (tests/test_papers_gallery.py solves for them again).
TABLE23_IMPLIED_B_MM = (181.1, 204.2)

BUILDERS = {4: fig4, 12: fig12, 29: fig29, 14: fig14, **_SPECTRA, **_SETS}
NEEDS_RECORDS = {14, *_SPECTRA_RECORDS, *_SETS_RECORDS}


def _entries():
    out = []
    for n, cap in CAPTIONS.items():
        key = f"ther:Fig. {n}"
        if n in (8, 33):
            out.append(Entry(key, cap, lambda ctx, k=key: _curve(ctx, k, ["half-sine"])))
        elif n == 34:
            out.append(Entry(key, cap, lambda ctx, k=key: _curve(ctx, k, ["half-sine", "full-sine"])))
        elif n in BUILDERS:
            out.append(Entry(key, cap, BUILDERS[n], needs_records=n in NEEDS_RECORDS))
        else:
            out.append(Entry(key, cap, why_not=WHY[n]))
    for n, cap in TABLES.items():
        why = {
            1: "measured data of other authors (quoted, not computed)",
            2: "the model column (Housner with the 5 mm cut corners, Eq. A3) needs the blocks' widths, drawn in "
            "Fig. 23 only, and the thesis is held as a text extraction without its figures (../shared/papers); "
            "from h/b alone Housner loses 31.2 % and 19.4 % (printed 28.4 % and 17.7 %). The printed values "
            f"imply b = {TABLE23_IMPLIED_B_MM[0]:.0f} mm and {TABLE23_IMPLIED_B_MM[1]:.0f} mm (a reading to check "
            "against Fig. 23, not used as data); the experiment columns are the thesis's measurements",
            3: "as Table 2: the model losses need the blocks' widths (Fig. 23 only). With the widths Table 2's "
            "printed values imply, Eq. A3/A7 give configuration b (a middle wire) 14.8 % and 9.1 % (printed "
            "14.8 %, 9.0 %), c (wires 7 mm in) 27.3 % and 17.0 % (26.5 %, 17.2 %), d (c and a middle wire) "
            "14.2 % and 8.7 % (13.8 %, 8.6 %): the thesis's two tables agree with each other and with rocklab's "
            "laws to 0.8 points (tests/test_papers_gallery.py)",
            4: "needs the 44 FEMA far-field records (not shipped): `python benchmarks/oas_fema44.py` computes it where they are",
            5: "needs the near-field records (not shipped)",
        }[n]
        out.append(Entry(f"ther:Table {n}", cap, why_not=why))
    return out


ENTRIES = _entries()
