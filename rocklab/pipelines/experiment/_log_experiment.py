"""Log one :class:`ExperimentResult` to Rerun (file and/or live viewer)."""

from __future__ import annotations

import functools

import numpy as np

from ._rerun import (
    close_recording,
    experiment_blueprint,
    log_events,
    log_impact_markers,
    log_series as _log_series,
    log_video_asset,
    log_video_frames,
    open_recording,
)

__all__ = ["log_experiment"]

ROOT = "experiment"

#: Measured data dark and bold, every simulation its own colour (Okabe-Ito, colour-blind safe),
#: the synthetic truth thin grey: (RGB, line width in points).
STYLE = {
    "measured_video": ([0, 0, 0], 3.0),
    "measured_imu": ([90, 55, 20], 2.5),
    "measured_track": ([0, 0, 0], 3.0),
    "truth": ([150, 150, 150], 1.0),
    "sim_column": ([0, 114, 178], 1.5),
}
SIM_COLOURS = {
    "housner": [230, 159, 0],
    "eta_e": [0, 114, 178],
    "modified": [0, 158, 115],
    "eta_e_first": [204, 121, 167],
    "given": [213, 94, 0],
}
_SPARE = [[86, 180, 233], [240, 228, 66], [204, 121, 167]]


def _style(key: str, i: int = 0):
    if key in STYLE:
        return STYLE[key]
    law = key.removeprefix("sim_")
    return SIM_COLOURS.get(law, _SPARE[i % len(_SPARE)]), 1.5


def _theta(rec, bp: str, key: str, t, th, name: str, i: int = 0, t_min_s: float | None = None) -> int:
    """θ of one series in rad and in degrees (``theta`` and ``theta_deg``), in its colour."""
    colour, width = _style(key, i)
    kw = dict(color=colour, width=width, name=name, t_min_s=t_min_s)
    n = _log_series(rec, f"{bp}/theta/{key}", t, th, **kw)
    _log_series(rec, f"{bp}/theta_deg/{key}", t, np.degrees(np.asarray(th, float)), **kw)
    return n


def _film_start_s(res) -> float | None:
    """Time of the film's first logged frame, s (None without a film in the recording)."""
    if res.config.video is None or res.video is None or not len(res.video.frame_index):
        return None
    i0 = int(res.video.frame_index[0])
    if res.video.kind == "av1" and res.frames is not None and res.frames.tracks:
        tr0 = res.frames.tracks[0]
        hit = np.flatnonzero(np.asarray(tr0.frame, int) == i0)
        if hit.size:
            return float(np.asarray(tr0.t_s, float)[hit[0]])
    return i0 / float(res.frames.fps)


def _impact_times(sim, t_min_s: float | None) -> np.ndarray:
    """Impact times of one simulation (a LawSimulation), s (those from ``t_min_s`` on)."""
    t = sim.impact_times_s()
    return t if t_min_s is None else t[t >= t_min_s]


def _focus(ref, t_s, residual_rad):
    """(t_impact_s, t0_s, t1_s): the impact of the simulation ``ref`` nearest the largest
    |measured − simulated| (``residual_rad`` at ``t_s``) and a window of a few half-cycles
    around it, for the blueprint to open on; None without one."""
    if ref is None or ref.impacts is None or not len(ref.impacts):
        return None
    r = np.abs(np.asarray(residual_rad, float))
    if not np.isfinite(r).any():
        return None
    t_worst = float(np.asarray(t_s, float)[int(np.nanargmax(r))])
    ti = ref.impact_times_s()
    k = int(np.argmin(np.abs(ti - t_worst)))
    # two half-cycles either side (impacts k-2 .. k+2), never less than 0.15 s each way
    t0 = min(float(ti[max(k - 2, 0)]), float(ti[k]) - 0.15)
    t1 = max(float(ti[min(k + 2, len(ti) - 1)]), float(ti[k]) + 0.15)
    return float(ti[k]), t0, t1


def _rotate(theta: float, pts) -> np.ndarray:
    c, s = np.cos(theta), np.sin(theta)
    return np.asarray(pts, float) @ np.array([[c, s], [-s, c]])


