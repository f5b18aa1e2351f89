"""Ding et al. (2011) single-wheel tests at 80 N: the published curves, soil and wheels.

Ding, Gao, Deng, Nagatani & Yoshida (2011) "Experimental study and analysis on driving wheels'
performance for planetary exploration rovers moving in deformable soil", J.
Terramechanics 48(1):27-45: a smooth and a 10 mm lug wheel (R = 157.35 mm, b = 165
mm) on their planetary soil simulant. Points and soil as digitised by roverdevkit
(``terramechanics/data/ding2011_80n.csv`` names the source). ``errors`` gives the
median relative errors of DP and sinkage that the issue's accuracy targets use (and of
the torque, which no fit here uses). ``fit_slip_soil`` fits the slip-dependent shear
modulus of Ding et al. 2015 (``terramechanics/slip_soil_ding2015.py``) and the
slip-sinkage exponent on one wheel, so that the other can be held out.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from scipy.optimize import brentq, least_squares

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
    source="Ding, Gao, Deng, Nagatani & Yoshida 2011, J. Terramech. 48(1):27-45, Table 2: "
           "n = 1.10, kc = 15.6, kphi = 2407.4 (kN units), c = 0.25 kPa, phi = 31.9 deg, "
           "K = 9.7-13.1 mm (11 mm used), 1605 kg/m^3; as tabulated by roverdevkit "
           "data/soil_simulants.csv")


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
            "torque_nm": out["torque_nm"], "dp_meas_n": rows["dp_n"].to_numpy(),
            "sinkage_meas_m": rows["sinkage_m"].to_numpy(),
            "torque_meas_nm": rows["torque_nm"].to_numpy()}


def errors(model: WheelModel, points: pd.DataFrame, name: str) -> dict[str, float]:
    """Median |relative error| of DP and of sinkage over the wheel's points, and of the
    torque over those with a torque reported (> 0; the towed s = 0 point has none)."""
    p = predict(model, points, name)
    driven = p["torque_meas_nm"] > 0
    return {"dp_median_rel": float(np.median(np.abs(p["dp_n"] / p["dp_meas_n"] - 1))),
            "sinkage_median_rel": float(np.median(np.abs(p["sinkage_m"]
                                                         / p["sinkage_meas_m"] - 1))),
            "torque_median_rel": float(np.median(np.abs(p["torque_nm"][driven]
                                                        / p["torque_meas_nm"][driven] - 1)))}


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


#: start, lower and upper bound of each parameter :func:`fit_slip_soil` may free
SLIP_SOIL_PARAMS = {"K0": (0.004, 1e-4, 0.05), "K1": (0.02, 0.0, 0.1), "n1": (0.9, 0.0, 2.0),
                    "c4": (0.2, 0.0, 1.0)}


def fit_slip_soil(model: WheelModel, points: pd.DataFrame, name: str,
                  free: tuple[str, ...] = ("K0", "K1", "n1")) -> WheelModel:
    """``model`` with the ``free`` ones of K0, K1 of ``K = K0 + K1 s`` and c4 of
    ``theta_2 = -(c3 + c4 s) theta_1`` (Ding et al. 2015) and n1 of the ``slip_sinkage``
    law ding2011 fitted by least squares to wheel ``name``'s relative DP and sinkage
    errors (K1, c4 not free: 0, constant; n1 not free: no slip-sinkage). Raises if a
    value ends on a bound: then it is no fit."""
    start, lower, upper = (np.array([SLIP_SOIL_PARAMS[p][i] for p in free]) for i in range(3))

    def make(x) -> WheelModel:
        value = dict(zip(free, x))
        fitted = model.with_soil(shear_modulus_m=value["K0"],
                                 shear_modulus_slip_m=value.get("K1", 0.0),
                                 c4=value.get("c4", 0.0))
        if "n1" in value:
            fitted = fitted.with_effects(slip_sinkage={"law": "ding2011", "n1": value["n1"]})
        return fitted

    def residuals(x) -> np.ndarray:
        p = predict(make(x), points, name)
        return np.concatenate([p["dp_n"] / p["dp_meas_n"] - 1,
                               p["sinkage_m"] / p["sinkage_meas_m"] - 1])

    fit = least_squares(residuals, start, bounds=(lower, upper), diff_step=1e-3)
    on_bound = [f"{p} = {v:.3g}" for p, v, lo, hi in zip(free, fit.x, lower, upper)
                if np.isclose(v, lo, rtol=1e-3, atol=1e-6) or np.isclose(v, hi, rtol=1e-3)]
    if on_bound:
        raise RuntimeError(f"fit on {name} ends on a bound ({', '.join(on_bound)})")
    return make(fit.x)
