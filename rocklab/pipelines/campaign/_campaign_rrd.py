"""A campaign's Rerun recording (``campaign.rrd``): the campaign-level view of its experiments."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["campaign_rrd"]


def campaign_rrd(res, path: Path) -> None:
    """Write ``campaign.rrd``: η_e against h/b, one entity per experiment, each with the links to
    its own report and recording (folders under ``experiments/``), and the campaign blueprint.

    Parameters
    ----------
    res : CampaignResult
    path : Path
        The recording to write (atomically).
    """
    import rerun as rr

    from ..._io import atomic_path
    from ..experiment._rerun import campaign_blueprint, close_recording, open_recording

    with atomic_path(path, suffix=".rrd") as tmp:
        rec = open_recording("rocklab", tmp, recording_id="campaign")
        t = res.ok_table
        for _, r in t.iterrows():
            # h/b on a sequence timeline so the viewer plots η against slenderness
            rec.set_time("h_over_b_x1000", sequence=int(round(1000 * r["hb"])))
            base = f"campaign/eta/{r['contact']}/b_{int(round(1000 * r['b_m']))}mm"
            rec.log(f"{base}/eta_e", rr.Scalars(float(r["eta_e"])))
            rec.log(f"{base}/eta_H", rr.Scalars(float(r["eta_H"])))
            if np.isfinite(r.get("eta_true", np.nan)):
                rec.log(f"{base}/eta_true", rr.Scalars(float(r["eta_true"])))
            rec.log(
                "campaign/experiments",
                rr.TextLog(
                    f"{r['experiment']}: block {r['block']} ({r['contact']}), η_e = {r['eta_e']:.4f}, "
                    f"η_H = {r['eta_H']:.4f}"
                ),
            )
        rec.reset_time()
        # η_e against h/b as labelled points, one entity per experiment: clicking a point selects
        # that experiment and shows where its own report and recording are
        for _, r in t.iterrows():
            if not np.isfinite(r["eta_e"]):
                continue
            name = str(r["experiment"])
            folder = Path(str(r["out"])).name
            ent = f"campaign/eta_vs_hb/{r['contact']}/{name}"
            colour = [0, 114, 178] if r["contact"] == "full" else [213, 94, 0]
            rec.log(
                ent,
                rr.Points2D(
                    [[float(r["hb"]), -float(r["eta_e"])]],
                    labels=[name],
                    colors=[colour],
                    radii=[0.06],
                    show_labels=False,
                ),
                static=True,
            )
            rec.log(
                ent,
                rr.TextDocument(
                    f"**{name}**: block {r['block']} ({r['contact']} contact), h/b = {r['hb']:.4g}, "
                    f"η_e = {r['eta_e']:.4g}, η_H = {r['eta_H']:.4g}\n\n"
                    f"report: [experiments/{folder}/report.html](experiments/{folder}/report.html); "
                    f"review: `rerun experiments/{folder}/session.rrd`",
                    media_type="text/markdown",
                ),
                static=True,
            )
        rec.send_blueprint(campaign_blueprint())
        close_recording(rec, tmp)
