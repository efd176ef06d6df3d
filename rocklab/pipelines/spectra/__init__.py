"""Record studies: OAS and t_I of many records (local processes or Dask), the record table, their figures."""

from ._plots_spectra import plot_oas, plot_overturning_curve, plot_tI_vs_tp
from ._spectra_batch import expand_records, oas_many, oas_table, table4_row, thesis_table4

__all__ = [
    "oas_many",
    "oas_table",
    "expand_records",
    "thesis_table4",
    "table4_row",
    "plot_oas",
    "plot_tI_vs_tp",
    "plot_overturning_curve",
]
