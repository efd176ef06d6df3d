"""Čeh et al. (2018) block catalogue (Table 2) and fitted restitutions (Tables 3, 5) as package data.

The CSVs live in ``rocklab/data/ceh2018/`` (see PROVENANCE.md there). Masses are
stored in grams as printed and converted to kg here (file boundary).
"""

from __future__ import annotations

from functools import lru_cache
from importlib import resources

import pandas as pd

from .._errors import InputError
from ..blocks import Block

__all__ = ["ceh_catalogue", "catalogue_block", "ceh_full_contact", "ceh_table5"]


def _read(name: str) -> pd.DataFrame:
    path = resources.files("rocklab") / "data" / "ceh2018" / name
    with path.open("r", encoding="utf-8") as fh:
        return pd.read_csv(fh)


@lru_cache(maxsize=None)
def _catalogue() -> pd.DataFrame:
    df = _read("table2_blocks.csv")
    df["mass_kg"] = df.pop("mass_g") / 1000.0
    # Depth equals width except B1, whose depth is inferred (same mass and volume as B2).
    df["depth_m"] = df["b_m"].where(~df["block"].str.match(r"B1[SML]$"), 1.5 * df["b_m"])
    df["b_cm"] = 100.0 * df["b_m"]
    full = _read("table3_eta_e_full.csv")
    return df.merge(full, on="block", how="left")


def ceh_catalogue() -> pd.DataFrame:
    """Čeh Table 2 (30 blocks) joined with Table 3's η_e,full (NaN for B1).

    Returns
    -------
    DataFrame, one row per block, columns ``block, scale, b_m, h_m, h_over_b,
    alpha_rad, R_m`` (alpha and R as printed, 4 decimals), ``mass_kg, depth_m,
    b_cm, eta_e_full``.
    """
    return _catalogue().copy()


def ceh_full_contact() -> pd.DataFrame:
    """The 27 full-contact results of Table 3: ``block, b_m, h_m, eta_e`` (a FULL.csv table)."""
    df = _catalogue().dropna(subset=["eta_e_full"])
    return df[["block", "b_m", "h_m", "eta_e_full"]].rename(columns={"eta_e_full": "eta_e"}).reset_index(drop=True)


def ceh_table5() -> pd.DataFrame:
    """Table 5 as printed: ``block, k_printed, b_bar_m_printed`` (B2M's k is a known misprint)."""
    return _read("table5_k_printed.csv")


def catalogue_block(block_id: str) -> Block:
    """A :class:`~rocklab.Block` for a Čeh catalogue id such as ``"B6M"`` (case-insensitive)."""
    df = _catalogue()
    key = str(block_id).strip().upper()
    row = df[df["block"].str.upper() == key]
    if row.empty:
        raise InputError(f"block id {block_id!r}: not in the Čeh 2018 catalogue; use B1S..B10S, B1M..B10M or B1L..B10L")
    r = row.iloc[0]
    return Block(
        b_m=float(r.b_m), h_m=float(r.h_m), depth_m=float(r.depth_m), mass_kg=float(r.mass_kg), name=str(r.block)
    )
