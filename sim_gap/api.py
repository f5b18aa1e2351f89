"""From inputs to a written report: the one call the CLI and the bench make."""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path

from sim_gap.diagnose import Settings, diagnose
from sim_gap.measured import load_measured
from sim_gap.report import build_report, write_json
from sim_gap.simulated import load_simulated


def run_gap(measured: str, sim: str, json_path: str | Path | None = None,
            effects: list[str] | None = None,
            reference_model: str | None = None, settings: Settings | None = None) -> dict:
    """Diagnose ``measured`` (database URL, WPM CSV or CMU smooth_runs.csv) against ``sim``
    (model TOML or WPM CSV); write the JSON report when ``json_path`` is given. The HTML
    page: ``campaign_report.gap.write_gap_page(report, path)``."""
    settings = settings or Settings()
    points = load_measured(measured)
    simulated = load_simulated(sim, reference_model)
    report = build_report(diagnose(points, simulated, effects, settings), measured, sim,
                          asdict(settings))
    if json_path:
        write_json(report, json_path)
    return report
