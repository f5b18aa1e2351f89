"""The run-results table: one row per run, the schema every stage reads and writes
(docs/results.md). Built by ``run_results.results_table`` (no database) and
``traceability.queries.latest_results`` (a database); both pass :func:`check_results`.

Set load and measured load are apart: ``load_set_n`` is the set point (the group key of the
curves), ``wheel_load_n_mean`` the load measured over the stable window. Every quantity
``q`` has ``q_mean``, ``q_std`` (spread of the samples) and ``q_se`` (standard error of the
mean, corrected for autocorrelation), and its uncertainty budget (:data:`BUDGET_COLUMNS`):
``q_u`` (combined standard uncertainty), ``q_u95`` (95 % expanded), ``q_k``, ``q_dof``,
``q_correction`` (re-zeroing added to the mean) and ``q_u_<term>``.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np
import pandas as pd

from swtlab_base.domain.condition import MODES
from swtlab_base.domain.wheel import Wheel

STATS = ("mean", "std", "se")
STATUSES = ("ok", "flagged", "no_stable_phase")

#: identity, condition and status columns: name -> (unit, meaning); every table has them
COLUMNS: dict[str, tuple[str, str]] = {
    "campaign": ("", "campaign name (swt.run.campaign)"),
    "run_id": ("", "run name (swt.run.run_id)"),
    "wheel": ("", "wheel name"),
    "wheel_radius_m": ("m", "wheel rim radius without grousers"),
    "wheel_width_m": ("m", "wheel width"),
    "wheel_grouser_count": ("", "number of grousers"),
    "wheel_grouser_height_m": ("m", "grouser height"),
    "wheel_stiffness_n_per_mm": ("N/mm", "radial wheel stiffness, empty for a rigid wheel"),
    "soil": ("", "soil name"),
    "mode": ("", f"test mode, one of {', '.join(MODES)}"),
    "multipass": ("", "previous passes over the soil (0 = virgin soil)"),
    "load_set_n": ("N", "set wheel load (the measured one is wheel_load_n_mean)"),
    "slip_setpoint": ("1", "set slip (speed control), empty otherwise"),
    "velocity_set_mps": ("m/s", "set travel velocity"),
    "gravity_mps2": ("m/s^2", "gravity of the test"),
    "steer_deg": ("deg", "set steering angle, empty unless steered"),
    "status": ("", f"one of {', '.join(STATUSES)}"),
    "flags": ("", "reasons of a flagged run, '; '-separated"),
}

#: the quantities of a run (``<q>_mean``, ``<q>_std``, ``<q>_se``): name -> unit
QUANTITIES: dict[str, str] = {
    "slip": "1", "travel_velocity_mps": "m/s", "wheel_omega_radps": "rad/s",
    "wheel_load_n": "N", "dp_n": "N", "torque_nm": "N*m", "thrust_n": "N",
    "resistance_n": "N", "sinkage_m": "m", "hub_height_m": "m", "side_force_n": "N",
    "slip_angle_deg": "deg", "image_slip": "1",
}

#: terms of a quantity's uncertainty budget (``run_results.uncertainty_budget``)
UNCERTAINTY_TERMS = ("statistical", "zero_drift", "calibration", "quantisation",
                     "phase_sampling", "clock", "timing")
#: results-table columns of a quantity's budget, ``<q>_<name>`` (docs/results.md)
BUDGET_COLUMNS = ("u", "u95", "k", "dof", "correction", *(f"u_{t}" for t in UNCERTAINTY_TERMS))


#: results-table column: what the run's budgets could not measure (docs/results.md)
NOT_MEASURED = "not_measured"


def not_measured_text(items: Iterable[str]) -> str:
    """The ``not_measured`` column of a run: its budgets' ``not_measured`` items, each once,
    sorted, ``'; '``-separated."""
    return "; ".join(sorted(set(items)))


def not_measured_heads(text: object) -> list[str]:
    """The items of a ``not_measured`` cell without their explanations (the text before
    ``' ('``), for a summary."""
    if not isinstance(text, str) or not text:
        return []
    return sorted({item.split(" (")[0] for item in text.split("; ")})


def budget_columns(quantity: str, budget: dict) -> dict:
    """A budget (``QuantityBudget.to_dict()``, or as stored) as results-table columns."""
    return {f"{quantity}_{name}": budget.get(name) for name in BUDGET_COLUMNS}


#: wheel columns of the table -> fields of :class:`Wheel`
WHEEL_COLUMNS = {"wheel_radius_m": "radius_m", "wheel_width_m": "width_m",
                 "wheel_grouser_count": "grouser_count",
                 "wheel_grouser_height_m": "grouser_height_m",
                 "wheel_stiffness_n_per_mm": "stiffness_n_per_mm"}


def wheel_columns(wheel: Wheel) -> dict:
    """The table's wheel columns for ``wheel``."""
    return {"wheel": wheel.name, **{c: getattr(wheel, f) for c, f in WHEEL_COLUMNS.items()}}


def wheels_of(table: pd.DataFrame) -> dict[str, Wheel]:
    """Wheel name -> :class:`Wheel` from the table's wheel columns; a name with two
    geometries is an error (the curves of a name are one wheel's)."""
    out: dict[str, Wheel] = {}
    cols = ["wheel", *WHEEL_COLUMNS]
    for row in table[cols].drop_duplicates().itertuples(index=False):
        values = dict(zip(cols, row))
        stiffness = values["wheel_stiffness_n_per_mm"]
        wheel = Wheel(name=str(values["wheel"]), radius_m=float(values["wheel_radius_m"]),
                      width_m=float(values["wheel_width_m"]),
                      grouser_count=int(values["wheel_grouser_count"]),
                      grouser_height_m=float(values["wheel_grouser_height_m"]),
                      stiffness_n_per_mm=None if pd.isna(stiffness) else float(stiffness))
        if wheel.name in out and out[wheel.name] != wheel:
            raise ValueError(f"wheel {wheel.name!r} has two geometries in the results "
                             f"({out[wheel.name].geometry()} and {wheel.geometry()}); give "
                             "each wheel its own name")
        out[wheel.name] = wheel
    return out


def check_results(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` if it follows the schema (every column of :data:`COLUMNS`; statuses, modes,
    loads, gravity, multipass and standard errors valid), else a one-line ``ValueError``."""
    missing = [c for c in COLUMNS if c not in table]
    if missing:
        raise ValueError(f"results table lacks column(s) {missing} (docs/results.md)")
    if table.empty:
        return table
    problems = []
    for col, allowed in (("status", STATUSES), ("mode", MODES)):
        bad = sorted(set(table[col]) - set(allowed))
        if bad:
            problems.append(f"{col} {bad} not in {allowed}")
    for col in ("load_set_n", "gravity_mps2", "wheel_radius_m", "wheel_width_m"):
        values = table[col].astype(float)
        if not (np.isfinite(values) & (values > 0)).all():
            problems.append(f"{col} must be > 0 in every row")
    if (table["multipass"].astype(int) < 0).any():
        problems.append("multipass must be >= 0")
    for col in table.columns:
        if col.endswith("_se") and (table[col].astype(float) < 0).any():
            problems.append(f"{col} has a negative standard error")
    if problems:
        raise ValueError("results table: " + "; ".join(problems))
    return table
