"""The campaign report of a :class:`Campaign` (docs/report.md)."""

from __future__ import annotations

import tempfile
from pathlib import Path

from swtlab.pipeline.campaign import Campaign


def report(campaign: Campaign, path: str | Path, quiet: bool = True) -> dict[str, Path]:
    """Write the report page of each campaign ``campaign`` holds (one: ``path``; several:
    ``path`` with the campaign's name added); returns campaign -> page. A campaign loaded
    from a database is rendered from it; one from :func:`swtlab.process_campaign` is stored
    in a temporary SQLite database first (the renderer reads a database)."""
    from campaign_report import write_report, write_reports
    from swtlab.pipeline.database import store

    if not campaign.names:
        raise ValueError("the campaign has no processed run to report")

    def render(url: str) -> dict[str, Path]:
        if len(campaign.names) == 1:
            name = campaign.names[0]
            return {name: write_report(url, path, quiet, name)}
        return write_reports(url, path, quiet)

    if campaign.source is not None:
        return render(campaign.source)
    with tempfile.TemporaryDirectory(prefix="swtlab-report-") as folder:
        url = f"sqlite:///{Path(folder) / 'campaign.sqlite'}"
        store(campaign, url)
        return render(url)
