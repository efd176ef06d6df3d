"""Scene set-up for synthetic sessions: motions, layout, camera, textures, truth files."""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._errors import InputError
from ..blocks import Block

__all__ = ["build_scene", "Scene"]

TABLE_THICK_M = 0.06
_MOUNT_FRAC = 0.85  # IMU height on the block, fraction of h
#: The IMUs keep logging at least this long after the last video frame, s (as in the lab: the
#: camera is stopped first). The blocks and the table are simulated to the end of the
#: logs, so a block still rocking when the video ends keeps rocking in its IMU log.
IMU_TAIL_S = 0.5
#: ... and, as a lab logs until the blocks have rested, this long after the last block and the
#: table are still, s. The IMU reader anchors the gyro drift in a final rest (at least 0.1 s,
#: 50 ms trimmed next to the motion); a log cut while a block moves is W-IMU-NO-REST.
IMU_REST_S = 1.0
#: The blocks are simulated at most this long past the video to find their rest, s (Čeh's B9M
#: released from 0.8 alpha rocks for 12 s); a block still rocking then ends its log moving.
REST_SEARCH_S = 30.0


def _blocks(block, n):
    if block is None:
        heights = (0.20, 0.22, 0.21) if n == 3 else (0.20,)  # all survive the 45 mm sine pulse
        return [Block(0.1, h, depth_m=0.3, density_kg_m3=2700.0, name=f"block_{i + 1}") for i, h in enumerate(heights)]
    bl = list(block) if isinstance(block, (list, tuple)) else [block] * n
    if len(bl) != n or not all(isinstance(b, Block) for b in bl):
        raise InputError(f"block: give one rocklab.Block or a list of {n} Blocks")
    return bl


def _layout(layout, n):
    from ._column import column_api

    if n == 1:
        return "single"
    if layout is None:
        return "column" if column_api() is not None else "side"
    if layout not in ("column", "side"):
        raise InputError(f"layout={layout!r}: use 'column' (stacked) or 'side' (side by side)")
    if layout == "column" and column_api() is None:
        raise InputError(
            "layout='column': this rocklab has no column model (rocklab.models.simulate_column); use layout='side'"
        )
    return layout


def _simulate(blk, *, theta0_sim, base, horizon_s, restitution, eta):
    from ..models import simulate

    law = {"eta": eta} if restitution == "constant" else {}
    return simulate(
        blk, theta0_rad=theta0_sim, duration_s=horizon_s, dt_s=1e-4, restitution=restitution, base=base, **law
    )


def _table_motion(kind, seed_rng, *, record, amplitude, period, stroke, blocks, start_s, horizon_s):
    from ._scripted_motion import record_table, sine_pulse_table, still_table

    if kind == "none":
        return still_table()
    if kind == "sine":
        return sine_pulse_table(start_s, period, amplitude)
    from ..series import BaseMotion
    from ..models import bundled_record, load_base_motion

    if record is None:
        base, name = bundled_record("elcentro"), "elcentro"
    elif isinstance(record, BaseMotion):
        base, name = record, record.name
    else:
        base, name = load_base_motion(record), Path(record).name
    uplift = max(b.uplift_acc_m_s2 for b in blocks)
    return record_table(base, start_s, horizon_s - start_s - 0.5, stroke, 1.6 * uplift, name=name)


