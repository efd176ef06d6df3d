"""Log one :class:`ExperimentResult` to Rerun (file and/or live viewer)."""

from __future__ import annotations


import numpy as np

from ._rerun import close_recording, experiment_blueprint, log_events, log_series, log_video_frames, open_recording

__all__ = ["log_experiment"]

ROOT = "experiment"


def _overlay_fn(res):
    """Per-frame overlays: target centres and block outlines mapped back to pixels from the
    tracked poses, and a θ label."""
    tr = res.frames
    t, th = res.measured.get("video", (None, None))
    shapes = []
    if tr is not None and getattr(tr, "plane_map", None) is not None:
        b = res.block
        rect = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]]) * [b.b_m / 2, b.h_m / 2]
        blocks = res.column["objects"] if res.column is not None else [res.config.video.object]
        for o in tr.config.objects:
            targets = o.dots if o.dots else o.marker_positions_m
            # the outline assumes the object frame is centred on the block's front face (as
            # `rocklab synth` writes it); drawn only where the config defines that frame
            framed = bool(o.dots) or o.marker_positions_m is not None or o.size_m is not None
            outline = rect if (o.id in blocks and framed) else None
            shapes.append((o.id, None if targets is None else np.asarray(targets, float), outline))

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
        ov = {"points": np.asarray(pts) if pts else None, "outlines": lines}
        if th is not None and idx < len(th) and np.isfinite(th[idx]):
            ov["label"] = f"θ = {np.degrees(th[idx]):+.2f}°"
        return ov

    return fn


def log_experiment(res, rrd_path=None, *, spawn: bool = False, connect: str | None = None,
                   progress: bool = False) -> dict:
    """Write the experiment to ``rrd_path`` (and/or a live viewer). Returns rows per entity sent."""
    import rerun as rr

    rec = open_recording("rocklab", rrd_path, spawn=spawn, connect=connect,
                         recording_id=f"experiment-{res.name}")
    rows: dict[str, int] = {}
    blk = f"{ROOT}/block_1"
    b = res.block
    rec.log(f"{ROOT}/geometry", rr.TextDocument(
        f"block {b.name}: b = {b.b_m} m, h = {b.h_m} m, alpha = {b.alpha_rad:.5f} rad, "
        f"R = {b.R_m:.5f} m, p = {b.p_rad_s:.4f} rad/s, eta_H = {b.eta_H:.4f}; "
        f"contact {res.config.contact}", media_type="text/markdown"), static=True)

    for name, (t, th) in res.measured.items():
        rows[f"{blk}/theta/measured_{name}"] = log_series(rec, f"{blk}/theta/measured_{name}", t, th,
                                                          name=f"measured ({name})")
    for law, s in res.simulations.items():
        p = f"{blk}/theta/sim_{law}"
        rows[p] = log_series(rec, p, s["t_s"], s["theta_rad"], name=f"sim {law} η={s['eta']:.3f}")
        rows[f"{blk}/energy/sim_{law}"] = log_series(rec, f"{blk}/energy/sim_{law}", s["t_s"], s["energy_J"])
    if res.truth is not None:
        rows[f"{blk}/theta/truth"] = log_series(rec, f"{blk}/theta/truth", res.truth["t_s"],
                                                res.truth["theta_rad"], name="truth")
    if res.video_imu_residual is not None:
        rows[f"{blk}/residual/video_minus_imu"] = log_series(
            rec, f"{blk}/residual/video_minus_imu", *res.video_imu_residual)
    t_p, th_p = res.measured[res.primary]
    for law, s in res.simulations.items():
        sim_on = np.interp(t_p, s["t_s"], s["theta_rad"], left=np.nan, right=np.nan)
        rows[f"{blk}/residual/measured_minus_sim_{law}"] = log_series(
            rec, f"{blk}/residual/measured_minus_sim_{law}", t_p, th_p - sim_on)
    ref = res.simulations.get("eta_e") or next(iter(res.simulations.values()), None)
    if ref is not None and len(ref["impacts"]):
        imp = ref["impacts"]
        txt = [f"impact {i + 1}: ω⁻ = {a:+.3f} rad/s → ω⁺ = {c:+.3f} rad/s (η = {e:.3f})"
               for i, (a, c, e) in enumerate(zip(imp["omega_before_rad_s"], imp["omega_after_rad_s"], imp["eta"]))]
        log_events(rec, f"{blk}/impacts", imp["t_s"].to_numpy(float), txt, values=np.zeros(len(imp)))
        rows[f"{blk}/impacts"] = len(imp)
    block_paths = [blk]
    if res.column is not None:
        c = res.column
        block_paths = [f"{ROOT}/{o}" for o in c["objects"]]
        for i, bp in enumerate(block_paths):
            rows[f"{bp}/theta/measured_video"] = log_series(rec, f"{bp}/theta/measured_video", c["t_s"],
                                                            c["theta_measured_rad"][:, i], name="measured (video)")
            rows[f"{bp}/theta/sim_column"] = log_series(rec, f"{bp}/theta/sim_column", c["sim_t_s"],
                                                        c["theta_sim_rad"][:, i], name="column model")
            sim_on = np.interp(c["t_s"], c["sim_t_s"], c["theta_sim_rad"][:, i], left=np.nan, right=np.nan)
            rows[f"{bp}/residual/measured_minus_sim"] = log_series(
                rec, f"{bp}/residual/measured_minus_sim", c["t_s"], c["theta_measured_rad"][:, i] - sim_on)
            if "theta_truth_rad" in c:
                tt, th = c["theta_truth_rad"]
                rows[f"{bp}/theta/truth"] = log_series(rec, f"{bp}/theta/truth", tt, th[:, i], name="truth")
        conf = c["configurations"]
        if len(conf):
            log_events(rec, f"{ROOT}/column/configurations", conf["t_s"].to_numpy(float),
                       [f"joint {j}: {st} ({ev})" for j, st, ev in zip(conf["joint"], conf["state"], conf["event"])])
            rows[f"{ROOT}/column/configurations"] = len(conf)
    if res.table is not None:
        for k in ("disp_m", "vel_m_s", "acc_m_s2"):
            if k in res.table:
                rows[f"{ROOT}/table/{k}"] = log_series(rec, f"{ROOT}/table/{k}", res.table["t_s"], res.table[k])

    has_video = res.config.video is not None
    if has_video:
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(desc="rerun: video frames", unit="frame", leave=False)
        # frames were JPEG-encoded while the tracker decoded them (analyse_experiment(keep_video=...))
        fps = res.frames.fps
        frames = ((i, i / fps, data) for i, data in (res.video_jpeg or ()))
        rows[f"{ROOT}/video"] = log_video_frames(
            rec, f"{ROOT}/video", frames, overlays=_overlay_fn(res), progress=bar)
        if bar is not None:
            bar.close()
    rec.send_blueprint(experiment_blueprint(block_paths, has_video=has_video))
    close_recording(rec, rrd_path)
    return rows
