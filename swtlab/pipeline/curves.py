"""Results -> performance curves -> WPM CSV, and back: ``fit_curves``, ``export_wpm``,
``read_wpm``."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from swtlab_base.domain import Wheel, check_results, wheels_of
from swtlab.pipeline.campaign import Campaign


@dataclass
class Curves:
    """Fitted curves (``fitting.CurveFit``, one per (wheel, soil, multipass, set load) and
    quantity), the fitted ``table`` (``fitting.from_run_results`` of the results), each
    curve's ``wheels`` (name -> geometry), ``inputs_sha256`` of the table, the groups
    ``not_fitted`` (too few points) and the ``options`` (degree, statuses)."""

    fits: list
    table: pd.DataFrame
    wheels: dict[str, Wheel]
    inputs_sha256: str
    not_fitted: list[str] = field(default_factory=list)
    options: dict = field(default_factory=dict)

    @property
    def flagged(self) -> list:
        """The fits whose polynomial oscillates between its points."""
        return [f for f in self.fits if f.oscillates]

    def get(self, quantity: str, load_n: float, multipass: int = 0, wheel: str | None = None,
            soil: str | None = None):
        """The one fit of ``quantity`` at set load ``load_n`` and ``multipass`` (wheel and soil
        needed only when the curves hold several)."""
        match = [f for f in self.fits if f.quantity == quantity and f.load_n == load_n
                 and f.multipass == multipass and wheel in (None, f.wheel)
                 and soil in (None, f.soil)]
        if len(match) != 1:
            raise KeyError(f"{len(match)} curves of {quantity} at {load_n:g} N, multipass "
                           f"{multipass} (wheel {wheel}, soil {soil})")
        return match[0]


def fit_curves(campaign_or_results: Campaign | pd.DataFrame, degree: int | str = "loo",
               statuses: tuple[str, ...] = ("ok",)) -> Curves:
    """Fit every quantity of every (wheel, soil, multipass, set load) group of the runs whose
    status is in ``statuses`` (docs/fitting.md); ``degree`` 3-7, ``"loo"`` or ``"aicc"``.
    Groups with too few slips are left out and listed in ``not_fitted``; no usable run at all
    is a ``fitting.FittingError``."""
    from fitting import FittingError, fit_results, from_run_results
    from wpm_export import inputs_sha256

    results = (campaign_or_results.results if isinstance(campaign_or_results, Campaign)
               else check_results(campaign_or_results))
    table = from_run_results(results, statuses=statuses) if len(results) else results
    if table.empty:
        raise FittingError(f"no usable run results (none with status in {list(statuses)}; "
                           "process the campaign first)")
    too_few: list = []
    fits = fit_results(table, degree=degree, too_few=too_few)
    return Curves(fits=fits, table=table, wheels=wheels_of(table),
                  inputs_sha256=inputs_sha256(table), not_fitted=[str(e) for e in too_few],
                  options={"degree": degree, "statuses": list(statuses)})


def export_wpm(curves: Curves, path: str | Path, created: str | None = None) -> str:
    """Write ``curves`` as a WPM CSV (docs/wpm-csv.md, with each wheel's geometry) to
    ``path``, atomically; returns the file's sha256."""
    from traceability.provenance import swtlab_version
    from wpm_export import write_wpm_csv

    return write_wpm_csv(curves.fits, path, curves.inputs_sha256, swtlab_version(), created,
                         curves.wheels)


def read_wpm(path: str | Path):
    """The Wheel Performance Module (``wpm_export.WheelPerformanceModule``) of a WPM CSV."""
    from wpm_export import WheelPerformanceModule

    return WheelPerformanceModule.load(path)