@dataclass
class Scene:
    """Everything needed to render and describe a session (internal)."""

    seed: int
    fps: float
    size: tuple
    n_frames: int
    targets: str
    camera: object
    plane_maps: tuple
    objects: list  # RenderObject, table first
    block_motions: list
    table: object
    sims: list
    params: dict
    occluders: list
    background: np.ndarray
    illumination: np.ndarray
    exposure_s: float
    readout_s: float
    noise_dn: float
    noise_seed: object
    imu_seed: object
    features: dict
    table_width_m: float
    video_info: dict = field(default_factory=dict)
    layout: str = "single"
    flicker: float = 0.0  # relative amplitude of the exposure flicker (Renderer.exposure_gain)

    @property
    def imu_end_s(self) -> float:
        """When the IMU logs end (video clock), s: :func:`imu_log_end`."""
        return imu_log_end(self.block_motions, self.sims, self.table.end_s, self.n_frames / self.fps)

    def renderer(self):
        from ._render import Renderer

        return Renderer(
            self.camera,
            self.objects,
            self.background,
            self.illumination,
            exposure_s=self.exposure_s,
            readout_s=self.readout_s,
            noise_dn=self.noise_dn,
            rng=np.random.default_rng(self.noise_seed),
            occluders=self.occluders,
            plane_maps=self.plane_maps,
            flicker=self.flicker,
            flicker_seed=self.noise_seed,
        )

    # ------------------------------------------------------------------ truth
    def truth_frame(self):
        import pandas as pd

        t = np.arange(self.n_frames) / self.fps
        parts = []
        for bm in self.block_motions:
            x, y = bm.centre(t)
            parts.append(
                pd.DataFrame(
                    {
                        "frame": np.arange(self.n_frames),
                        "t_s": t,
                        "object": bm.id,
                        "x_m": x,
                        "y_m": y,
                        "theta_rad": bm.phi(t),
                        "vx_m_s": np.nan,
                        "ax_m_s2": np.nan,
                    }
                )
            )
        tb = self.table
        parts.append(
            pd.DataFrame(
                {
                    "frame": np.arange(self.n_frames),
                    "t_s": t,
                    "object": "table",
                    "x_m": tb.u(t),
                    "y_m": 0.0,
                    "theta_rad": 0.0,
                    "vx_m_s": tb.v(t),
                    "ax_m_s2": tb.a(t),
                }
            )
        )
        df = pd.concat(parts, ignore_index=True)
        return df.sort_values(["frame", "object"], kind="stable").reset_index(drop=True)

    def _track_objects(self):
        from ._render import to_world

        objs = []
        first = np.array([0.0])
        for o in self.objects:
            f = self.features[o.id]
            e = {"id": o.id, "kind": "table" if o.id == "table" else "block"}
            ox, oy, phi = (np.asarray(v, float) for v in o.pose(first))
            if self.targets == "aruco":
                e["markers"] = [int(k) for k in f["markers"]]
                e["marker_positions_m"] = [np.mean(c, axis=0).round(12).tolist() for c in f["markers"].values()]
                # each object's own printed marker size (the table's differ from the blocks')
                e["marker_size_m"] = float(f["marker_size_m"])
            elif self.targets == "dots":
                e["dots"] = np.asarray(f["dots"]).round(12).tolist()
            elif self.targets == "markerless":
                e["roi"] = _roi_box(self.camera.project(self._inner_points(o, f, ox, oy, phi)))
                e["theta0_rad"] = float(phi[0]) if e["kind"] == "block" else None
            else:
                px = self.camera.project(to_world(o.texture.outline_m, ox, oy, phi).reshape(-1, 2))
                e["roi"] = _roi_box(px, margin_px=8.0, size=self.size)
                e["size_m"] = list(f["size_m"])
                e["theta0_rad"] = float(phi[0])
            objs.append(e)
        return objs

    def _inner_points(self, o, f, ox, oy, phi):
        """Two world points (m) spanning a region inside the object's face in the first frame
        (no background in a markerless template).

        Block: the largest box of the face's aspect inside the tilted face (90 %). Table: its
        left part up to the first block, from 6 mm above its top edge (the edge levels the
        angles) to its bottom.
        """
        from ._render import to_world

        t0 = np.array([0.0])
        b, h = f["size_m"]
        if o.id == "table":
            xb = min(
                float(to_world(ob.texture.outline_m, *(np.asarray(v, float) for v in ob.pose(t0)))[..., 0].min())
                for ob in self.objects
                if ob.id != "table"
            )
            # table body frame: origin at the top centre of the face, y up; its pose is the shift
            local = np.array([[-b / 2 + 0.01, 0.006], [min(xb - float(ox[0]) - 0.02, -b / 4), -h + 0.002]])
            return to_world(local, ox, oy, phi).reshape(-1, 2)
        a, c, ph = b / 2, h / 2, abs(float(phi[0]))
        k = 0.9 * min(a / (a * np.cos(ph) + c * np.sin(ph)), c / (a * np.sin(ph) + c * np.cos(ph)))
        centre = to_world(np.array([[0.0, c]]), ox, oy, phi).reshape(-1, 2)[0]
        return centre + np.array([[-k * a, -k * c], [k * a, k * c]])

    def write_files(self, folder: Path, *, imu: bool, imu_rate_hz: float, calibrated: bool, video: bool = True) -> dict:
        """Write truth.csv, track.toml (with a film), experiment.toml, imu/ and return session.json's content."""
        from .._io import write_frame_atomic
        from ._files import write_experiment_toml, write_track_toml

        write_frame_atomic(folder / "truth.csv", self.truth_frame())
        f1 = self.features[self.block_motions[0].id]
        if video:
            write_track_toml(
                folder / "track.toml",
                style=self.targets,
                camera=self.camera,
                objects=self._track_objects(),
                marker_size_m=f1.get("marker_size_m"),
                dot_diameter_m=f1.get("dot_diameter_m"),
                calibrated=calibrated,
            )
        b0 = self.sims[0]["block"]
        imu_info = self._write_imu(folder, imu_rate_hz) if imu else {}
        column = None
        if self.layout == "column":
            s0 = self.sims[0]
            column = {
                "objects": [m.id for m in self.block_motions],
                "blocks": [s["block"] for s in self.sims],
                "cut_m": s0["column_cut_m"],
                "impacts": s0["column_impacts"],
            }
        write_experiment_toml(
            folder / "experiment.toml",
            name=f"synth-seed{self.seed}",
            block={"id": self.block_motions[0].id, "b_m": b0["b_m"], "h_m": b0["h_m"], "mass_kg": b0["mass_kg"]},
            table_kind=self.table.kind,
            imu_objects=set(imu_info),
            column=column,
            video=video,
        )
        return self._meta(imu_info)

    def _write_imu(self, folder: Path, rate_hz: float) -> dict:
        from ._imu import write_object_imu

        out = {}
        seqs = self.imu_seed.spawn(len(self.block_motions) + 1)
        t_end = self.imu_end_s
        blocks = {s["id"]: s["block"] for s in self.sims}
        for k, bm in enumerate(self.block_motions):
            bd = blocks[bm.id]
            blk = Block(bd["b_m"], bd["h_m"], depth_m=bd["depth_m"], mass_kg=bd["mass_kg"], alpha_I=bd["alpha_I"])
            out[bm.id] = write_object_imu(
                folder / "imu" / bm.id,
                bm.id,
                block_motion=bm,
                block=blk,
                mount_m=(0.0, _MOUNT_FRAC * bm.h_m),
                t_end_s=t_end,
                rate_hz=rate_hz,
                rng=np.random.default_rng(seqs[k]),
            )
        out["table"] = write_object_imu(
            folder / "imu" / "table",
            "table",
            table=self.table,
            t_end_s=t_end,
            rate_hz=rate_hz,
            rng=np.random.default_rng(seqs[-1]),
        )
        return out

    def _meta(self, imu_info) -> dict:
        from .. import __version__

        cam = self.camera.to_dict()
        feats = {}
        for oid, f in self.features.items():
            g = {k: v for k, v in f.items() if k not in ("markers", "dots")}
            if "markers" in f:
                g["markers"] = {str(k): np.asarray(c).tolist() for k, c in f["markers"].items()}
            if "dots" in f:
                g["dots"] = np.asarray(f["dots"]).tolist()
            feats[oid] = g
        return {
            "rocklab_version": __version__,
            "seed": self.seed,
            "params": self.params,
            "fps": self.fps,
            "size_px": list(self.size),
            "n_frames": self.n_frames,
            "duration_s": self.n_frames / self.fps,
            "targets": self.targets,
            "exposure_s": self.exposure_s,
            "rolling_shutter_readout_s": self.readout_s,
            "noise_dn": self.noise_dn,
            "psf_sigma_px": 0.5,
            "blocks": self.sims,
            "table": self.table.info | {"width_m": self.table_width_m, "thickness_m": TABLE_THICK_M},
            "occlusions": [o.__dict__ for o in self.occluders],
            "camera": cam,
            "features_object_frame": feats,
            "video": self.video_info,
            "imu": imu_info,
            "conventions": {
                "world": "rocking plane, x right, y up as seen by the camera, table top y = 0, m",
                "theta_rad": "counter-clockwise angle seen by the camera (tracker convention) = "
                "-theta of rocklab.models.simulate with base = table ax_m_s2",
                "t_s": "frame i is centred on t_s = i / fps (with rolling shutter: the middle row)",
                "x_m, y_m": "blocks: centre of the front face; table: top centre of its front face",
                "object_frame": "origin as x_m, y_m; x right, y up when upright",
                "simulated_span": f"truth.csv covers the video frames; the motions (and blocks' "
                f"impact_t_s, n_impacts, sim_status, max_abs_theta_rad) run on to "
                f"the end of the IMU logs, {IMU_REST_S} s after the blocks and the table are still "
                f"(at least {IMU_TAIL_S} s after the last frame; the blocks are simulated at most "
                f"{REST_SEARCH_S} s past the video to find their rest)",
                "imu_end_s": self.imu_end_s,
            },
        }


