"""The campaign report of a :class:`Campaign` (docs/report.md)."""

from __future__ import annotations

from pathlib import Path

from swtlab.pipeline.campaign import Campaign


def report(campaign: Campaign, path: str | Path) -> dict[str, Path]:
    """Write the report page of each campaign ``campaign`` holds (one: ``path``; several:
    ``path`` with the campaign's name added); returns campaign -> page. A campaign from
    :func:`swtlab.process_campaign` is rendered from its results in memory, one loaded from
    a database from that database (with its stored fits, exports and gap reports)."""
    from campaign_report import from_results, page_paths, render_report, write_report

    if not campaign.names:
        raise ValueError("the campaign has no processed run to report")
    pages = page_paths(path, campaign.names)
    if campaign.source is not None:
        return {name: write_report(campaign.source, page, name) for name, page in pages.items()}
    results = [r.result for r in campaign.runs if r.result is not None]
    return {name: render_report(from_results(name, [r for r in results
                                                    if r.campaign == name]), page)
            for name, page in pages.items()}
