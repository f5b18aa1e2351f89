"""Per-run results with honest uncertainty, for every test mode (docs/run-results.md).

Pure functions: ``process_run(run) -> RunResult``;
``towed_vs_powered(results_table(results))``. Never
reads ground truth.
"""

from run_results.corrections import RigCompliance, corrected_heights, tare_record
from run_results.modes import results_table, towed_vs_powered
from run_results.oscillation import harmonic_fit, measure_frequency_hz
from run_results.phase_average import phase_average
from run_results.process import process_run
from run_results.result import RunResult
from run_results.stats import QuantityStats, quantity_stats

__all__ = ["QuantityStats", "RigCompliance", "RunResult", "corrected_heights", "harmonic_fit",
           "measure_frequency_hz", "phase_average", "process_run", "quantity_stats",
           "results_table", "tare_record", "towed_vs_powered"]