def _roi_box(px, margin_px: float = 0.0, size=None) -> list:
    """``[u, v, w, h]`` (px, 0.1 px) of the box round the pixels ``px`` (n, 2), grown by
    ``margin_px`` and, given the frame ``size`` (W, H), clipped to it."""
    u0, v0 = px.min(axis=0) - margin_px
    u1, v1 = px.max(axis=0) + margin_px
    if size is not None:
        u0, v0 = max(0.0, u0), max(0.0, v0)
        u1, v1 = min(size[0] - 1.0, u1), min(size[1] - 1.0, v1)
    return [round(float(u0), 1), round(float(v0), 1), round(float(u1 - u0), 1), round(float(v1 - v0), 1)]


def build_scene(
    *,
    seed,
    blocks,
    table,
    fps,
    size,
    targets,
    duration_s,
    occlusion,
    rolling_shutter,
    block,
    restitution,
    eta,
    theta0_rad,
    record,
    table_amplitude_m,
    table_period_s,
    table_stroke_m,
    exposure_s,
    noise_dn,
    distortion,
    layout=None,
    texture="procedural",
    column_cut_m=0.0,
    column_impacts=1,
) -> Scene:
    ss = np.random.SeedSequence(seed)
    s_cam, s_motion, s_tex, s_noise, s_imu, s_bg = ss.spawn(6)
    rng_m = np.random.default_rng(s_motion)
    blks = _blocks(block, blocks)
    n = len(blks)
    layout = _layout(layout, n)
    if layout == "column" and block is None:  # thesis §4.3: three 100 x 200 mm granite blocks
        blks = [Block(0.1, 0.2, depth_m=0.3, density_kg_m3=2700.0, name=f"block_{i + 1}") for i in range(n)]
    if table_amplitude_m is None:
        # The column overturns under the full 45 mm smooth pulse (its peak acceleration is
        # ~2.1 A w^2 = 10 m/s^2); 20 mm keeps it rocking, as the thesis column did.
        table_amplitude_m = 0.02 if layout == "column" else 0.045
    rest_s = 0.6
    horizon = float(duration_s) if duration_s is not None else 12.0
    # The motions run past the video to the end of the IMU logs (IMU_TAIL_S after the last frame, up to half
    # a frame past `horizon` by rounding, + 0.1 s for the IMU's interval means), and on until the blocks rest
    # (the simulators stop there), REST_SEARCH_S at most. Fixed-step integration: the part under the video
    # is the same as a run stopped at the video's end.
    sim_end = horizon + IMU_TAIL_S + 0.5 / fps + 0.1 + REST_SEARCH_S
    tbl = _table_motion(
        table,
        rng_m,
        record=record,
        amplitude=table_amplitude_m,
        period=table_period_s,
        stroke=table_stroke_m,
        blocks=blks,
        start_s=rest_s,
        horizon_s=max(horizon, 3.0),
    )
    base = tbl.base_motion(sim_end)
    law, column = (restitution, eta), (column_cut_m, column_impacts)
    motions, sims, ends = _block_motions(
        layout, blks, theta0_rad, tbl, base, table, (rest_s, sim_end), rng_m, law, column=column
    )
    if duration_s is None:
        duration_s = float(np.clip(max(ends) + 0.6, 2.0, 12.0))
    n_frames = max(2, int(round(duration_s * fps)))
    _check_motions_cover(motions, sims, imu_log_end(motions, sims, tbl.end_s, n_frames / fps))
    table_w = 1.2 if layout == "side" else 0.8
    stroke = {"none": 0.0, "sine": table_amplitude_m, "record": table_stroke_m}[table]
    cam = _framed_camera(size, blks, layout, table_w + 2 * stroke, np.random.default_rng(s_cam), distortion)
    maps = cam.plane_maps()
    mpp = cam.m_per_px((0.0, 0.5 * max(b.h_m for b in blks)))
    texel, psf_m = mpp / 4.0, 0.5 * mpp
    objects, feats = _textured_objects(
        blks, motions, tbl, table, targets, table_w, texel, psf_m, np.random.default_rng(s_tex), texture
    )
    background, illum = _background(maps, size, targets, np.random.default_rng(s_bg), texture)
    occl = _occluders(occlusion, [o.id for o in objects])
    exposure = 0.5 / fps if exposure_s is None else float(exposure_s)
    params = _scene_params(
        blocks=blocks,
        table=table,
        fps=fps,
        size=size,
        targets=targets,
        duration_s=duration_s,
        rolling_shutter=rolling_shutter,
        restitution=restitution,
        eta=eta,
        table_amplitude_m=table_amplitude_m,
        table_period_s=table_period_s,
        table_stroke_m=table_stroke_m,
        noise_dn=noise_dn,
        distortion=distortion,
        layout=layout,
    )
    return Scene(
        seed,
        fps,
        tuple(size),
        n_frames,
        targets,
        cam,
        maps,
        objects,
        motions,
        tbl,
        sims,
        params,
        occl,
        background,
        illum,
        exposure,
        (0.8 / fps) if rolling_shutter else 0.0,
        float(noise_dn),
        s_noise,
        s_imu,
        feats,
        table_w,
        layout=layout,
    )


