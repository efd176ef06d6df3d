"""``experiment.toml`` for ``rocklab run``: the reader of :mod:`rocklab.config` with the block
catalogue (Čeh et al. 2018, Table 2), so ``[block] id = "B6M"`` needs no dimensions.

The schema, with every key and its default, is :data:`rocklab.config.EXAMPLE_TOML` (all lengths
in m, times in s, angles in rad).
"""

from __future__ import annotations

from ...config import ExperimentConfig, load_experiment_config

__all__ = ["load_experiment"]


def load_experiment(path) -> ExperimentConfig:
    """Read and validate an ``experiment.toml`` (:func:`rocklab.config.load_experiment_config`
    with the Čeh Table 2 catalogue for ``[block] id``).

    Raises
    ------
    InputError
        Missing file, TOML syntax error (with its line), unknown table or key, wrong type or
        value (naming the key and its line), missing input files.
    """
    return load_experiment_config(path, block_catalogue=_catalogue)


def _catalogue() -> dict:
    """Čeh Table 2 as {id: {b_m, h_m, mass_kg}} (from rocklab.fitting's package data)."""
    from ...fitting import ceh_catalogue

    return {
        str(r["block"]): {"b_m": float(r["b_m"]), "h_m": float(r["h_m"]), "mass_kg": float(r["mass_kg"])}
        for _, r in ceh_catalogue().iterrows()
    }
