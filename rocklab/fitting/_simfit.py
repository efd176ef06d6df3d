"""Simulation-backed least-squares machinery for :func:`~rocklab.fitting.fit_restitution`.

``Problem`` compares a record with free-rocking simulations of constant restitution
(release time profiled by Brent, θ0 by linearised least squares); ``grid_then_brent``
and ``profile_ci`` do the 1-D search and the profile-likelihood interval.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq, minimize_scalar


class Problem:
    """Simulation-backed objective for one record (θ0 > 0 after sign normalisation).

    For each η the release time is profiled by bounded Brent and θ0 (and optionally a
    constant level offset of the measured angle) by linear least squares on the
    sensitivity ∂θ/∂θ0 (a second simulation at θ0 + h): no extra simulation per
    release-time trial.
    """

    def __init__(self, t, y, block, theta0, dt_s, duration_s, offset=False):
        from ..models import simulate

        self._simulate = simulate
        self.t, self.y, self.block = t, y, block
        self.theta0 = theta0
        self.h = min(1e-3 * theta0, 0.5 * (block.alpha_rad - theta0))
        self.dt = dt_s
        self.duration = duration_s
        self.offset = bool(offset)
        self.cache = {}
        self.n_sim = 0

    def _run(self, th0, eta):
        self.n_sim += 1
        # output every 2nd step: linear interpolation error ~ θ'' (2 dt)² / 8, far below noise
        return self._simulate(
            self.block,
            theta0_rad=th0,
            omega0_rad_s=0.0,
            duration_s=self.duration,
            dt_s=self.dt,
            restitution="constant",
            eta=float(eta),
            stop_at_rest=True,
            output_dt_s=2 * self.dt,
        )

    def sim(self, eta, sens=True):
        key = (round(float(eta), 12), bool(sens))
        r = self.cache.get(key)
        if r is None:
            r0 = self._run(self.theta0, eta)
            r1 = self._run(self.theta0 + self.h, eta) if sens else None
            r = (r0, r1)
            if len(self.cache) > 256:
                self.cache.clear()
            self.cache[key] = r
        return r

    @staticmethod
    def _at(r, tau, th0):
        right = 0.0 if r.status == "rest" else float(r.theta_rad[-1])
        return np.interp(tau, r.t_s, r.theta_rad, left=th0, right=right)

    def model(self, eta, tt, tr, sens=True):
        """(θ_sim at tt for release tr, sensitivity to θ0 or None)."""
        r0, r1 = self.sim(eta, sens)
        tau = tt - tr
        m0 = self._at(r0, tau, self.theta0)
        if r1 is None:
            return m0, None
        return m0, (self._at(r1, tau, self.theta0 + self.h) - m0) / self.h

    def _linear(self, rr, S, n):
        """Least-squares θ0 shift (column S) and level offset (column of ones) for residual rr."""
        cols = ([S] if S is not None else []) + ([np.ones(n)] if self.offset else [])
        if not cols:
            return rr, 0.0, 0.0
        A = np.column_stack(cols)
        coef, *_ = np.linalg.lstsq(A, rr, rcond=None)
        d = rr - A @ coef
        dl = float(coef[0]) if S is not None else 0.0
        c = float(coef[-1]) if self.offset else 0.0
        return d, dl, c

    def profile(self, eta, idx, t_r_bounds, sens=True):
        """min over release time (θ0 if sens, level offset if enabled) of Σ (y − θ_sim)².

        Returns (sse, t_r, θ0, offset)."""
        res = minimize_scalar(
            lambda tr: self.at_release(eta, idx, tr, sens)[0],
            bounds=t_r_bounds,
            method="bounded",
            options=dict(xatol=1e-7),
        )
        sse, th0, c = self.at_release(eta, idx, float(res.x), sens)
        return sse, float(res.x), th0, c

    def at_release(self, eta, idx, t_r, sens=True):
        """(Σ (y − θ_sim)², θ0, offset) at samples idx for release time t_r, θ0 and offset profiled."""
        yy = self.y[idx]
        m0, S = self.model(eta, self.t[idx], t_r, sens)
        d, dl, c = self._linear(yy - m0, S, yy.size)
        return float(d @ d), self.theta0 + dl, c

    def residual(self, eta, idx, t_r, theta0, offset=0.0, sens=True):
        """y − offset − θ_sim at samples idx; θ0 enters linearly (sens) or exactly via a fresh run."""
        if not sens:
            key = ("fixed", round(float(eta), 12), float(theta0))
            r = self.cache.get(key)
            if r is None:
                r = self.cache[key] = self._run(theta0, eta)
            return self.y[idx] - offset - self._at(r, self.t[idx] - t_r, theta0)
        m0, S = self.model(eta, self.t[idx], t_r, True)
        return self.y[idx] - offset - (m0 + (theta0 - self.theta0) * S)

    def peaks_residual(self, eta, data_amp, data_half, arch_ids):
        """Amplitude (rad) and half-period (scaled to rad by 2A/T) residuals of arches arch_ids."""
        r = self.sim(eta, sens=False)[0]
        imp = r.impacts
        p2 = self.block.p_rad_s**2
        a = self.block.alpha_rad
        w = np.abs(imp["omega_after_rad_s"].to_numpy())
        amp = a - np.arccos(np.clip(math.cos(a) + w * w / (2 * p2), -1, 1))
        half = np.diff(imp["t_s"].to_numpy())
        res = []
        for j, k in enumerate(arch_ids):  # arch k follows impact k (0-based)
            A_s = amp[k] if k < amp.size else 0.0
            T_s = half[k] if k < half.size else 0.0
            res.append(data_amp[j] - A_s)
            res.append((data_half[j] - T_s) * 2.0 * data_amp[j] / max(data_half[j], 1e-9))
        return np.asarray(res)


def grid_then_brent(fun_grid, fun, lo, hi, n_grid=5, xtol=1e-6):
    """1-D minimisation: coarse grid with a cheap objective, then bounded Brent on ``fun``
    between the neighbours of the best node. Returns (x, f(x), best node on the grid edge)."""
    xs = np.linspace(lo, hi, n_grid)
    fs = np.array([fun_grid(x) for x in xs])
    i = int(np.nanargmin(fs))
    a, b = xs[max(i - 1, 0)], xs[min(i + 1, n_grid - 1)]
    res = minimize_scalar(fun, bounds=(a, b), method="bounded", options=dict(xatol=xtol))
    return float(res.x), float(res.fun), (i == 0 or i == n_grid - 1)


def profile_ci(fun, x_hat, f_hat, thresh, lo, hi):
    """Interval where fun(x) − f_hat ≤ thresh, searched outward from x_hat within [lo, hi].

    The profile is nearly quadratic near its minimum, so each side is first solved by the
    fixed-point step d ← d·sqrt(thresh/Δf(d)) (exact for a parabola, 2–3 evaluations);
    if that does not settle, the crossing is bracketed and refined by Brent's method.
    """
    h = max(1e-5, 1e-4 * abs(x_hat))
    fp, fm = fun(min(x_hat + h, hi)), fun(max(x_hat - h, lo))
    curv = (fp + fm - 2 * f_hat) / (h * h)
    guess = math.sqrt(2 * thresh / curv) if curv > 0 else 1e-3
    out = []
    for direction, bound in ((-1, lo), (+1, hi)):
        room = abs(bound - x_hat)
        d = min(guess, room)
        edge = None
        for _ in range(4):
            D = fun(x_hat + direction * d) - f_hat
            if D <= 0:
                break
            if abs(D / thresh - 1) < 0.02:
                edge = x_hat + direction * d
                break
            d_new = d * math.sqrt(thresh / D)
            if d_new >= room:
                d = room
                if fun(bound) - f_hat <= thresh:
                    edge = bound
                break
            d = d_new
        if edge is None:  # fall back: bracket outward, then Brent
            x_in, step = x_hat, max(guess, 2 * h)
            edge = bound
            for _ in range(40):
                x = x_hat + direction * min(step, room)
                if fun(x) - f_hat > thresh:
                    edge = brentq(
                        lambda z: fun(z) - f_hat - thresh, *sorted((x_in, x)), xtol=max(0.02 * guess, 1e-8), rtol=1e-12
                    )
                    break
                if step >= room:
                    break
                x_in, step = x, step * 1.5
        out.append(float(edge))
    return tuple(out)


def ac_factor(res):
    if res.size < 8:
        return 1.0
    r = res - res.mean()
    den = float(r @ r)
    if den <= 0:
        return 1.0
    rho = float(r[1:] @ r[:-1]) / den
    rho = min(max(rho, 0.0), 0.95)
    return (1 + rho) / (1 - rho)