#: build_scene's options, which ``synth_session`` forwards as it was given them
SCENE_OPTIONS = frozenset(inspect.signature(build_scene).parameters)


def _release_angles(theta0_rad, blks) -> list:
    """Initial tilts of blocks rocking side by side, rad (default: ±0.5 alpha, alternating)."""
    if theta0_rad is None:
        return [s * 0.5 * b.alpha_rad for s, b in zip((1, -1, 1), blks)]
    phi0 = list(np.broadcast_to(np.asarray(theta0_rad, float), (len(blks),)))
    for p, b in zip(phi0, blks):
        if not abs(p) < b.alpha_rad:
            raise InputError(f"theta0_rad={p!r}: must be within ±alpha = ±{b.alpha_rad:.4f} rad")
    return phi0


def _block_motions(layout, blks, theta0_rad, tbl, base, table, times_s, rng_m, law, column=(0.0, 1)):
    """(motions, simulation summaries, end times s) of the blocks: a column, or blocks side by side.

    ``times_s`` = (release or table start, end of the simulation), ``law`` = (restitution, eta),
    ``column`` = (cut at every joint m, impacts per closing).
    """
    rest_s, sim_end = times_s
    phi0 = _release_angles(theta0_rad, blks)  # each block within its own ±alpha, whatever the layout
    if layout == "column":
        th0 = None if theta0_rad is None else np.ravel(np.asarray(theta0_rad, float))
        # one angle: the column tilted as one body; one per level: each block's own angle
        th0 = None if th0 is None else (float(th0[0]) if th0.size == 1 else th0)
        cut_m, impacts = column
        return _column_motions(blks, tbl, base, table, rest_s, sim_end, rng_m, th0, cut_m=cut_m, impacts=impacts)
    xs = [0.0] if len(blks) == 1 else [-0.35, 0.0, 0.35]  # blocks side by side, 0.35 m apart
    return _single_motions(blks, xs, phi0, tbl, base, table, rest_s, sim_end, rng_m, *law)


