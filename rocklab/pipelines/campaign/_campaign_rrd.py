"""A campaign's Rerun recording (``campaign.rrd``): the campaign-level view of its experiments."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["campaign_rrd"]

#: Marker colour per contact type (Okabe-Ito), and of the reference series.
CONTACT_COLOURS = {"full": [0, 114, 178], "edge": [213, 94, 0]}
REFERENCE_STYLE = {"eta_H": ([120, 120, 120], "η_H (Housner)", "circle"), "eta_true": ([0, 0, 0], "truth", "cross")}


def campaign_rrd(res, path: Path) -> None:
    """Write ``campaign.rrd``: η_e against h/b as a scatter plot, one marker series per experiment
    (named by it; its entity also holds a note with the links to its own report and recording,
    folders under ``experiments/``), η_H and the truth as reference markers, the campaign's
    summary as one text document, and the campaign blueprint.

    Parameters
    ----------
    res : CampaignResult
    path : Path
        The recording to write (atomically).
    """
    import rerun as rr

    from ..._io import atomic_path
    from ..experiment._rerun import HB_TIMELINE, campaign_blueprint, close_recording, open_recording

    with atomic_path(path, suffix=".rrd") as tmp:
        rec = open_recording("rocklab", tmp, recording_id="campaign")
        t = res.ok_table
        rec.log("campaign/summary", rr.TextDocument(res.summary_md(), media_type="text/markdown"), static=True)
        for key, (colour, name, marker) in REFERENCE_STYLE.items():
            rec.log(
                f"campaign/reference/{key}",
                rr.SeriesPoints(colors=colour, names=name, markers=marker, marker_sizes=4.0),
                static=True,
            )
        for _, r in t.iterrows():
            # h/b on a sequence timeline: the viewer's plot takes its x axis from the timeline
            rec.set_time(HB_TIMELINE, sequence=int(round(1000 * r["hb"])))
            for key in REFERENCE_STYLE:
                if np.isfinite(r.get(key, np.nan)):
                    rec.log(f"campaign/reference/{key}", rr.Scalars(float(r[key])))
            rec.log(
                "campaign/experiments",
                rr.TextLog(
                    f"{r['experiment']}: block {r['block']} ({r['contact']}), η_e = {r['eta_e']:.4f}, "
                    f"η_H = {r['eta_H']:.4f}"
                ),
            )
            if not np.isfinite(r["eta_e"]):
                continue
            name = str(r["experiment"])
            folder = Path(str(r["out"])).name
            ent = f"campaign/eta_vs_hb/{r['contact']}/{name}"
            rec.log(ent, rr.Scalars(float(r["eta_e"])))
            colour = CONTACT_COLOURS.get(str(r["contact"]), [0, 158, 115])
            rec.log(
                ent,
                rr.SeriesPoints(colors=colour, names=f"η_e {name}", markers="circle", marker_sizes=5.0),
                static=True,
            )
            # selecting the marker shows this note: where the experiment's own outputs are
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
        rec.reset_time()
        hb = [int(round(1000 * x)) for x in t["hb"] if np.isfinite(x)] if len(t) else []
        rec.send_blueprint(campaign_blueprint((min(hb), max(hb)) if hb else None))
        close_recording(rec, tmp)
