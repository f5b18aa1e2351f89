"""Campaign report: one self-contained HTML page per campaign, from the database or from
in-memory pipeline results; no raw file is read.

``write_report(db_url, path)`` writes the page of the database's campaign (``campaign=`` to
pick one of several), ``write_reports(db_url, path)`` one page per campaign;
``render_report(from_results(name, results), path)`` the page of ``process_run`` results
without a database. The page: the run table with each quantity's standard uncertainty, the
replicate spread per condition (or that there are none), each run's time series with its
stable window (from the traces stored at processing), the performance curves with their
points, the load-interpolation check, the exported WPM curves, and the sections registered
in :mod:`campaign_report.extensions` that have data. See docs/report.md.
"""

from campaign_report import flow, gap, image_slip  # noqa: F401 - their sections
from campaign_report.data import CampaignData, from_results, gather
from campaign_report.render import page_paths, render_report, write_report, write_reports

__all__ = ["CampaignData", "from_results", "gather", "page_paths", "render_report",
           "write_report", "write_reports"]
