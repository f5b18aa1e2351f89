"""Report section: the newest sim-to-real gap report recorded in the database.

Registered as an optional section (:mod:`campaign_report.extensions`): it appears when
``swtlab gap --measured <this database>`` has recorded a report (docs/gap-report.md): the
verdict and its reason, the residual heatmap, and the ranked explanations. Its data
(``data.extras["gap"]``): ``{"sim_source": ..., "report": ...}`` as ``gap_report`` stores them.
"""

from __future__ import annotations

from sqlalchemy import select
from sqlalchemy.orm import Session

from campaign_report.data import CampaignData
from campaign_report.extensions import Extension, register
from campaign_report.html import Image, Note, Section, Table
from campaign_report.style import Palette
from sim_gap.regions import heatmap_png
from traceability.models import GapReport

CANDIDATES_SHOWN = 8
NAME = "gap"


def _verdict(report: dict) -> str:
    verdict = report["verdict"]
    if isinstance(verdict, str):
        return verdict
    return ", ".join(verdict) if verdict else "no missing effect"


def gather_gap(session: Session, data: CampaignData) -> dict | None:
    """The newest gap report recorded in the database; None without one."""
    row = session.scalars(select(GapReport).order_by(GapReport.id.desc())).first()
    return None if row is None else {"sim_source": row.sim_source, "report": row.report}


def gap_section(data: CampaignData, palette: Palette) -> Section | None:
    """Verdict, heatmap and ranked candidates of the newest gap report; None without one."""
    found = data.extras.get(NAME)
    if found is None:
        return None
    report = found["report"]
    blocks: list = [Note(f"Simulation {found['sim_source']} against the measurements of this "
                         f"database: verdict \"{_verdict(report)}\". {report['reason']}",
                         warning=report["verdict"] == "inconclusive")]
    if report.get("separating_test"):
        blocks.append(Note(f"Test that would decide: {report['separating_test']['test']}"))
    blocks.append(Image("gap-heatmap", "residuals by slip band, load, multipass and gravity",
                        heatmap_png(report["regions"])))
    rows = [[str(i + 1), c["label"], f"{c['held_out_score']:.3g}", str(c["n_params"]),
             ", ".join(f"{k} = {v:.3g}" for k, v in c["parameters"].items())]
            for i, c in enumerate(report["candidates"][:CANDIDATES_SHOWN])]
    blocks.append(Table(["rank", "explanation", "held-out score", "parameters", "fitted values"],
                        rows, numeric=frozenset({0, 2, 3})))
    shrink = [[q, f"{report['held_out_rmse_before'][q]:.4g}",
               f"{report['held_out_rmse_after'][q]:.4g}", f"{report['shrink_pct'][q]:.1f}"]
              for q in report["held_out_rmse_before"]]
    blocks.append(Table(["quantity", "held-out RMSE before", "after", "shrink (%)"], shrink,
                        numeric=frozenset({1, 2, 3})))
    return Section("gap", "Sim-to-real gap", blocks)


register(Extension(NAME, gap_section, gather_gap))
