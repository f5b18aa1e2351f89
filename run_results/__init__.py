"""Per-run results with honest uncertainty, for every test mode (docs/run-results.md).

Pure functions: ``process_run(run) -> RunResult``;
``towed_vs_powered(results_table(results))``. Never
reads ground truth.
"""

from importlib import import_module

#: public name -> the module defining it; imported on first use (PEP 562), so that reading
#: stored results (``run_results.result``, ``run_results.traces``) does not load the readers
_SOURCES = {"RigCompliance": "corrections", "corrected_heights": "corrections",
            "tare_record": "corrections", "results_table": "modes",
            "towed_vs_powered": "modes", "harmonic_fit": "oscillation",
            "measure_frequency_hz": "oscillation", "phase_average": "phase_average",
            "process_run": "process", "RunResult": "result", "QuantityStats": "stats",
            "quantity_stats": "stats"}

__all__ = sorted(_SOURCES)


def __getattr__(name: str):
    if name not in _SOURCES:
        raise AttributeError(f"module 'run_results' has no attribute {name!r}")
    value = getattr(import_module(f"run_results.{_SOURCES[name]}"), name)
    globals()[name] = value
    return value
