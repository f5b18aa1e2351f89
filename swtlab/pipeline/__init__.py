"""The stages chained as data in, data out (docs/python-api.md): raw files -> Campaign ->
Curves -> WPM CSV -> GapReport; the database and the report are adapters at the edge."""

from swtlab.pipeline.campaign import Campaign, Failure, ProcessedRun
from swtlab.pipeline.curves import Curves, export_wpm, fit_curves, read_wpm
from swtlab.pipeline.database import load, store
from swtlab.pipeline.gap import GapReport, diagnose_gap
from swtlab.pipeline.process import process_campaign, process_file
from swtlab.pipeline.report import report

__all__ = ["Campaign", "Curves", "Failure", "GapReport", "ProcessedRun", "diagnose_gap",
           "export_wpm", "fit_curves", "load", "process_campaign", "process_file", "read_wpm",
           "report", "store"]
