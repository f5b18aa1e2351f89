"""The campaign page's replicate section, right after the run table: the spread of runs of
one test condition beside their within-run uncertainty (``swtlab_base.domain.replicates``), or
the note that the campaign has no replicates."""

from __future__ import annotations

import math

from campaign_report.data import CampaignData
from campaign_report.html import Note, Section, Table
from campaign_report.style import QUANTITIES, Palette, Quantity
from swtlab_base.domain.replicates import NO_REPLICATES, replicate_spread
from swtlab_base.rounding import to_decimal_of, value_and_u


def _slip(value) -> str:
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else f"{100 * value:g}"


def replicates_section(data: CampaignData, palette: Palette) -> Section | None:
    """Replicate spread per condition and quantity; the no-replicates note otherwise."""
    del palette  # a table only
    if data.results is None or len(data.results) == 0:
        return None
    spread = replicate_spread(data.results)
    if spread.empty:
        return Section("replicates", "Repeatability", [Note(f"This campaign has {NO_REPLICATES}.",
                                                            warning=True)])
    cells = []
    for r in spread.itertuples():
        q = QUANTITIES.get(r.quantity, Quantity(r.quantity, "SI"))
        cells.append([r.mode, f"{r.load_set_n:g}", str(r.multipass), _slip(r.slip_setpoint),
                      q.axis_label, str(r.runs),
                      to_decimal_of(r.mean, max(r.replicate_sd, r.within_u), q.scale),
                      value_and_u(None, r.replicate_sd, q.scale)[1],
                      value_and_u(None, r.within_u, q.scale)[1], f"{r.ratio:.2f}"])
    larger = int((spread["larger"] == "replicates").sum())
    return Section("replicates", "Repeatability", [
        Note(f"Runs of one test condition (replicates): the spread of their means (sample "
             f"standard deviation) beside the within-run standard uncertainty (RMS of the runs' "
             f"budgets). The spread is the larger in {larger} of {len(spread)} rows; the fits "
             "weight each run by the larger of the two, and the mean is shown to its decimal "
             "(two significant digits; GUM 7.2.6)."),
        Table(["mode", "load (N)", "multipass", "slip set (%)", "quantity", "runs", "mean",
               "replicate sd", "within-run u", "sd / u"], cells,
              numeric=frozenset({1, 2, 3, 5, 6, 7, 8, 9}))])

