"""Priors of the soil calibration from published soil tables.

One Gaussian prior per calibrated soil parameter, its centre the mean and its spread the
standard deviation over the published soils (``terramechanics.SOILS``: Wong's dry sand,
LETE sand, the nominal lunar soil; ``terramechanics/soil_tables/published_soils.csv``: the
CMU authors' own soil and lunar simulants), in log space for the moduli (k, K). The
pressure-sinkage modulus is taken at the wheel's width, ``k = kc/b + kphi`` (Bekker 1969):
one width cannot separate kc from kphi. A floor on each spread keeps a few similar
soils from pinning a parameter.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

import terramechanics as tm

TABLE_CSV = Path(tm.__file__).parent / "soil_tables" / "published_soils.csv"
#: smallest prior spread per parameter (internal units: log for the moduli)
MIN_SPREAD = {"soil.kphi": np.log(2.0), "soil.n": 0.15, "soil.cohesion_pa": 300.0,
              "soil.friction_angle_deg": 3.0, "soil.shear_modulus_m": np.log(1.5)}
LOG_SCALE = {"soil.kphi": True, "soil.n": False, "soil.cohesion_pa": False,
             "soil.friction_angle_deg": False, "soil.shear_modulus_m": True}


@dataclass(frozen=True)
class ParamPrior:
    """Gaussian prior of one dotted model parameter; ``centre``/``spread`` are in log space
    when ``log``. ``sources``: the soils it was made from."""

    name: str
    centre: float
    spread: float
    log: bool
    sources: tuple[str, ...]

    def residual(self, value: float) -> float:
        """Standardised deviation of ``value`` from the centre."""
        x = np.log(value) if self.log else value
        return (x - self.centre) / self.spread

    @property
    def centre_value(self) -> float:
        return float(np.exp(self.centre) if self.log else self.centre)


def published_soils() -> pd.DataFrame:
    """Every published soil: name, kc, kphi, n, cohesion_pa, friction_angle_deg,
    shear_modulus_m (NaN where not published), source."""
    builtin = pd.DataFrame([{
        "name": s.name, "kc": s.kc, "kphi": s.kphi, "n": s.n, "cohesion_pa": s.cohesion_pa,
        "friction_angle_deg": s.friction_angle_deg, "shear_modulus_m": s.shear_modulus_m,
        "source": s.source} for s in tm.SOILS.values()])
    return pd.concat([builtin, pd.read_csv(TABLE_CSV, comment="#")], ignore_index=True)


def soil_prior(width_m: float, soils: pd.DataFrame | None = None) -> tuple[ParamPrior, ...]:
    """Priors of ``soil.kphi`` (as k = kc/b + kphi at ``width_m``), ``soil.n``,
    ``soil.cohesion_pa``, ``soil.friction_angle_deg``, ``soil.shear_modulus_m``."""
    if width_m <= 0:
        raise ValueError(f"width_m must be > 0, got {width_m}")
    return _published_prior(width_m) if soils is None else _prior(width_m, soils)


@lru_cache(maxsize=None)
def _published_prior(width_m: float) -> tuple[ParamPrior, ...]:
    """:func:`soil_prior` of the published soils, read and computed once per width: a
    diagnosis asks for it at every candidate's evidence (hundreds of times), and the table
    is a file of the package."""
    return _prior(width_m, published_soils())


def _prior(width_m: float, soils: pd.DataFrame) -> tuple[ParamPrior, ...]:
    columns = {"soil.kphi": soils["kc"] / width_m + soils["kphi"], "soil.n": soils["n"],
               "soil.cohesion_pa": soils["cohesion_pa"],
               "soil.friction_angle_deg": soils["friction_angle_deg"],
               "soil.shear_modulus_m": soils["shear_modulus_m"]}
    priors = []
    for name, column in columns.items():
        known = column.notna().to_numpy()
        x = column.to_numpy(float)[known]
        if x.size < 2:
            raise ValueError(f"prior of {name}: fewer than two published values")
        x = np.log(x) if LOG_SCALE[name] else x
        priors.append(ParamPrior(name, float(x.mean()),
                                 float(max(x.std(ddof=1), MIN_SPREAD[name])), LOG_SCALE[name],
                                 tuple(soils["name"][known])))
    return tuple(priors)
