"""Campaign report: one self-contained HTML page per campaign, from the database.

``write_report(db_url, path)`` writes the page of the database's campaign (``campaign=`` to
pick one of several), ``write_reports(db_url, path)`` one page per campaign. The page: the
run table, each run's time series with its stable window, the performance curves with their
points, the load-interpolation check, the exported WPM curves, and the sections registered
in :mod:`campaign_report.extensions` that have data. See docs/report.md.
"""

from campaign_report import flow, gap, image_slip  # noqa: F401 - register their sections
from campaign_report.render import page_paths, write_report, write_reports

__all__ = ["page_paths", "write_report", "write_reports"]