def sim_outline(b_m: float, h_m: float, theta_meas_rad: float, theta_sim_rad: float) -> np.ndarray:
    """Outline of the simulated block, in the measured block's own frame, m (shape (5, 2)).

    The block rocks on a bottom corner (θ > 0 counter-clockwise: the left one). The measured pose
    fixes the table's base line and the resting place of the block; the simulated block stands at
    that place, tilted by ``theta_sim_rad`` about its own corner. The result is in the frame of the
    measured block (centred on its front face, x right, y up), the frame overlays are drawn in.
    """
    half = np.array([b_m / 2, h_m / 2])
    rect = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * half
    sm = 1.0 if theta_meas_rad >= 0 else -1.0
    ss = 1.0 if theta_sim_rad >= 0 else -1.0
    # the measured pivot corner, and the block's centre at rest, relative to the measured centre
    rest_centre = _rotate(theta_meas_rad, [-sm * half[0], -half[1]]) + [sm * half[0], half[1]]
    pivot_sim = rest_centre + [-ss * half[0], -half[1]]
    centre_sim = pivot_sim + _rotate(theta_sim_rad, [ss * half[0], half[1]])
    corners = centre_sim + _rotate(theta_sim_rad, rect)
    return _rotate(-theta_meas_rad, corners)


def _overlay_fn(res):
    """Per-frame overlays: target centres and block outlines mapped back to pixels from the
    tracked poses (θ itself is on the plots, not in a per-frame text line)."""
    tr = res.frames
    b = res.block
    shapes = []
    if tr is not None and getattr(tr, "plane_map", None) is not None:
        rect = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * [b.b_m / 2, b.h_m / 2]
        blocks = res.column.objects if res.column is not None else [res.config.video.object]
        for o in tr.config.objects:
            targets = o.dots if o.dots else o.marker_positions_m
            # the outline assumes the object frame is centred on the block's front face (as
            # `rocklab synth` writes it); drawn only where the config defines that frame
            framed = bool(o.dots) or o.marker_positions_m is not None or o.size_m is not None
            outline = rect if (o.id in blocks and framed) else None
            shapes.append((o.id, None if targets is None else np.asarray(targets, float), outline))

    # each law's simulated block beside the measured one (one block only: a column has its own model)
    sims, t_of, th_of = [], {}, {}
    main = res.config.video.object if res.config.video is not None else None
    if res.column is None and any(oid == main and outline is not None for oid, _, outline in shapes):
        tm = tr[main]
        t_of = dict(zip(np.asarray(tm.frame, int).tolist(), np.asarray(tm.t_s, float).tolist()))
        th_of = dict(zip(np.asarray(tm.frame, int).tolist(), np.asarray(tm.theta_rad, float).tolist()))
        for i, (law, s) in enumerate(res.simulations.items()):
            # a simulation that came to rest stays upright to the film's end
            after = 0.0 if s.status == "rest" else np.nan
            sims.append(
                (law, np.asarray(s.t_s, float), np.asarray(s.theta_rad, float), after, _style(f"sim_{law}", i)[0])
            )

    def fn(idx):
        pts, lines = [], []
        for oid, targets, outline in shapes:
            if targets is not None and len(targets):
                p = tr.to_pixels(oid, idx, targets)
                pts.extend(p[np.isfinite(p).all(axis=1)])
            if outline is not None:
                q = tr.to_pixels(oid, idx, outline)
                if np.isfinite(q).all():
                    lines.append(q)
        ov = {"points": np.asarray(pts) if pts else None, "outlines": lines, "sim": []}
        if sims and idx in t_of and np.isfinite(th_of[idx]):
            for law, ts, ths, after, colour in sims:
                # before the release the model's block is held at its initial angle
                th_s = float(np.interp(t_of[idx], ts, ths, left=ths[0], right=after))
                if np.isfinite(th_s):
                    q = tr.to_pixels(main, idx, sim_outline(b.b_m, b.h_m, th_of[idx], th_s))
                    if np.isfinite(q).all():
                        ov["sim"].append((law, q, colour))
        return ov

    return fn