def _framed_camera(size, blks, layout, table_span_m, rng, distortion):
    """The session camera, framed so the blocks (stacked or not) and the table's span (m) fit the view."""
    from ._camera import make_camera

    W, H = size
    h_max = max(b.h_m for b in blks)
    stack = sum(b.h_m for b in blks) if layout == "column" else h_max
    view_h = max(3.0 * h_max, 1.4 * stack, (table_span_m + 0.1) * H / W)
    return make_camera(size, (0.0, 0.4 * stack), view_h, rng, distortion=distortion)


def imu_log_end(motions, sims, table_end_s: float, video_end_s: float) -> float:
    """When the IMU logs end (video clock), s: :data:`IMU_REST_S` after the blocks and the table
    are still, at least :data:`IMU_TAIL_S` after the video.

    A simulation stops when its block rests (or falls): its last time is when the block is still.
    A block still rocking at the end of its simulation (the rest search's end) is logged to that
    end, 0.1 s short for the IMU's interval means: its log ends moving, as a real one would.
    """
    ends = [float(m.t_s[-1]) for m in motions]
    moving = [e for e, s in zip(ends, sims) if s["sim_status"] == "rocking"]
    end = min(moving) - 0.1 if moving else max([float(table_end_s), *ends]) + IMU_REST_S
    return max(float(video_end_s) + IMU_TAIL_S, end)


