"""rocklab.fitting: restitution calibration from measured free rocking (Čeh et al. 2018 §5, Ther thesis §4).

Per experiment: :func:`fit_restitution` (constant η_e, η′_e, profile interval, suspicious-run
flags), :func:`per_impact_eta` (data-only per-impact η), :func:`energy_loss_from_peaks`
(thesis Eq. 12). Repeats: :func:`fit_many`, :func:`summarize_repeats`, :func:`campaign_table` (per-block
η_e table for the campaign functions). Campaign:
:func:`fit_eta_mat` (Eq. 16), :func:`k_table` (Eq. 17–18), :func:`fit_k_regression`
(Eq. 19) and :meth:`KRegression.predict`. Shake-table runs: :func:`fit_forced_restitution`
(η_e from half cycles), :func:`simulate_ensemble` and :func:`judge_law` (a verdict per law). Čeh's tables ship as package data
(:func:`ceh_catalogue`, :func:`catalogue_block`).
"""

from ._campaign_fits import ETA_MAT_RULES, EtaMatResult, KTableResult, fit_eta_mat, k_table, read_block_table
from ._column_ensemble import EVENT_THRESHOLD_RAD, ColumnEnsemble, ColumnVerdict, judge_column, simulate_column_ensemble
from ._catalogue import catalogue_block, ceh_catalogue, ceh_full_contact, ceh_table5
from ._ensemble import (
    BUDGET_SOURCES,
    DEFAULT_ENSEMBLE_SIZE,
    HORIZON_FRACTION,
    Ensemble,
    InputUncertainty,
    LawVerdict,
    error_budget,
    judge_law,
    response_statistics,
    simulate_ensemble,
)
from ._forced import ETA_SYSTEMATIC, ForcedRestitutionFit, fit_forced_restitution, half_cycle_segments
from ._impacts import (
    EnergyLoss,
    ReleaseInfo,
    arch_peaks,
    check_record,
    detect_release,
    energy_loss_from_peaks,
    find_crossings,
    per_impact_eta,
)
from ._table_error import FUSED_ERROR_BANDS_HZ, FUSED_ERROR_Z_VAR, fused_error_draw
from ._laws import alpha_from_hb, edge_contact_k, eta_housner, eta_modified, k_from_eta
from ._regression import CEH_EQ19, REGRESSION_FORMS, KPrediction, KRegression, fit_k_regression
from ._repeats import RepeatSummary, campaign_table, fit_many, summarize_repeats
from ._eta_fit import OBJECTIVES, WINDOWS, RestitutionFit, fit_restitution

__all__ = [
    # per experiment
    "fit_restitution",
    "RestitutionFit",
    "WINDOWS",
    "OBJECTIVES",
    "per_impact_eta",
    "energy_loss_from_peaks",
    "EnergyLoss",
    "detect_release",
    "ReleaseInfo",
    "find_crossings",
    "arch_peaks",
    "check_record",
    # shake-table runs
    "fit_forced_restitution",
    "ForcedRestitutionFit",
    "half_cycle_segments",
    "ETA_SYSTEMATIC",
    "simulate_ensemble",
    "error_budget",
    "BUDGET_SOURCES",
    "fused_error_draw",
    "FUSED_ERROR_BANDS_HZ",
    "FUSED_ERROR_Z_VAR",
    "judge_law",
    "response_statistics",
    "simulate_column_ensemble",
    "judge_column",
    "ColumnEnsemble",
    "ColumnVerdict",
    "EVENT_THRESHOLD_RAD",
    "InputUncertainty",
    "Ensemble",
    "LawVerdict",
    "DEFAULT_ENSEMBLE_SIZE",
    "HORIZON_FRACTION",
    # repeats
    "fit_many",
    "summarize_repeats",
    "RepeatSummary",
    "campaign_table",
    # campaign
    "fit_eta_mat",
    "EtaMatResult",
    "ETA_MAT_RULES",
    "k_table",
    "KTableResult",
    "read_block_table",
    "fit_k_regression",
    "KRegression",
    "KPrediction",
    "REGRESSION_FORMS",
    "CEH_EQ19",
    # closed forms
    "eta_housner",
    "eta_modified",
    "k_from_eta",
    "edge_contact_k",
    "alpha_from_hb",
    # Čeh 2018 package data
    "ceh_catalogue",
    "catalogue_block",
    "ceh_full_contact",
    "ceh_table5",
]