def log_experiment(
    res, rrd_path=None, *, spawn: bool = False, connect: str | None = None, progress: bool = False
) -> dict:
    """Write the experiment to ``rrd_path`` (and/or a live viewer). Returns rows per entity sent.

    With a film, nothing is logged before its first frame: the viewer opens with its time cursor
    at the timeline's start, which is then the film's first frame.
    """
    t_min = _film_start_s(res)
    rec = open_recording("rocklab", rrd_path, spawn=spawn, connect=connect, recording_id=f"experiment-{res.name}")
    rows: dict[str, int] = {}
    blk = f"{ROOT}/block_1"
    _log_geometry(rec, res)
    focus = _log_block(rec, res, blk, t_min, rows)
    block_paths = _log_column(rec, res, t_min, rows) if res.column is not None else [blk]
    if res.table is not None:
        for k, v in res.table.columns().items():
            rows[f"{ROOT}/table/{k}"] = _log_series(rec, f"{ROOT}/table/{k}", res.table.t_s, v, t_min_s=t_min)
    has_video = res.config.video is not None
    if has_video:
        _log_film(rec, res, progress, rows)
    rec.send_blueprint(experiment_blueprint(block_paths, has_video=has_video, focus=focus))
    close_recording(rec, rrd_path)
    return rows


def _log_geometry(rec, res) -> None:
    """The block's dimensions and contact as a static text document."""
    import rerun as rr

    b = res.block
    rec.log(
        f"{ROOT}/geometry",
        rr.TextDocument(
            f"block {b.name}: b = {b.b_m} m, h = {b.h_m} m, alpha = {b.alpha_rad:.5f} rad, "
            f"R = {b.R_m:.5f} m, p = {b.p_rad_s:.4f} rad/s, eta_H = {b.eta_H:.4f}; "
            f"contact {res.config.contact}",
            media_type="text/markdown",
        ),
        static=True,
    )


def _log_block(rec, res, blk: str, t_min, rows: dict):
    """θ measured and simulated, energies, the ensemble's bands, residuals and impacts of the
    single block; returns the time window the blueprint focuses on."""
    log_series = functools.partial(_log_series, t_min_s=t_min)
    theta = functools.partial(_theta, t_min_s=t_min)
    for name, (t, th) in res.measured.items():
        rows[f"{blk}/theta/measured_{name}"] = theta(rec, blk, f"measured_{name}", t, th, f"measured ({name})")
    for i, (law, s) in enumerate(res.simulations.items()):
        rows[f"{blk}/theta/sim_{law}"] = theta(
            rec, blk, f"sim_{law}", s.t_s, s.theta_rad, f"sim {law} (η = {s.eta:.4g})", i
        )
        colour, width = _style(f"sim_{law}", i)
        rows[f"{blk}/energy/sim_{law}"] = log_series(
            rec, f"{blk}/energy/sim_{law}", s.t_s, s.energy_J, color=colour, width=width, name=f"sim {law} (J)"
        )
    val = res.validation
    for i, law in enumerate(res.simulations):
        band = val.bands.get(law) if val is not None else None
        if band is None:
            continue
        # the ensemble's 5–95 % band as two thin lines in the law's colour
        colour = _style(f"sim_{law}", i)[0]
        for q, th in (("p05", band[1]), ("p95", band[2])):
            key = f"band_{law}_{q}"
            rows[f"{blk}/theta/{key}"] = log_series(
                rec, f"{blk}/theta/{key}", band[0], th, color=colour, width=0.5, name=f"{law} {q[1:]} % of ensemble"
            )
            log_series(rec, f"{blk}/theta_deg/{key}", band[0], np.degrees(th), color=colour, width=0.5, name=key)
    if val is not None:
        verdicts = ", ".join(f"{law} {v.verdict} (score {v.score:.3g})" for law, v in val.laws.items())
        log_events(rec, f"{blk}/validation", np.array([val.horizon_s]), [f"predictability horizon; {verdicts}"])
        rows[f"{blk}/validation"] = 1
    if res.truth is not None:
        rows[f"{blk}/theta/truth"] = theta(rec, blk, "truth", res.truth.t_s, res.truth.theta_rad, "truth")
    if res.video_imu_residual is not None:
        rows[f"{blk}/residual/video_minus_imu"] = log_series(
            rec, f"{blk}/residual/video_minus_imu", *res.video_imu_residual
        )
    t_p, th_p = res.measured[res.primary]
    residual = {}
    for i, (law, s) in enumerate(res.simulations.items()):
        residual[law] = th_p - np.interp(t_p, s.t_s, s.theta_rad, left=np.nan, right=np.nan)
        rows[f"{blk}/residual/measured_minus_sim_{law}"] = log_series(
            rec,
            f"{blk}/residual/measured_minus_sim_{law}",
            t_p,
            residual[law],
            color=_style(f"sim_{law}", i)[0],
            name=f"measured − sim {law} (rad)",
        )
    ref_law = "eta_e" if "eta_e" in res.simulations else next(iter(res.simulations), None)
    ref = res.simulations.get(ref_law)
    focus = _focus(ref, t_p, residual.get(ref_law))
    for i, (law, s) in enumerate(res.simulations.items()):
        # each law's impacts as markers on the θ plots: an impact is where θ passes through 0
        t_imp = _impact_times(s, t_min)
        if t_imp.size:
            colour = _style(f"sim_{law}", i)[0]
            for sub in ("theta", "theta_deg"):
                rows[f"{blk}/{sub}/impacts_{law}"] = log_impact_markers(
                    rec, f"{blk}/{sub}/impacts_{law}", t_imp, np.zeros(t_imp.size), color=colour, name=f"impacts {law}"
                )
    if ref is not None and len(ref.impacts):
        imp = ref.impacts
        keep = imp["t_s"].to_numpy(float) >= (-np.inf if t_min is None else t_min)
        txt = [
            f"impact {i + 1} (sim {ref_law}): ω⁻ = {a:+.3f} rad/s → ω⁺ = {c:+.3f} rad/s (η = {e:.3f})"
            for i, (a, c, e) in enumerate(zip(imp["omega_before_rad_s"], imp["omega_after_rad_s"], imp["eta"]))
        ]
        log_events(rec, f"{blk}/impacts", imp["t_s"].to_numpy(float)[keep], [x for x, k in zip(txt, keep) if k])
        rows[f"{blk}/impacts"] = int(keep.sum())
    return focus


