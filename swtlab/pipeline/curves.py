"""Results -> performance curves -> WPM CSV, and back: ``fit_curves``, ``export_wpm``,
``export_from_database`` (what ``swtlab export`` does), ``read_wpm``; ``record_in=DB_URL``
records the fits and the exports in the database the results came from (docs/fitting.md)."""

from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pandas as pd

from swtlab_base.domain import Wheel, check_results, wheels_of
from swtlab.pipeline.campaign import Campaign

if TYPE_CHECKING:
    from sqlalchemy.orm import Session

    from fitting import CurveFit
    from traceability.models import CurveFit as StoredFit
    from wpm_export import WheelPerformanceModule


@dataclass
class Curves:
    """Fitted curves (``fitting.CurveFit``, one per (wheel, soil, multipass, set load) and
    quantity), the fitted ``table`` (``fitting.from_run_results`` of the results), each
    curve's ``wheels`` (name -> geometry), ``inputs_sha256`` of the table, the groups
    ``not_fitted`` (too few points) and the ``options`` (degree, statuses)."""

    fits: list[CurveFit]
    table: pd.DataFrame
    wheels: dict[str, Wheel]
    inputs_sha256: str
    not_fitted: list[str] = field(default_factory=list)
    options: dict = field(default_factory=dict)

    @property
    def flagged(self) -> list[CurveFit]:
        """The fits whose polynomial oscillates between its points."""
        return [f for f in self.fits if f.oscillates]

    def get(self, quantity: str, load_n: float, multipass: int = 0, wheel: str | None = None,
            soil: str | None = None) -> CurveFit:
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
               statuses: tuple[str, ...] = ("ok",), *, record_in: str | None = None) -> Curves:
    """Fit every quantity of every (wheel, soil, multipass, set load) group of the runs whose
    status is in ``statuses`` (docs/fitting.md); ``degree`` 3-7, ``"loo"`` or ``"aicc"``.
    Groups with too few slips are left out and listed in ``not_fitted``; no usable run at all
    is a ``fitting.FittingError``. ``record_in``: the database URL the results were loaded
    from (:func:`swtlab.load`), where the fits are stored linked to their run results."""
    from fitting import FittingError, TooFewPointsError, fit_results, from_run_results
    from wpm_export import inputs_sha256

    results = (campaign_or_results.results if isinstance(campaign_or_results, Campaign)
               else check_results(campaign_or_results))
    table = from_run_results(results, statuses=statuses) if len(results) else results
    if table.empty:
        raise FittingError(f"no usable run results (none with status in {list(statuses)}; "
                           "process the campaign first)")
    too_few: list[TooFewPointsError] = []
    fits = fit_results(table, degree=degree, too_few=too_few)
    curves = Curves(fits=fits, table=table, wheels=wheels_of(table),
                    inputs_sha256=inputs_sha256(table), not_fitted=[str(e) for e in too_few],
                    options={"degree": degree, "statuses": list(statuses)})
    if record_in is not None:
        _record(record_in, lambda session: _store_fits(session, curves))
    return curves


def _record(db_url: str, work: Callable[[Session], object]) -> None:
    """``work(session)`` in one transaction on the existing database at ``db_url``."""
    from traceability import open_database
    from traceability.database import in_transaction

    in_transaction(open_database(db_url, create=False), work)


def _store_fits(session: Session, curves: Curves) -> list[StoredFit]:
    from traceability.store_fits import store_fits

    if "result_id" not in curves.table:
        raise ValueError("the curves were not fitted from results loaded from a database: "
                         "nothing to record them against")
    return store_fits(session, curves.table, curves.fits, curves.options)


def export_wpm(curves: Curves, path: str | Path, created: str | None = None, *,
               record_in: str | None = None) -> str:
    """Write ``curves`` as a WPM CSV (docs/wpm-csv.md, with each wheel's geometry) to
    ``path``, atomically; returns the file's sha256. ``record_in``: the database URL the
    curves' results came from, where the export is recorded with its sha256 and its fits
    once the file is in place."""
    from traceability.provenance import swtlab_version
    from traceability.store_fits import store_export
    from wpm_export import write_wpm_csv
    from wpm_export.schema import FORMAT

    file_hash = write_wpm_csv(curves.fits, path, curves.inputs_sha256, swtlab_version(),
                              created, curves.wheels)
    if record_in is not None:
        _record(record_in, lambda session: store_export(
            session, Path(path), file_hash, curves.inputs_sha256, FORMAT,
            _store_fits(session, curves), curves.options))
    return file_hash


def export_from_database(db_url: str, path: str | Path, *, degree: int | str = "loo",
                         statuses: tuple[str, ...] = ("ok",)) -> tuple[Curves, str]:
    """Fit the newest results in the database at ``db_url`` (:func:`fit_curves`), write the
    WPM CSV to ``path`` and record the fits and the export there (``swtlab export``);
    returns the curves and the file's sha256."""
    from swtlab.pipeline.database import load

    curves = fit_curves(load(db_url), degree=degree, statuses=statuses)
    return curves, export_wpm(curves, path, record_in=db_url)


def read_wpm(path: str | Path) -> WheelPerformanceModule:
    """The Wheel Performance Module (``wpm_export.WheelPerformanceModule``) of a WPM CSV."""
    from wpm_export import WheelPerformanceModule

    return WheelPerformanceModule.load(path)


def query_wpm(path: str | Path, load_n: float, *, quantity: str | None = None,
              target: float | None = None, slip: float | None = None, soil: str | None = None,
              wheel: str | None = None, multipass: int | None = None,
              allow_extrapolation: bool = False) -> dict:
    """The Wheel Performance Module's answer from the WPM CSV at ``path`` at ``load_n`` (N),
    as ``swtlab wpm query`` gives it (docs/wpm-csv.md): the smallest slip giving ``target``
    of ``quantity`` (``WheelPerformanceModule.answer_for``), or every quantity at ``slip``
    (``answer_at``), with the file and the curve set chosen (``soil``, ``wheel``,
    ``multipass``: needed only where the file holds several)."""
    asked: float | tuple[str, float]
    if slip is not None and quantity is None and target is None:
        asked = slip
    elif slip is None and quantity is not None and target is not None:
        asked = (quantity, target)
    else:
        raise ValueError("give either quantity and target, or slip")
    wpm = read_wpm(path)
    soil, wheel, multipass = wpm.select(soil=soil, wheel=wheel, multipass=multipass)
    chosen: dict[str, Any] = {"soil": soil, "wheel": wheel, "multipass": multipass,
                              "allow_extrapolation": allow_extrapolation}
    answer = (wpm.answer_for(*asked, load_n, **chosen) if isinstance(asked, tuple)
              else wpm.answer_at(asked, load_n, **chosen))
    return {"file": str(path), "soil": soil, "wheel": wheel, "multipass": multipass,
            "load_n": load_n, **answer}
