"""``rocklab demo``: a small synthetic campaign, made deterministically, run end to end.

The campaign (all rendered by :func:`rocklab.synth.synth_session` with ArUco
targets and x-IMU logs, 960×540 at 50 fps; at this size η_e of a 4.5 cm wide
block comes back within 1e-4 of the truth). The runs read the camcorder-like
H.264 film ``video.mp4`` (17 Mbit/s at 1080p, scaled by pixels), as a lab's
footage would be; ``camcorder=False`` reads the lossless ``video.mkv`` instead:

- full-contact free rocking of Čeh Table 2 blocks (B3M, B5M, B7M, B9M, B4L), whose
  true restitution is Čeh Table 3's η_e,full, so the campaign fits k per block and
  the k(h/b, b) regression of Čeh Eq. 19;
- edge-contact free rocking (base strips l_c = 1.5 mm) whose true restitution is
  η_M(k = 1 − 2 l_c/b) · η_mat with η_mat = 0.989 (Čeh Eq. 14, 16), so the
  campaign's η_mat fit has a known answer;
- one shake-table run: the bundled 1940 El Centro record scaled to the table's
  stroke drives a block; the simulation is driven by the table IMU fused with
  the table tracked on the film;
- one 3-block column (thesis §4.3: 0.1 × 0.2 m granite blocks) on a one-cycle
  sine table pulse (the table IMU fused with the film's table drives the model),
  compared with the column model by block and by its opening/closing sequence.

Then :func:`rocklab.pipelines.run_campaign` runs them all and the demo prints
block, η_H, η_e ± CI, η_M and the truth.
"""

from __future__ import annotations


import time
from pathlib import Path

from ..._procs import spawn_pool

__all__ = ["DEMO_RUNS", "make_demo_campaign", "run_demo"]

ETA_MAT_TRUE = 0.989
L_C_M = 0.0015

#: (run name, catalogue block or "column", contact, table); the seed is the position in this list.
DEMO_RUNS = (
    ("B3M_full", "B3M", "full", "none"),
    ("B5M_full", "B5M", "full", "none"),
    ("B7M_full", "B7M", "full", "none"),
    ("B3M_edge", "B3M", "edge", "none"),
    ("B5M_edge", "B5M", "edge", "none"),
    ("B5L_elcentro", "B5L", "full", "record"),
    ("column_sine", "column", "full", "sine"),
    # two more full-contact blocks (two widths) so the campaign can fit the Eq. 19 regression
    ("B9M_full", "B9M", "full", "none"),
    ("B4L_full", "B4L", "full", "none"),
)


def _true_eta(block_id: str, contact: str) -> float:
    from ...fitting import catalogue_block, ceh_catalogue, edge_contact_k, eta_modified

    b = catalogue_block(block_id)
    if contact == "edge":
        return float(eta_modified(b.alpha_rad, edge_contact_k(b.b_m, L_C_M)) * ETA_MAT_TRUE)
    cat = ceh_catalogue().set_index("block")
    return float(cat.loc[block_id, "eta_e_full"])


def _edit_experiment(path: Path, name: str, block_id: str, contact: str, table: str, camcorder: bool) -> None:
    """Adapt the synth's experiment.toml through its schema: run name, catalogue id, contact,
    forced-run options."""
    changes: dict = dict(name=name, block_id=block_id)
    if contact == "edge":
        changes.update(contact="edge", l_c_m=L_C_M)
    if table != "none":
        # forced rocking: no free-rocking restitution fit; simulate the table-driven response
        changes.update(table=_table_imu(path))
        # (the η a lab would have calibrated on free rocking of the same block: here the truth)
        eta = float(f"{_true_eta(block_id, contact):.6f}")
        changes.update(fit_restitution=False, laws=("housner", "modified", "given"), eta_given=eta)
    _rewrite_experiment(path, camcorder, **changes)


def _table_imu(path: Path):
    """The table motion from the session's table IMU (256 Hz), synced to the film by its acceleration and
    fused with the film's table: a record's acceleration has content a 50 fps camera cannot sample, and a
    column's near-critical response moves by 4 % for 1 % of table-acceleration error (the film alone: 5 %)."""
    from ...config import SourceTable

    return SourceTable(source="imu", object="table", imu=path.parent.resolve() / "imu" / "table")


