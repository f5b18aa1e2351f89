"""Ding et al. (2011) single-wheel tests at 80 N: the published curves, soil and wheels.

Ding, Gao, Deng & Tao (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil", J.
Terramechanics 48(1):27-45: a smooth and a 10 mm lug wheel (R = 157.35 mm, b = 165
mm) on their planetary soil simulant. Points and soil as digitised by roverdevkit
(``terramechanics/data/ding2011_80n.csv`` names the source). ``errors`` gives the
median relative errors of DP and sinkage that the issue's accuracy targets use.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq

from terramechanics.model import WheelModel
from terramechanics.soil import SoilParams
from terramechanics.wheel import Wheel

DATA = Path(__file__).parent / "data" / "ding2011_80n.csv"
LOAD_N = 80.0
WHEELS = ("smooth", "lug10")

#: Ding et al. 2011, Table 2 (via roverdevkit data/soil_simulants.csv); K = 9.7-13.1 mm
SOIL = SoilParams(
    kc=15.6e3, kphi=2407.4e3, n=1.10, cohesion_pa=250.0, friction_angle_deg=31.9,
    shear_modulus_m=0.011, density_kg_m3=1605.0, name="ding2011_simulant",
    source="Ding, Gao, Deng & Tao 2011, J. Terramech. 48(1):27-45, Table 2: n = 1.10, "
           "kc = 15.6, kphi = 2407.4 (kN units), c = 0.25 kPa, phi = 31.9 deg, K = 9.7-13.1 "
           "mm (11 mm used), 1605 kg/m^3; as tabulated by roverdevkit data/soil_simulants.csv")


def load_points() -> pd.DataFrame:
    """The digitised points, with a ``wheel`` column (``smooth`` / ``lug10``)."""
    points = pd.read_csv(DATA, comment="#")
    points["wheel"] = np.where(points["grouser_height_m"] > 0, "lug10", "smooth")
    return points


def wheel(points: pd.DataFrame, name: str) -> Wheel:
    row = points[points["wheel"] == name].iloc[0]
    return Wheel(float(row["wheel_radius_m"]), float(row["wheel_width_m"]),
                 int(row["grouser_count"]), float(row["grouser_height_m"]))


def predict(model: WheelModel, points: pd.DataFrame, name: str) -> dict[str, np.ndarray]:
    """The model (its soil and effects) on wheel ``name`` at that wheel's slips."""
    rows = points[points["wheel"] == name]
    w = wheel(points, name)
    out = model.with_wheel(radius_m=w.radius_m, width_m=w.width_m, grouser_count=w.grouser_count,
                           grouser_height_m=w.grouser_height_m).curves(LOAD_N, rows["slip"])
    return {"slip": rows["slip"].to_numpy(), "dp_n": out["dp_n"], "sinkage_m": out["sinkage_m"],
            "dp_meas_n": rows["dp_n"].to_numpy(), "sinkage_meas_m": rows["sinkage_m"].to_numpy()}


def errors(model: WheelModel, points: pd.DataFrame, name: str) -> dict[str, float]:
    """Median |relative error| of DP and of sinkage over the wheel's points."""
    p = predict(model, points, name)
    return {"dp_median_rel": float(np.median(np.abs(p["dp_n"] / p["dp_meas_n"] - 1))),
            "sinkage_median_rel": float(np.median(np.abs(p["sinkage_m"]
                                                         / p["sinkage_meas_m"] - 1)))}


def static_stiffness_factor(model: WheelModel, points: pd.DataFrame) -> float:
    """The one factor on kc and kphi that makes the smooth wheel's zero-slip sinkage
    the measured one (uses that single point only)."""
    rows = points[(points["wheel"] == "smooth") & (points["slip"] == 0.0)]
    target = float(rows["sinkage_m"].iloc[0])

    def miss(factor: float) -> float:
        soil = model.soil
        scaled = model.with_soil(kc=soil.kc * factor, kphi=soil.kphi * factor)
        return float(predict(scaled, rows.assign(wheel="smooth"), "smooth")["sinkage_m"][0]
                     - target)

    return brentq(miss, 0.1, 100.0, xtol=1e-4)