def _check_motions_cover(motions, sims, t_end_s: float) -> None:
    """Every block still rocking is simulated to the end of the IMU logs, ``t_end_s``."""
    for m, sim in zip(motions, sims):
        # a run cut short while still moving would freeze the block in the IMU log's tail
        if sim["sim_status"] == "rocking" and float(m.t_s[-1]) < t_end_s:
            raise AssertionError(
                f"{m.id}: simulated to {float(m.t_s[-1]):.3f} s only, before the IMU logs end at {t_end_s:.3f} s"
            )


def _textured_objects(blks, motions, tbl, table, targets, table_w, texel, psf_m, rng_t, texture):
    """The table and each block as textured render objects, and the features (markers, dots)
    each carries in its own frame."""
    from ._render import RenderObject
    from ._render_targets import block_texture, table_texture

    objects, feats = [], {}
    dot_dia = min(min(0.16 * b.b_m, 0.08 * b.h_m) for b in blks)
    tt = table_texture(
        table_w,
        TABLE_THICK_M,
        targets,
        marker_ids=(0, 7),
        marker_size_m=0.75 * TABLE_THICK_M,
        dot_diameter_m=dot_dia,
        texel_m=texel,
        psf_px_m=psf_m,
        rng=rng_t,
    )
    objects.append(
        RenderObject(
            "table",
            tt,
            lambda t, _tb=tbl: (_tb.u(t), np.zeros_like(np.asarray(t, float)), np.zeros_like(np.asarray(t, float))),
            static=(table == "none"),
        )
    )
    feats["table"] = dict(tt.features, size_m=[table_w, TABLE_THICK_M], origin="top centre of the front face")
    for k, (blk, bm) in enumerate(zip(blks, motions)):
        tex = block_texture(
            blk.b_m,
            blk.h_m,
            targets,
            marker_ids=(2 * k + 1, 2 * k + 2),
            marker_size_m=min(0.6 * blk.b_m, 0.3 * blk.h_m),
            dot_diameter_m=dot_dia,
            texel_m=texel,
            psf_px_m=psf_m,
            rng=rng_t,
            # stacked plain blocks alternate in shade so the joints are visible
            face_value=(212.0, 176.0)[k % 2] if targets == "edges" else None,
            texture=texture,
        )
        objects.append(RenderObject(bm.id, tex, bm.pose))
        f = dict(tex.features, size_m=[blk.b_m, blk.h_m], origin="centre of the front face")
        shift = np.array([0.0, blk.h_m / 2])  # body (bottom centre) -> face centre origin
        if "markers" in f:
            f["markers"] = {m: c - shift for m, c in f["markers"].items()}
        if "dots" in f:
            f["dots"] = f["dots"] - shift
        feats[bm.id] = f
    return objects, feats


def _occluders(occlusion, ids):
    """The occluders asked for (``(t0, t1)`` or a dict with object, t0_s, t1_s, kind), checked
    against the scene's object ids."""
    from ._render import Occluder

    occl = []
    if occlusion is not None:
        if isinstance(occlusion, dict):
            occl.append(
                Occluder(
                    str(occlusion.get("object", "block_1")),
                    float(occlusion["t0_s"]),
                    float(occlusion["t1_s"]),
                    str(occlusion.get("kind", "patch")),
                )
            )
        else:
            t0, t1 = (float(v) for v in occlusion)
            occl.append(Occluder("block_1", t0, t1))
    for oc in occl:
        if oc.object not in ids or not oc.t1_s > oc.t0_s or oc.kind not in ("patch", "hand"):
            raise InputError(
                f"occlusion={occlusion!r}: needs an object among {', '.join(ids)}, t1_s > t0_s "
                "and kind 'patch' or 'hand'"
            )
    return occl


