"""The stages chained as data in, data out (docs/python-api.md): raw files -> Campaign ->
Curves -> WPM CSV -> GapReport; the database and the report are adapters at the edge."""

from swtlab.pipeline.campaign import Campaign, Failure, ProcessedRun
from swtlab.pipeline.curves import (Curves, export_from_database, export_wpm, fit_curves,
                                    query_wpm, read_wpm)
from swtlab.pipeline.database import load, store
from swtlab.pipeline.gap import GapReport, diagnose_gap
from swtlab.pipeline.into import StoredBatch, process_into
from swtlab.pipeline.process import process_campaign, process_file
from swtlab.pipeline.report import report

__all__ = ["Campaign", "Curves", "Failure", "GapReport", "ProcessedRun", "StoredBatch",
           "diagnose_gap", "export_from_database", "export_wpm", "fit_curves", "load",
           "process_campaign", "process_file", "process_into", "query_wpm", "read_wpm",
           "report", "store"]
