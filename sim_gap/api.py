"""Measured points and a simulation -> the gap report (after the wheel check) -> files; what
``swtlab.diagnose_gap`` (and through it ``swtlab gap``) calls."""

from __future__ import annotations

from dataclasses import asdict

import pandas as pd

from sim_gap.diagnose import Settings, diagnose
from sim_gap.report import build_report
from sim_gap.simulated import Simulated
from sim_gap.wheel_check import check_wheels


def gap_report(points: pd.DataFrame, simulated: Simulated, measured_label: str,
               sim_label: str, effects: list[str] | None = None,
               settings: Settings | None = None, allow_wheel_mismatch: bool = False) -> dict:
    """The report dict of measured ``points`` against ``simulated``, after checking that they
    are one wheel (``allow_wheel_mismatch`` goes on and records the differences)."""
    settings = settings or Settings()
    mismatches = check_wheels(points, simulated, allow_wheel_mismatch)
    report = build_report(diagnose(points, simulated, effects, settings), measured_label,
                          sim_label, asdict(settings))
    measured = points.attrs.get("wheel")
    report["wheel"] = {"measured": None if measured is None else measured.geometry(),
                       "simulated": simulated.wheel.geometry(), "mismatches": mismatches}
    return report