def _scene_params(
    *,
    blocks,
    table,
    fps,
    size,
    targets,
    duration_s,
    rolling_shutter,
    restitution,
    eta,
    table_amplitude_m,
    table_period_s,
    table_stroke_m,
    noise_dn,
    distortion,
    layout,
) -> dict:
    """The render's parameters as written to ``session.json``."""
    return {
        "blocks": blocks,
        "table": table,
        "fps": fps,
        "size": list(size),
        "targets": targets,
        "duration_s": duration_s,
        "rolling_shutter": rolling_shutter,
        "restitution": restitution,
        "eta": eta,
        "table_amplitude_m": table_amplitude_m,
        "table_period_s": table_period_s,
        "table_stroke_m": table_stroke_m,
        "noise_dn": noise_dn,
        "distortion": distortion,
        "layout": {
            "single": "single block",
            "side": "independent blocks side by side",
            "column": "stacked column (rocklab.models.simulate_column)",
        }[layout],
    }


def _block_info(blk) -> dict:
    return blk.to_dict() | {"alpha_rad": blk.alpha_rad, "R_m": blk.R_m, "p_rad_s": blk.p_rad_s, "eta_H": blk.eta_H}


def _single_motions(blks, xs, phi0, tbl, base, table, rest_s, sim_end_s, rng_m, restitution, eta):
    """Independent blocks side by side: one ``simulate`` run each, to ``sim_end_s`` (video time)."""
    from ._scripted_motion import BlockMotion

    motions, sims, ends = [], [], [tbl.end_s]
    for k, blk in enumerate(blks):
        oid = f"block_{k + 1}"
        if table == "none":
            release = round(rest_s + 0.3 * k + float(rng_m.uniform(0.0, 0.1)), 4)
            res = _simulate(
                blk,
                theta0_sim=-phi0[k],
                base=None,
                horizon_s=max(sim_end_s - release, 0.5),
                restitution=restitution,
                eta=eta,
            )
            t = np.concatenate(([0.0], release + res.t_s))
            ph = np.concatenate(([phi0[k]], -res.theta_rad))
        else:
            release = None
            res = _simulate(blk, theta0_sim=0.0, base=base, horizon_s=sim_end_s, restitution=restitution, eta=eta)
            t, ph = res.t_s, -res.theta_rad
        ends.append(float(t[-1]))
        motions.append(BlockMotion(oid, blk.b_m, blk.h_m, xs[k], t, ph, tbl, release))
        imp = res.impacts
        sims.append(
            {
                "id": oid,
                "block": _block_info(blk),
                "x0_m": xs[k],
                "release_s": release,
                "theta0_rad": phi0[k] if table == "none" else 0.0,
                "restitution": restitution,
                "eta_true": (
                    float(eta) if restitution == "constant" else (blk.eta_H if restitution == "housner" else None)
                ),
                "sim_status": res.status,
                "overturned": bool(res.overturned),
                "n_impacts": int(res.n_impacts),
                "impact_t_s": [float(v) + (release or 0.0) for v in imp["t_s"]] if len(imp) else [],
                "impact_eta": [float(v) for v in imp["eta"]] if len(imp) else [],
                "max_abs_theta_rad": float(res.max_abs_theta_rad),
            }
        )
    return motions, sims, ends


