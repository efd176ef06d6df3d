"""``rocklab demo``: the main job on the bundled example (placeholder until the pipelines land)."""

from __future__ import annotations


def register(sub):
    p = sub.add_parser("demo", help="run the main job on the bundled synthetic campaign")
    p.add_argument("--out", default="demo_out", help="output folder (default: demo_out)")
    p.set_defaults(func=run)


def run(args) -> int:
    from ..blocks import Block

    b = Block(0.045, 0.2025, name="B6M")
    print("rocklab demo: the pipeline demo lands with the pipelines issue; for now, block B6M:")
    for k in ("alpha_rad", "R_m", "p_rad_s", "eta_H", "uplift_acc_m_s2"):
        print(f"  {k:>16} = {getattr(b, k):.4f}")
    return 0
