"""swtlab's front door (docs/python-api.md): the domain model (:mod:`swtlab.domain`) and the
pipeline API (:mod:`swtlab.pipeline`)::

    import swtlab
    campaign = swtlab.process_campaign("sample_data/campaign")
    curves = swtlab.fit_curves(campaign)
    swtlab.export_wpm(curves, "wpm.csv")

The API names are loaded on first use, so that a stage importing :mod:`swtlab.domain` does
not import every other stage.
"""

from __future__ import annotations

import importlib

API = ("Campaign", "Curves", "GapReport", "process_campaign", "fit_curves", "export_wpm",
       "read_wpm", "diagnose_gap", "store", "load", "report")

__all__ = list(API)


def __getattr__(name: str):
    if name in API:
        return getattr(importlib.import_module("swtlab.pipeline"), name)
    raise AttributeError(f"module 'swtlab' has no attribute {name!r}")