def _column_motions(blks, tbl, base, table, rest_s, sim_end_s, rng_m, phi0=None, *, cut_m=0.0, impacts=1):
    """A stacked column (``rocklab.models.simulate_column``, ``cut_m`` at every joint, ``impacts``
    per closing): free rocking after a thread-burn release of the whole column tilted by half its
    slenderness angle (``phi0`` one angle: the whole column; an array: each level's own
    counter-clockwise angle), or standing on the moving table; simulated to ``sim_end_s`` (video time)."""
    from ._column import ColumnBlockView, ColumnMotion, column_api

    Column, simulate_column = column_api()
    col = Column(tuple(blks), cut_m=cut_m)
    n = len(blks)
    H = sum(b.h_m for b in blks)
    if table == "none":
        alpha_col = float(np.arctan(min(b.b_m for b in blks) / H))
        if phi0 is None:
            phi0 = 0.5 * alpha_col
        elif np.ndim(phi0) == 0 and not abs(phi0) < alpha_col:
            raise InputError(
                f"theta0_rad={phi0!r}: the column tips as one body; give |theta0| < "
                f"{alpha_col:.4f} rad (its slenderness angle)"
            )
        if np.ndim(phi0) and np.size(phi0) != n:
            raise InputError(f"theta0_rad={list(phi0)!r}: give one angle or one per level ({n})")
        levels = np.broadcast_to(np.asarray(phi0, float), (n,))
        release = round(rest_s + float(rng_m.uniform(0.0, 0.1)), 4)
        res = simulate_column(
            col, None, theta0_rad=-levels, duration_s=max(sim_end_s - release, 0.5), n_impacts=impacts
        )
        psi0 = np.diff(np.concatenate([[0.0], levels]))[None, :]  # held by the thread until the release
        t = np.concatenate(([0.0], release + res.t_s))
        psi = np.vstack([psi0, -res.phi_rad])
        phi0 = [float(v) for v in levels]
    else:
        phi0, release = [0.0] * n, None
        res = simulate_column(col, base, duration_s=sim_end_s, n_impacts=impacts)
        t, psi = res.t_s, -res.phi_rad
    cm = ColumnMotion(
        np.array([b.b_m for b in blks]),
        np.array([b.h_m for b in blks]),
        np.asarray(col.half_width_m, float),
        0.0,
        t,
        psi,
        tbl,
        release,
    )
    motions = [ColumnBlockView(f"block_{k + 1}", cm, k) for k in range(n)]
    imp = res.impacts
    common = {
        "x0_m": 0.0,
        "release_s": release,
        "restitution": "column impact model (rocklab.models)",
        "eta_true": None,
        "sim_status": res.status,
        "overturned": bool(res.overturned),
        "n_impacts": int(len(imp)),
        "impact_t_s": [float(v) + (release or 0.0) for v in imp["t_s"]] if len(imp) else [],
        "impact_joint": [int(v) for v in imp["joint"]] if len(imp) else [],
        "column_status_t_s": float(res.t_status_s),
        "column_cut_m": float(cut_m),
        "column_impacts": int(impacts),
        "column_events": [
            {"t_s": float(r.t_s) + (release or 0.0), "joint": int(r.joint), "state": r.state, "event": r.event}
            for r in res.configurations.itertuples()
            if r.event != "start"
        ],
    }
    sims = [
        {
            "id": m.id,
            "block": _block_info(b),
            "theta0_rad": phi0[k],
            "layout": "column",
            "max_abs_theta_rad": float(res.max_abs_theta_rad[k]),
        }
        | common
        for k, (m, b) in enumerate(zip(motions, blks))
    ]
    return motions, sims, [tbl.end_s, float(t[-1])]


def _background(maps, size, targets, rng, texture="procedural"):
    """Wall (faint blotches, or the brick photograph) above the table, the table's steel frame below; lighting."""
    import cv2

    W, H = size
    X, Y = maps
    wall = 50.0 if targets == "edges" else 150.0
    blot = cv2.resize(rng.standard_normal((6, 10)).astype(np.float32), (W, H), interpolation=cv2.INTER_CUBIC)
    bg = wall + (3.0 if targets == "edges" else 6.0) * blot
    if texture == "photo":
        from ._render_targets import PHOTOS, photo_texture

        img = np.ascontiguousarray(photo_texture("brick").T)  # the photograph's courses run vertically
        k = img.shape[1] / PHOTOS["brick"]  # photo pixels per metre on the wall
        # centred on the set-up: one photograph spans the view (it does not tile without a seam;
        # mirrored beyond its edges for the widest framings)
        u = ((X + 0.5 * PHOTOS["brick"]) * k).astype(np.float32)
        v = ((0.6 - Y) * k).astype(np.float32)
        bg = bg + 18.0 * cv2.remap(img, u, v, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REFLECT_101)
    bg = np.where(Y < -TABLE_THICK_M - 0.004, np.float32(72.0), bg).astype(np.float32)
    u = (np.arange(W, dtype=np.float32) - W / 2) / (W / 2)
    v = (np.arange(H, dtype=np.float32) - H / 2) / (W / 2)
    psi = rng.uniform(0, 2 * np.pi)
    grad = 0.92 + 0.1 * (np.cos(psi) * u[None, :] + np.sin(psi) * v[:, None])
    vign = 1.0 - 0.12 * (u[None, :] ** 2 + v[:, None] ** 2)
    return bg, (grad * vign).astype(np.float32)
