"""Least-squares regression k(h/b, b) (Čeh Eq. 19) with diagnostics and prediction."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .._errors import InputError
from ._laws import alpha_from_hb, eta_modified

__all__ = ["KRegression", "KPrediction", "fit_k_regression", "CEH_EQ19", "REGRESSION_FORMS"]

#: Regressor columns of each selectable form (b in cm, as in the paper).
REGRESSION_FORMS = {
    "ceh19": ("hb2", "hb", "const", "b_cm"),  # Čeh Eq. 19: linear-quadratic
    "linear": ("hb", "const", "b_cm"),
    "quadratic_b": ("hb2", "hb", "const", "b_cm", "b_cm2"),
    "hb_only": ("hb2", "hb", "const"),
    "interaction": ("hb2", "hb", "const", "b_cm", "hb_b_cm"),
}

#: Coefficients printed in Čeh Eq. 19 (k = 0.0047 (h/b)² − 0.0258 h/b + 1.0635 − 0.0565 b[cm]).
CEH_EQ19 = {"hb2": 0.0047, "hb": -0.0258, "const": 1.0635, "b_cm": -0.0565}
#: Range of the data behind Eq. 19 (Čeh Table 3): h/b in [1.5, 9.75], b in [3, 6] cm.
CEH_EQ19_RANGE = {"hb": (1.5, 9.75), "b_cm": (3.0, 6.0)}


def _design(names, hb, b_cm) -> np.ndarray:
    cols = {"hb2": hb**2, "hb": hb, "const": np.ones_like(hb), "b_cm": b_cm, "b_cm2": b_cm**2, "hb_b_cm": hb * b_cm}
    return np.column_stack([cols[n] for n in names])


@dataclass(frozen=True)
class KPrediction:
    """Predicted contact-impulse position and restitution for one block.

    Attributes
    ----------
    hb, b_m : inputs (aspect ratio h/b, width in m)
    k : predicted k = 2 b̄ / b (–)
    eta_M : η_M(α, k) from Čeh Eq. 14 (–)
    b_bar_m : impulse offset from the block centre, b k / 2 (m)
    extrapolated : True when (hb, b) lies outside the fitted data range
    feasible : k in (0, 1]
    message : why the prediction is flagged ("" when inside the range)
    """

    hb: float
    b_m: float
    k: float
    eta_M: float
    b_bar_m: float
    extrapolated: bool
    feasible: bool
    message: str = ""

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(
            hb=self.hb,
            b_m=self.b_m,
            b_cm=100 * self.b_m,
            k=self.k,
            eta_M=self.eta_M,
            b_bar_m=self.b_bar_m,
            extrapolated=self.extrapolated,
            feasible=self.feasible,
            message=self.message,
        )

    def report(self) -> str:
        lines = [
            "[[k prediction (Čeh Eq. 19, Eq. 14)]]",
            f"    h/b = {self.hb:g}, b = {100 * self.b_m:g} cm",
            f"    k = {self.k:.4f}, eta_M = {self.eta_M:.4f}, b_bar = {1000 * self.b_bar_m:.2f} mm",
        ]
        if self.message:
            lines.append(f"    WARNING: {self.message}")
        return "\n".join(lines)


@dataclass(frozen=True)
class KRegression:
    """A fitted k(h/b, b) regression (b in cm inside, as in Čeh Eq. 19).

    Attributes
    ----------
    form : key of :data:`REGRESSION_FORMS`
    coefficients : dict name -> value (``hb2, hb, const, b_cm`` for Eq. 19)
    r2, rmse : coefficient of determination and root-mean-square residual of k
    n : number of data points
    residuals : (n,) k − k̂
    loso : DataFrame ``b_cm, n, rmse, max_abs_error`` — leave-one-scale-out: refit
        without the blocks of that width and predict them (NaN if not identifiable)
    hb_range, b_cm_range : fitted data ranges (min, max), used for extrapolation flags
    """

    form: str
    coefficients: dict
    r2: float
    rmse: float
    n: int
    residuals: np.ndarray = field(repr=False)
    loso: pd.DataFrame = field(repr=False)
    hb_range: tuple
    b_cm_range: tuple

    @classmethod
    def ceh2018(cls) -> "KRegression":
        """Eq. 19 as printed (no residuals: r2/rmse NaN), range of Čeh Table 3."""
        return cls(
            form="ceh19",
            coefficients=dict(CEH_EQ19),
            r2=float("nan"),
            rmse=float("nan"),
            n=27,
            residuals=np.array([]),
            loso=pd.DataFrame(columns=["b_cm", "n", "rmse", "max_abs_error"]),
            hb_range=CEH_EQ19_RANGE["hb"],
            b_cm_range=CEH_EQ19_RANGE["b_cm"],
        )

    @classmethod
    def from_coefficients(
        cls, coefficients: dict, hb_range=(np.nan, np.nan), b_cm_range=(np.nan, np.nan)
    ) -> "KRegression":
        """A regression from stored coefficients (e.g. a ``k-table --json`` output)."""
        names = tuple(coefficients)
        form = next((f for f, n in REGRESSION_FORMS.items() if set(n) == set(names)), None)
        if form is None:
            raise InputError(
                f"coefficients {sorted(names)}: not a known regression form; expected the keys "
                f"of one of {sorted(REGRESSION_FORMS)} e.g. {list(REGRESSION_FORMS['ceh19'])}"
            )
        try:
            coefs = {n: float(coefficients[n]) for n in REGRESSION_FORMS[form]}
        except (TypeError, ValueError):
            raise InputError(f"coefficients {coefficients}: values must be numbers") from None

        def rng(r):
            r = list(r) if r is not None else [None, None]
            if len(r) != 2:
                raise InputError(f"range {r}: must be [min, max]")
            return tuple(float("nan") if v is None else float(v) for v in r)

        return cls(
            form=form,
            coefficients=coefs,
            r2=float("nan"),
            rmse=float("nan"),
            n=0,
            residuals=np.array([]),
            loso=pd.DataFrame(columns=["b_cm", "n", "rmse", "max_abs_error"]),
            hb_range=rng(hb_range),
            b_cm_range=rng(b_cm_range),
        )

    def k(self, hb, b_m):
        """k̂ at aspect ratio ``hb`` and width ``b_m`` (m; converted to cm for the formula)."""
        hb = np.asarray(hb, dtype=float)
        b_cm = 100.0 * np.asarray(b_m, dtype=float)
        names = REGRESSION_FORMS[self.form]
        X = _design(names, np.atleast_1d(hb), np.atleast_1d(b_cm) * np.ones_like(np.atleast_1d(hb)))
        out = X @ np.array([self.coefficients[n] for n in names])
        return out if hb.ndim else float(out[0])

    def predict(self, hb: float, b_m: float) -> KPrediction:
        """Predict k, η_M and b̄ for a new block; flags extrapolation outside the fitted range."""
        hb = float(hb)
        b_m = float(b_m)
        if not (np.isfinite(hb) and hb > 0):
            raise InputError(f"hb={hb}: aspect ratio h/b must be a finite number > 0")
        if not (np.isfinite(b_m) and b_m > 0):
            raise InputError(f"b_m={b_m}: block width must be a finite number > 0 m")
        k = self.k(hb, b_m)
        eta = float(eta_modified(alpha_from_hb(hb), k))
        msgs = []
        extrap = False
        b_cm = 100 * b_m
        for name, v, (lo, hi), unit in (("h/b", hb, self.hb_range, ""), ("b", b_cm, self.b_cm_range, " cm")):
            if not (np.isfinite(lo) and np.isfinite(hi)):
                extrap = True
                msgs.append(f"fitted {name} range unknown: cannot check extrapolation")
            elif not (lo - 1e-9 <= v <= hi + 1e-9):
                extrap = True
                msgs.append(f"{name}={v:g}{unit} outside the fitted [{lo:g}, {hi:g}]{unit}: extrapolation")
        feasible = bool(0 < k <= 1)
        if not feasible:
            msgs.append(f"k={k:.4f} outside (0, 1]: impulse outside the base")
        return KPrediction(
            hb=hb,
            b_m=b_m,
            k=float(k),
            eta_M=eta,
            b_bar_m=0.5 * b_m * float(k),
            extrapolated=extrap,
            feasible=feasible,
            message="; ".join(msgs),
        )

    def to_dict(self) -> dict:
        """Plain dict of the fields, JSON-ready (SI units in the keys)."""
        return dict(
            form=self.form,
            coefficients=dict(self.coefficients),
            r2=self.r2,
            rmse=self.rmse,
            n=self.n,
            residuals=[float(x) for x in self.residuals],
            hb_range=list(self.hb_range),
            b_cm_range=list(self.b_cm_range),
            loso=self.loso.to_dict(orient="records"),
        )

    def report(self) -> str:
        names = REGRESSION_FORMS[self.form]
        lines = [
            "[[Model]]",
            f"    k(h/b, b) form {self.form!r}: " + " + ".join(f"{n}" for n in names) + "  (b in cm)",
            "[[Fit Statistics]]",
            f"    data points = {self.n}",
            f"    R-squared   = {self.r2:.5f}",
            f"    RMSE        = {self.rmse:.5f}",
            "[[Coefficients]]",
        ]
        lines += [f"    {n:6s} = {self.coefficients[n]: .5f}" for n in names]
        if len(self.loso):
            lines.append("[[Leave-one-scale-out]]")
            for r in self.loso.itertuples():
                lines.append(
                    f"    b = {r.b_cm:g} cm: n = {r.n}, RMSE = {r.rmse:.4f}, max |err| = {r.max_abs_error:.4f}"
                )
        return "\n".join(lines)


def fit_k_regression(hb, b_m, k, form: str = "ceh19") -> KRegression:
    """Least-squares fit of k(h/b, b) (Čeh Eq. 19 by default; b converted to cm).

    Parameters
    ----------
    hb, b_m, k : array (n,)
        Aspect ratios h/b, widths (m) and k values (e.g. from :func:`k_table`).
        Rows with non-finite k are dropped.
    form : str
        One of :data:`REGRESSION_FORMS` (``"ceh19"``, ``"linear"``, ``"quadratic_b"``,
        ``"hb_only"``, ``"interaction"``).

    Returns
    -------
    KRegression
    """
    if form not in REGRESSION_FORMS:
        raise InputError(f"form={form!r}: unknown regression form; use one of {sorted(REGRESSION_FORMS)}")
    hb = np.asarray(hb, dtype=float).ravel()
    b_cm = 100.0 * np.asarray(b_m, dtype=float).ravel()
    k = np.asarray(k, dtype=float).ravel()
    if not (hb.shape == b_cm.shape == k.shape):
        raise InputError("hb, b_m, k: must have the same length")
    ok = np.isfinite(hb) & np.isfinite(b_cm) & np.isfinite(k)
    hb, b_cm, k = hb[ok], b_cm[ok], k[ok]
    names = REGRESSION_FORMS[form]
    if len(k) <= len(names):
        raise InputError(f"k regression '{form}': needs more than {len(names)} blocks with finite k, got {len(k)}")
    X = _design(names, hb, b_cm)
    if np.linalg.matrix_rank(X) < len(names):
        raise InputError(
            f"k regression '{form}': data do not identify all terms {names} "
            "(e.g. a single width cannot fit a b term); choose another form"
        )
    coef, *_ = np.linalg.lstsq(X, k, rcond=None)
    res = k - X @ coef
    ss_tot = float(np.sum((k - k.mean()) ** 2))
    r2 = 1.0 - float(res @ res) / ss_tot if ss_tot > 0 else float("nan")
    rmse = float(np.sqrt(np.mean(res**2)))
    rows = []
    for bc in np.unique(b_cm):
        held = np.isclose(b_cm, bc)
        Xt = X[~held]
        if np.linalg.matrix_rank(Xt) < len(names):
            rows.append(dict(b_cm=float(bc), n=int(held.sum()), rmse=np.nan, max_abs_error=np.nan))
            continue
        c, *_ = np.linalg.lstsq(Xt, k[~held], rcond=None)
        err = k[held] - X[held] @ c
        rows.append(
            dict(
                b_cm=float(bc),
                n=int(held.sum()),
                rmse=float(np.sqrt(np.mean(err**2))),
                max_abs_error=float(np.max(np.abs(err))),
            )
        )
    return KRegression(
        form=form,
        coefficients={n: float(c) for n, c in zip(names, coef)},
        r2=r2,
        rmse=rmse,
        n=int(len(k)),
        residuals=res,
        loso=pd.DataFrame(rows, columns=["b_cm", "n", "rmse", "max_abs_error"]),
        hb_range=(float(hb.min()), float(hb.max())),
        b_cm_range=(float(b_cm.min()), float(b_cm.max())),
    )
