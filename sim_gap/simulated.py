"""The simulated side: the built-in model from a TOML file, or a WPM CSV or a points CSV
(tabulated, docs/points-csv.md) written by any simulator (DEM, FEM, SCM ...).

For a WPM CSV or a points CSV an effect (or a soil recalibration) is added as the correction
the built-in reference model computes for it at the same conditions:
``sim + (model(theta, effects) - model(theta_0))``. For a model TOML the prediction is the
model itself, ``model(theta, effects)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

import terramechanics as tm
from sim_gap.points_csv import WHEEL_KEY, is_points_csv, read_points_csv
from sim_gap.tabulated import at_points
from sim_gap.vocabulary import QUANTITIES
from wpm_export import WheelPerformanceModule


@dataclass
class Simulated:
    """``model``: the built-in model (the simulation itself for a TOML; the reference model
    that computes corrections for a WPM CSV); ``wpm``: the simulator's curves, if any;
    ``table``: its tabulated points (:mod:`sim_gap.tabulated`), if any; ``wheel_per_row``:
    each point is simulated with its own source's wheel (the points' wheel columns replace
    the model's wheel; several measured sources, docs/gap-report.md)."""

    model: tm.WheelModel
    wpm: WheelPerformanceModule | None = None
    source: str = "<model>"
    wheel_per_row: bool = False
    table: pd.DataFrame | None = None
    _base_cache: dict = field(default_factory=dict, repr=False)

    @property
    def radius_m(self) -> float:
        return self.model.wheel.radius_m

    @property
    def wheel(self):
        """The simulated wheel (a WPM CSV's, which the reference model was given)."""
        return self.model.wheel

    @property
    def external(self) -> bool:
        """Another simulator's output (WPM CSV or points CSV), corrected by the model."""
        return self.wpm is not None or self.table is not None

    def missing_effects(self) -> list[str]:
        """Effects of the vocabulary that the simulation does not have on (the candidates).
        Another simulator is taken to have none of them."""
        on = set() if self.external else set(self.model.effects)
        return [name for name in tm.EFFECTS if name not in on]

    def _wheel_groups(self, points: pd.DataFrame) -> list[tuple[dict, np.ndarray | None,
                                                                 tuple[np.ndarray, ...]]]:
        """Per wheel the points are simulated with: its fields for ``WheelModel.with_wheel``
        (none: the model's own), its rows (None: all) and their conditions."""
        conditions = _conditions(points)
        if not self.wheel_per_row:
            return [({}, None, conditions)]
        groups = []
        for key, idx in points.groupby(list(WHEEL_KEY), sort=False).indices.items():
            wheel = dict(zip(("radius_m", "width_m", "grouser_count", "grouser_height_m"), key))
            wheel["grouser_count"] = int(wheel["grouser_count"])
            groups.append((wheel, idx, tuple(c[idx] for c in conditions)))
        return groups

    @staticmethod
    def _model_curves(model: tm.WheelModel, groups: list, n_points: int
                      ) -> dict[str, np.ndarray]:
        """``model`` at the points of ``groups`` (:meth:`_wheel_groups`), ``n_points`` of them."""
        if groups[0][1] is None:
            return Simulated._curves_of(model, groups[0][2])
        out = {q: np.full(n_points, np.nan) for q in QUANTITIES}
        for wheel, idx, conditions in groups:
            part = Simulated._curves_of(model.with_wheel(**wheel), conditions)
            for q in QUANTITIES:
                out[q][idx] = part[q]
        return out

    @staticmethod
    def _curves_of(model: tm.WheelModel, conditions: tuple[np.ndarray, ...]
                   ) -> dict[str, np.ndarray]:
        c = model.curves(*conditions)
        return {q: c[q] for q in QUANTITIES}

    def _wpm_curves(self, points: pd.DataFrame) -> dict[str, np.ndarray]:
        out = {q: np.full(len(points), np.nan) for q in QUANTITIES}
        for mp, idx in points.groupby("multipass").indices.items():
            sub = points.iloc[idx]
            values = self.wpm.at_slip(sub["slip"].to_numpy(float),
                                      sub["wheel_load_n"].to_numpy(float),
                                      multipass=int(mp), allow_extrapolation=True)
            for q, v in values.items():
                if q in out:
                    out[q][idx] = v
        return out

    def _base(self, points: pd.DataFrame, groups: list) -> tuple[dict, dict]:
        cols = ["wheel_load_n", "slip", "multipass", "gravity_mps2"]
        key = points[cols + [c for c in WHEEL_KEY if c in points]].to_numpy(float).tobytes()
        if key not in self._base_cache:
            self._base_cache.clear()
            model0 = self._model_curves(self.model, groups, len(points))
            sim0 = (self._wpm_curves(points) if self.wpm is not None else
                    at_points(self.table, points, self.source) if self.table is not None
                    else model0)
            self._base_cache[key] = (model0, sim0)
        return self._base_cache[key]

    def predict(self, points: pd.DataFrame, values: dict[str, float] | None = None
                ) -> dict[str, np.ndarray]:
        """Each quantity at every point with the dotted-name ``values`` changed (naming
        ``effects.<name>.<param>`` switches that effect on)."""
        return self.predictor(points)(values or {})

    def predictor(self, points: pd.DataFrame) -> Callable[[dict], dict[str, np.ndarray]]:
        """:meth:`predict` at fixed ``points``, their conditions and wheels read once: a fit
        calls it hundreds of times, and each column read from the points costs pandas a deep
        copy of their ``attrs`` (the sources' wheels)."""
        groups, n = self._wheel_groups(points), len(points)

        def model_at(values: dict) -> dict[str, np.ndarray]:
            return self._model_curves(self.model.with_parameters(values), groups, n)

        if not self.external:
            return lambda values: model_at(values or {})
        model0, sim0 = self._base(points, groups)

        def corrected(values: dict) -> dict[str, np.ndarray]:
            if not values:
                return dict(sim0)
            changed = model_at(values)
            return {q: sim0[q] + changed[q] - model0[q] for q in QUANTITIES}

        return corrected


