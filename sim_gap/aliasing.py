"""Effects that a campaign cannot tell apart by its design: on one grousered wheel, the
soil's slip-sinkage and the lugs' slip-sinkage.

Lugged wheels sink more as slip rises than smooth ones on the same soil, because the lugs
dig and carry soil backwards (Ding, Gao, Deng, Nagatani & Yoshida 2011, J. Terramech.
48(1):27-45: at 80 N the 10 mm lug wheel sank 6 times deeper at s = 0.6 than at rest, the
smooth wheel 3.5 times). With a single grouser geometry the two are confounded in the
design, as two factors that never vary apart are aliased in a fractional factorial (Box,
Hunter & Hunter 2005, Statistics for Experimenters, ch. 6): whatever shape the data has,
no fit can say whether the soil or the lugs made it, and which law happens to fit better
is a statement about the laws, not the wheel. Hence a call that names ``slip_sinkage``,
or ``grousers`` under a law whose fitted lug slip-sinkage is not negligible, is not
confident on such a campaign; a smooth (or other-lug) wheel on the same soil separates
them (the several-source diagnosis, :mod:`sim_gap.sources`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

import terramechanics as tm
from sim_gap.points_csv import WHEEL_KEY
from terramechanics.effects.slip_sinkage_lyasko2010 import slip_sinkage_coefficient

#: the run that lifts the aliasing (the gap report's "test that would decide")
SEPARATING_RUN = ("a smooth wheel (or one with other lugs) run on the same soil at the same "
                  "slips, diagnosed together with this wheel (several --measured sources)")
#: a lug slip-sinkage that changes the sinkage exponent by less than this at the
#: campaign's largest slip is negligible (a 1 % pressure change at z/b = 0.4)
NEGLIGIBLE_EXPONENT_CHANGE = 0.01
#: a lug slip-sinkage that multiplies the sinkage by less than 1 + this there is negligible
NEGLIGIBLE_SINKAGE_CHANGE = 0.01


def grouser_geometries(points: pd.DataFrame, wheel) -> set[tuple[int, float]]:
    """The (grouser count, grouser height m) of the measured wheels: per row where the
    points carry their wheel, else the simulation's one wheel."""
    if all(k in points for k in WHEEL_KEY):
        return {(int(c), float(h)) for c, h in
                zip(points["grouser_count"], points["grouser_height_m"])}
    return {(int(wheel.grouser_count), float(wheel.grouser_height_m))}


def lug_slip_sinkage_text(law: str, values: dict[str, float], wheel, max_slip: float) -> str | None:
    """What the lug slip-sinkage of ``law`` of grousers, with the fitted ``values``, does at
    ``max_slip``, in words; None for a law without that term or where it is negligible.
    Ding et al.'s lugs raise the sinkage exponent by ``kappa h/r s``; a ``~slip`` law
    multiplies the sinkage by Lyasko's ``K_s^(g h/r)`` (terramechanics.effects.lug_slip_sinkage)."""
    effect = tm.law_class("grousers", law)()
    height_ratio = wheel.grouser_height_m / wheel.radius_m
    if hasattr(effect, "lug_sinkage_gain"):
        gain = values.get("effects.grousers.lug_sinkage_gain", effect.lug_sinkage_gain)
        change = gain * height_ratio * max_slip
        if change >= NEGLIGIBLE_EXPONENT_CHANGE:
            return f"the exponent grows by {change:.2f} at slip {max_slip:.2f}"
    if hasattr(effect, "lug_slip_gain"):
        gain = values.get("effects.grousers.lug_slip_gain", effect.lug_slip_gain)
        factor = float(slip_sinkage_coefficient(max_slip) ** (gain * height_ratio))
        if factor - 1 >= NEGLIGIBLE_SINKAGE_CHANGE:
            return f"the sinkage grows {factor:.2f} times at slip {max_slip:.2f}"
    return None


def aliasing_problem(points: pd.DataFrame, wheel, effects: list[str],
                     laws: dict[str, str], values: dict[str, float]) -> str | None:
    """Why a call of ``effects`` (with their ``laws`` and fitted ``values``) on ``points``
    cannot be confident, or None when nothing in it is aliased by the design."""
    geometries = grouser_geometries(points, wheel)
    if len(geometries) != 1:
        return None
    count, height_m = next(iter(geometries))
    if count == 0 or height_m <= 0:
        return None
    where = (f"on one grousered wheel ({count} grousers of {1000 * height_m:g} mm, no smooth "
             "or other-lug wheel on the same soil)")
    fix = "; a smooth wheel run on the same soil separates them"
    if "slip_sinkage" in effects:
        return (f"{where} the soil's slip-sinkage cannot be told from the lugs' (lugged wheels "
                f"sink more as slip rises, Ding et al. 2011){fix}")
    if "grousers" in effects:
        max_slip = float(np.nanmax(np.abs(points["slip"].to_numpy(float))))
        lugs = lug_slip_sinkage_text(laws["grousers"], values, wheel, max_slip)
        if lugs is not None:
            return (f"{where} the grousers call rests on their slip-sinkage term ({lugs}), "
                    f"which the soil's own slip-sinkage would give as well{fix}")
    return None