def _log_column(rec, res, t_min, rows: dict) -> list:
    """Each block of a column run (measured, model, truth, residual) and the joints' configurations;
    returns the blocks' entity paths."""
    log_series = functools.partial(_log_series, t_min_s=t_min)
    theta = functools.partial(_theta, t_min_s=t_min)
    c = res.column
    block_paths = [f"{ROOT}/{o}" for o in c.objects]
    for i, bp in enumerate(block_paths):
        rows[f"{bp}/theta/measured_video"] = theta(
            rec, bp, "measured_video", c.t_s, c.theta_measured_rad[:, i], "measured (video)"
        )
        rows[f"{bp}/theta/sim_column"] = theta(rec, bp, "sim_column", c.sim_t_s, c.theta_sim_rad[:, i], "column model")
        sim_on = np.interp(c.t_s, c.sim_t_s, c.theta_sim_rad[:, i], left=np.nan, right=np.nan)
        rows[f"{bp}/residual/measured_minus_sim"] = log_series(
            rec, f"{bp}/residual/measured_minus_sim", c.t_s, c.theta_measured_rad[:, i] - sim_on
        )
        if c.theta_truth is not None:
            tt, th = c.theta_truth
            rows[f"{bp}/theta/truth"] = theta(rec, bp, "truth", tt, th[:, i], "truth")
    conf = c.configurations
    if len(conf):
        log_events(
            rec,
            f"{ROOT}/column/configurations",
            conf["t_s"].to_numpy(float),
            [f"joint {j}: {st} ({ev})" for j, st, ev in zip(conf["joint"], conf["state"], conf["event"])],
        )
        rows[f"{ROOT}/column/configurations"] = len(conf)
    return block_paths


def _log_film(rec, res, progress: bool, rows: dict) -> None:
    """The review film: the AV1 asset with one reference per frame, or JPEG stills."""
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(desc="rerun: video frames", unit="frame", leave=False)
    # the film was encoded while the tracker decoded it (analyse_experiment(keep_video=...))
    fps = res.frames.fps
    film = res.video
    if film is not None and film.kind == "av1":
        tr0 = res.frames.tracks[0]  # the tracker's own frame times (a variable-rate film's)
        t_of = dict(zip(np.asarray(tr0.frame, int).tolist(), np.asarray(tr0.t_s, float).tolist()))
        t_film = [t_of.get(int(i), i / fps) for i in film.frame_index]
        rows[f"{ROOT}/video"] = log_video_asset(
            rec,
            f"{ROOT}/video",
            film.data,
            film.frame_index,
            fps,
            overlays=_overlay_fn(res),
            progress=bar,
            frame_t_s=t_film,
        )
    else:
        frames = ((i, i / fps, data) for i, data in (zip(film.frame_index, film.stills) if film is not None else ()))
        rows[f"{ROOT}/video"] = log_video_frames(rec, f"{ROOT}/video", frames, overlays=_overlay_fn(res), progress=bar)
    if bar is not None:
        bar.close()