def _conditions(points: pd.DataFrame) -> tuple[np.ndarray, ...]:
    """Load, slip, multipass and gravity of each point (``WheelModel.curves``'s inputs)."""
    return tuple(points[c].to_numpy(float)
                 for c in ("wheel_load_n", "slip", "multipass", "gravity_mps2"))


def load_simulated(source: str | Path, reference: str | Path | None = None) -> Simulated:
    """A model TOML, or a WPM CSV or points CSV with ``reference`` (a model TOML; default:
    the shipped ``bb2_sand`` soil with every effect off) computing the corrections. The
    reference model takes the WPM CSV's wheel (its geometry header is required: one wheel);
    for a points CSV each measured point's own wheel, which must be one of the table's."""
    path = Path(source)
    if path.suffix.lower() == ".toml":
        return Simulated(tm.load_model(path), source=str(path))
    if reference is not None:
        ref = tm.load_model(reference)
    else:
        ref = tm.shipped_model("bb2_sand")
        ref = ref.with_effects(**{name: False for name in tm.EFFECTS})
    if path.exists() and is_points_csv(path):
        table = read_points_csv(path, uncertainty=False)
        first = table.iloc[0]
        ref = ref.with_wheel(**{c[6:] if c.startswith("wheel_") else c: first[c]
                                for c in WHEEL_KEY})
        return Simulated(ref, source=str(path), wheel_per_row=True, table=table)
    wpm = WheelPerformanceModule.load(path)
    names = sorted({wheel for _, wheel, _ in wpm.sets()})
    if len(names) != 1:
        raise ValueError(f"{path}: curves of {len(names)} wheels {names}; a simulation is "
                         "one wheel's")
    wheel = wpm.wheel(names[0], needed_for="the gap diagnosis")
    return Simulated(ref.with_wheel(**{k: getattr(wheel, k) for k in (
        "name", "radius_m", "width_m", "grouser_count", "grouser_height_m")}), wpm,
                     source=str(path))
