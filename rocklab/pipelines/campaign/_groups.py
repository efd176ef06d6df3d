"""Repeats grouped by their ``[experiment] tags``: mean ± std per group (thesis Tables 2–3,
Čeh's tape comparison).

A campaign's table carries one ``tag_<name>`` column per tag; :func:`group_repeats` summarises
the restitution and the Eq. 12 energy loss of every group of experiments sharing the values of
the chosen tags.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from ..._errors import InputError

__all__ = ["GROUPED_QUANTITIES", "group_repeats", "campaign_tags", "check_group_by"]

#: The campaign columns summarised per group (mean and sample standard deviation, ddof = 1).
GROUPED_QUANTITIES = ("eta_e", "energy_loss_mean4", "eta_equivalent")

#: The group name of experiments that do not carry a grouped tag.
UNTAGGED = "(untagged)"


def campaign_tags(configs) -> dict[str, set]:
    """Every tag name found in ``configs`` (``experiment.toml`` paths) and the values it takes.
    A config that cannot be read adds nothing (its own run reports why)."""
    from ...config import load_experiment_tags

    found: dict[str, set] = {}
    for c in configs:
        for k, v in load_experiment_tags(c):
            found.setdefault(k, set()).add(v)
    return found


def check_group_by(group_by, tags: dict[str, set], root: Path) -> tuple[tuple[str, ...], ...]:
    """The groupings a campaign reports: each ``group_by`` entry is one grouping, a
    comma-separated combination of tag names (``"config"``, ``"config,tape"``); none given:
    one grouping per tag name found. A name no experiment carries is refused before any work."""
    if not group_by:
        return tuple((k,) for k in sorted(tags))
    out = []
    for entry in group_by:
        names = tuple(n.strip() for n in str(entry).split(",") if n.strip())
        if not names:
            raise InputError(f"--group-by {entry!r}: give tag names, e.g. --group-by config or config,tape")
        for n in names:
            if n not in tags:
                have = ", ".join(sorted(tags)) or "none"
                raise InputError(
                    f"--group-by {entry!r}: no experiment under {root} has the tag {n!r} "
                    f'(tags found: {have}); add it to [experiment] tags = {{ {n} = "..." }} or group by another'
                )
        out.append(names)
    return tuple(out)


def group_repeats(table: pd.DataFrame, groupings) -> pd.DataFrame:
    """Mean ± std of :data:`GROUPED_QUANTITIES` per group of experiments.

    Parameters
    ----------
    table : DataFrame
        A campaign table (failed experiments are left out) with ``tag_<name>`` columns.
    groupings : sequence of tuple of str
        Each a combination of tag names.

    Returns
    -------
    DataFrame
        One row per grouping and group: ``group_by`` (names joined by ``+``), ``group`` (values
        joined by ``/``; :data:`UNTAGGED` for experiments without a name), ``n``, ``experiments``,
        and per quantity ``<q>_mean``, ``<q>_std`` (sample, NaN for one value) and ``<q>_n``
        (finite values). η is dimensionless; the energy loss is a fraction per rocking.
    """
    rows = []
    ok = table[table["status"] != "failed"] if "status" in table else table
    for names in groupings:
        keys = []
        for n in names:
            col = ok[f"tag_{n}"] if f"tag_{n}" in ok else pd.Series([None] * len(ok), index=ok.index)
            keys.append(col.map(lambda v: UNTAGGED if v is None or v == "" or v != v else str(v)))
        label = pd.Series(["/".join(parts) for parts in zip(*keys)], index=ok.index, dtype=object) if keys else None
        for value, sub in ok.groupby(label, sort=True):
            row = {"group_by": "+".join(names), "group": value, "n": len(sub)}
            row["experiments"] = " ".join(map(str, sub["experiment"]))
            for q in GROUPED_QUANTITIES:
                x = pd.to_numeric(sub[q], errors="coerce").to_numpy(float) if q in sub else np.array([])
                x = x[np.isfinite(x)]
                row[f"{q}_mean"] = float(np.mean(x)) if x.size else np.nan
                row[f"{q}_std"] = float(np.std(x, ddof=1)) if x.size > 1 else np.nan
                row[f"{q}_n"] = int(x.size)
            rows.append(row)
    return pd.DataFrame(rows)


def group_lines_md(groups: pd.DataFrame) -> list[str]:
    """Markdown tables of :func:`group_repeats`, one per grouping."""
    from ..reports import sig as g

    if groups is None or not len(groups):
        return []
    lines = ["## Repeats by tag", ""]
    for by, sub in groups.groupby("group_by", sort=False):
        lines += [
            f"| {by} | n | η_e (mean ± std) | energy loss per rocking, Eq. 12 (mean ± std) | η equivalent |",
            "|---|---|---|---|---|",
        ]
        for _, r in sub.iterrows():
            cells = [f"{g(r[f'{q}_mean'])} ± {g(r[f'{q}_std'])}" if r[f"{q}_n"] else "–" for q in GROUPED_QUANTITIES]
            lines.append(f"| {r['group']} | {r['n']} | " + " | ".join(cells) + " |")
        lines.append("")
    return lines


def group_lines_text(groups: pd.DataFrame) -> list[str]:
    """The CLI's lines of :func:`group_repeats`."""
    if groups is None or not len(groups):
        return []
    out = []
    for _, r in groups.iterrows():

        def ms(q, fmt=".4f"):
            return f"{r[f'{q}_mean']:{fmt}} ± {r[f'{q}_std']:{fmt}}" if r[f"{q}_n"] else "-"

        out.append(
            f"{r['group_by']} = {r['group']}: n = {r['n']}, eta_e {ms('eta_e')}, "
            f"energy loss per rocking (Eq. 12) {ms('energy_loss_mean4')}"
        )
    return out
