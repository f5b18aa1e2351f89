"""The stages chained as data in, data out (docs/python-api.md): raw files -> Campaign ->
Curves -> WPM CSV -> GapReport; the database and the report are adapters at the edge."""

from swtlab.pipeline.campaign import Campaign, Failure, ProcessedRun
from swtlab.pipeline.database import load, store
from swtlab.pipeline.process import process_campaign, process_file

__all__ = ["Campaign", "Failure", "ProcessedRun", "load", "process_campaign", "process_file",
           "store"]