def _rewrite_experiment(path: Path, camcorder: bool, **changes) -> None:
    """Read the synth's experiment.toml, change fields of its :class:`ExperimentConfig` (the
    demo logs every 5th frame to Rerun; ``camcorder`` points the video source at the H.264 film
    the synth writes beside the lossless one) and write it back."""
    from dataclasses import replace

    from ..._io import write_text_atomic
    from ..experiment import load_experiment

    cfg = load_experiment(path)
    if camcorder:
        mp4 = cfg.video.path.with_suffix(".mp4")
        if not mp4.is_file():
            raise AssertionError(f"{path}: the synth wrote no camcorder film {mp4.name}")
        changes["video"] = replace(cfg.video, path=mp4)
    cfg = replace(cfg, video_decimation=5, **changes)
    write_text_atomic(
        path, cfg.to_toml(header=("Experiment config of the demo campaign (rocklab demo).",)), stamp=False
    )


def _render_one(
    d: Path, seed: int, name: str, bid: str, contact: str, table: str, size, fps, camcorder: bool = True
) -> Path:
    from ...fitting import catalogue_block
    from ...synth import synth_session

    cfg = d / "experiment.toml"
    if bid == "column":
        synth_session(
            d,
            seed=seed,
            blocks=3,
            table=table,
            fps=fps,
            size=size,
            targets="aruco",
            duration_s=4.0,
            mp4=camcorder,
            force=True,
        )
        _rewrite_experiment(cfg, camcorder, name=name, imu=None, table=_table_imu(cfg))
        return cfg
    blk = catalogue_block(bid)
    kw = (
        dict(theta0_rad=0.8 * blk.alpha_rad, duration_s=4.0)
        if table == "none"
        else dict(duration_s=8.0, table_stroke_m=0.01)
    )  # rocks to ~0.6 alpha, survives
    synth_session(
        d,
        seed=seed,
        blocks=1,
        table=table,
        fps=fps,
        size=size,
        targets="aruco",
        block=blk,
        eta=_true_eta(bid, contact),
        mp4=camcorder,
        force=True,
        **kw,
    )
    _edit_experiment(cfg, name, bid, contact, table, camcorder)
    return cfg


def make_demo_campaign(
    root,
    *,
    size=(960, 540),
    fps: float = 50.0,
    progress: bool = True,
    runs=DEMO_RUNS,
    workers: int = 2,
    camcorder: bool = True,
) -> list[Path]:
    """Render the demo sessions into ``root/<run>/`` (skips sessions already there), in parallel.

    ``camcorder`` (default) points each run at the H.264 film; ``False`` at the lossless one.
    """

    from tqdm import tqdm

    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    todo = [
        (root / name, seed, name, bid, contact, table, size, fps, camcorder)
        for seed, (name, bid, contact, table) in enumerate(runs)
        if not (root / name / "experiment.toml").is_file()
    ]
    bar = tqdm(total=len(todo), desc="demo: render sessions", unit="session", disable=not progress)
    if workers > 1 and len(todo) > 1:
        with spawn_pool(workers) as ex:
            for f in [ex.submit(_render_one, *job) for job in todo]:
                f.result()
                bar.update(1)
    else:
        for job in todo:
            _render_one(*job)
            bar.update(1)
    bar.close()
    return [root / name / "experiment.toml" for name, *_ in runs]


def run_demo(
    out_dir="demo_out",
    *,
    workers: int = 2,
    progress: bool = True,
    size=(960, 540),
    runs=DEMO_RUNS,
    camcorder: bool = True,
):
    """Make the demo campaign under ``out_dir/sessions`` and run it into ``out_dir/results``."""
    from ._campaign import run_campaign

    from ..._outdir import check_output_dir, claim_dir

    out_dir = check_output_dir(out_dir, need_bytes=300 * 1024 * 1024)
    claim_dir(out_dir, ("sessions", "results"), command="demo")
    t0 = time.perf_counter()
    make_demo_campaign(
        out_dir / "sessions", size=size, progress=progress, runs=runs, workers=workers, camcorder=camcorder
    )
    t1 = time.perf_counter()
    res = run_campaign(out_dir / "sessions", out_dir / "results", workers=workers, progress=progress)
    t2 = time.perf_counter()
    return res, {"render_s": t1 - t0, "campaign_s": t2 - t1}
