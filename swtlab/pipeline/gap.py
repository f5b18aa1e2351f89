"""Measured against simulated: ``diagnose_gap`` -> :class:`GapReport` (docs/gap-report.md)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from swtlab.pipeline.campaign import Campaign

if TYPE_CHECKING:
    from sim_gap import report_types
    from sim_gap.simulated import Simulated
    from terramechanics import WheelModel


@dataclass
class GapReport:
    """The gap report (``data``: the JSON of docs/gap-report.md) with its main answers."""

    data: dict

    @property
    def verdict(self) -> list[str] | str:
        """The missing effects found, ``[]`` for none, or ``"inconclusive"``."""
        return self.data["verdict"]

    @property
    def reason(self) -> str:
        return self.data["reason"]

    @property
    def shrink_pct(self) -> dict[str, float]:
        """Held-out RMSE shrink per quantity, %, with the chosen explanation."""
        return self.data["shrink_pct"]

    def regions(self) -> pd.DataFrame:
        """The residual map, one row per region and quantity."""
        return pd.DataFrame(self.data["regions"])

    def to_dict(self) -> dict:
        return self.data

    @property
    def typed(self) -> report_types.PosteriorReport:
        """The report as typed objects (:class:`sim_gap.report_types.PosteriorReport`: the
        schema :func:`diagnose_gap` writes)."""
        from sim_gap.report_types import GapReport as Typed, PosteriorReport

        report = Typed.from_json(self.data)
        if not isinstance(report, PosteriorReport):
            raise ValueError(f"gap report of schema {report.schema}: diagnose_gap writes "
                             f"{PosteriorReport.schema}")
        return report

    def write(self, json_path: str | Path | None = None,
              html_path: str | Path | None = None) -> None:
        """Write the JSON and the self-contained HTML page (the campaign report's gap
        section on a page of its own) where asked."""
        from sim_gap.report import write_json

        if json_path:
            write_json(self.data, json_path)
        if html_path:
            from campaign_report.gap import write_gap_page  # matplotlib: only for a page

            write_gap_page(self.typed, html_path)


def _points(measured: object) -> tuple[pd.DataFrame, str]:
    from sim_gap.measured import combine, from_results_table, load_measured

    if isinstance(measured, (list, tuple)):
        if not measured:
            raise ValueError("no measured source given")
        parts = [_points(m) for m in measured]
        return combine([p for p, _ in parts]), " + ".join(label for _, label in parts)
    if isinstance(measured, Campaign):
        label = "campaign " + ", ".join(measured.names)
        return from_results_table(measured.results, source=label), label
    if isinstance(measured, pd.DataFrame):
        return from_results_table(measured, source="results table"), "results table"
    return load_measured(str(measured)), str(measured)


def _simulated(simulation: Simulated | WheelModel | str | Path,
               reference_model: str | Path | None) -> tuple[Simulated, str]:
    import terramechanics as tm
    from sim_gap.simulated import Simulated, load_simulated

    if isinstance(simulation, Simulated):
        return simulation, simulation.source
    if isinstance(simulation, tm.WheelModel):
        return Simulated(simulation), "<model>"
    return load_simulated(simulation, reference_model), str(simulation)


def diagnose_gap(measured: Campaign | pd.DataFrame | str | Path | list[Any] | tuple[Any, ...],
                 simulation: Simulated | WheelModel | str | Path, *,
                 effects: list[str] | None = None,
                 reference_model: str | Path | None = None, n_boot: int = 200, jobs: int = 1,
                 seed: int = 0, laws: dict[str, tuple[str, ...]] | None = None,
                 allow_wheel_mismatch: bool = False,
                 record_in: str | None = None) -> GapReport:
    """Where the measurements and the simulation differ, which missing effect explains it and
    how far (docs/gap-report.md).

    ``measured``: a :class:`Campaign`, a results table (docs/results.md), a database URL, a
    WPM CSV, a points CSV (docs/points-csv.md) or a CMU ``smooth_runs.csv``, or a list of
    them (several sources on one soil: the soil is fitted on all, each source keeps its
    wheel; docs/gap-report.md, "Several sources"); ``simulation``: a model TOML, a
    ``terramechanics.WheelModel`` or a simulator's WPM CSV (with ``reference_model``
    computing the effect corrections). The measured wheel must be the simulated one (radius,
    width, grousers), else ``sim_gap.wheel_check.WheelMismatchError``, unless
    ``allow_wheel_mismatch``; sources of several wheels are each simulated with their own.
    ``n_boot`` bootstrap replicates, ``jobs`` worker processes; ``laws``: effect -> the laws
    its candidates may use (default: every law of the family; a verdict must hold under each,
    docs/gap-report.md, "Laws"). ``record_in``: a database URL (the measured campaign's)
    where the report is recorded, for ``swtlab report`` to show.
    """
    from sim_gap.api import gap_report
    from sim_gap.diagnose import Settings

    points, measured_label = _points(measured)
    sim, sim_label = _simulated(simulation, reference_model)
    report = GapReport(gap_report(points, sim, measured_label, sim_label, effects,
                                  Settings(n_boot=n_boot, jobs=jobs, seed=seed, laws=laws),
                                  allow_wheel_mismatch))
    if record_in is not None:
        from traceability import open_database
        from traceability.store_gap import store_gap_report

        with open_database(record_in, create=False).begin() as session:
            store_gap_report(session, report.data)
    return report
