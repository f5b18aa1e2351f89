"""swtlab's front door (docs/python-api.md): the pipeline API (:mod:`swtlab.pipeline`)::

    import swtlab
    campaign = swtlab.process_campaign("sample_data/campaign")
    curves = swtlab.fit_curves(campaign)
    swtlab.export_wpm(curves, "wpm.csv")

The top layer: it chains the stages, and no stage imports it (the domain model every stage
shares is :mod:`swtlab_base.domain`).
"""

from swtlab.pipeline import (Campaign, Curves, GapReport, StoredBatch, diagnose_gap,
                             export_from_database, export_wpm, fit_curves, load,
                             process_campaign, process_into, query_wpm, read_wpm, report, store)

__all__ = ["Campaign", "Curves", "GapReport", "StoredBatch", "diagnose_gap",
           "export_from_database", "export_wpm", "fit_curves", "load", "process_campaign",
           "process_into", "query_wpm", "read_wpm", "report", "store"]
