"""Measured points and a simulation -> the gap report (after the wheel check) -> files; what
``swtlab.diagnose_gap`` (and through it ``swtlab gap``) calls."""

from __future__ import annotations

from dataclasses import asdict, replace

import pandas as pd

from sim_gap.diagnose import Settings, diagnose
from sim_gap.report import build_report
from sim_gap.simulated import Simulated
from sim_gap.sources import describe_sources
from sim_gap.wheel_check import check_wheels


def several_wheels(points: pd.DataFrame) -> bool:
    """The points' sources have more than one wheel (``attrs['wheel']`` is None then)."""
    return points.attrs.get("wheel") is None and len(points.attrs.get("wheels", {})) > 1


def gap_report(points: pd.DataFrame, simulated: Simulated, measured_label: str,
               sim_label: str, effects: list[str] | None = None,
               settings: Settings | None = None, allow_wheel_mismatch: bool = False) -> dict:
    """The report dict of measured ``points`` against ``simulated``, after checking that they
    are one wheel (``allow_wheel_mismatch`` goes on and records the differences). With
    sources of several wheels, each source's rows are simulated with its own wheel (the
    model gives soil and laws; a WPM-CSV simulation, one wheel's curves, cannot; a points-CSV
    simulation is read at each point's own wheel and condition)."""
    settings = settings or Settings()
    if several_wheels(points):
        if simulated.wpm is not None:
            raise ValueError(f"{simulated.source}: a WPM-CSV simulation is one wheel's, the "
                             f"measured sources have {len(points.attrs['wheels'])} wheels; "
                             "simulate them with a model TOML")
        simulated, mismatches = replace(simulated, wheel_per_row=True), []
    elif simulated.table is not None:  # each point is looked up at its own wheel
        mismatches = []
    else:
        mismatches = check_wheels(points, simulated, allow_wheel_mismatch)
    diagnosis = diagnose(points, simulated, effects, settings)
    report = build_report(diagnosis, measured_label, sim_label, asdict(settings))
    measured = points.attrs.get("wheel")
    report["wheel"] = {"measured": None if measured is None else measured.geometry(),
                       "simulated": "each source's own wheel" if simulated.wheel_per_row
                       else simulated.wheel.geometry(),
                       "model_wheel": simulated.wheel.geometry(), "mismatches": mismatches}
    tested = sorted({e for h in diagnosis["hypotheses"] for e in h["effects"]})
    described = describe_sources(points, simulated, tested, settings.laws)
    report["sources"], report["effect_sources"] = described["sources"], described["effects"]
    return report
