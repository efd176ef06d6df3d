"""Record studies: OAS and t_I of many records (local processes or Dask), the record table, their figures."""

from ._plots_spectra import plot_oas, plot_overturning_curve, plot_tI_vs_tp
from ._spectra_batch import expand_records, h_over_b_values, oas_many, oas_table, table4_row, thesis_table4
from ._study_journal import StudyJournal

__all__ = [
    "oas_many",
    "oas_table",
    "h_over_b_values",
    "StudyJournal",
    "expand_records",
    "thesis_table4",
    "table4_row",
    "plot_oas",
    "plot_tI_vs_tp",
    "plot_overturning_curve",
]
