"""The testbed's soil: Reece's dimensionless pressure-sinkage and Wong's shear law with a hump.

Pressure-sinkage, Reece (1965), "Principles of soil-vehicle mechanics", Proc. Instn Mech.
Engrs 180(2A):45-66::

    p(z) = (c k'c + gamma b k'phi) (z / b)^n,     gamma = rho g

with dimensionless moduli ``k'c``, ``k'phi``: the frictional term carries the soil's unit
weight (so the soil's stiffness depends on gravity, see :mod:`testbeds.apart.effects`) and
the width enters as ``(z/b)^n``, not Bekker's ``kc/b + kphi``.

Shear, Wong's curve with a hump (Wong 2008, Theory of Ground Vehicles, 4th ed., Wiley, §2.4;
dense sand and compacted soils: a peak at ``j = K_w``, then down to a residual ``K_r`` of
it)::

    tau / tau_max = K_r {1 + [1 / (K_r (1 - 1/e)) - 1] exp(1 - j/K_w)} (1 - exp(-j/K_w))

normalised here by its largest value over ``j`` so that the peak is the Mohr-Coulomb
strength ``c + sigma tan(phi)``; odd in ``j`` (braked wheels shear backwards), smooth through
``j = 0``.

The published soils below are Bekker sets; their Reece moduli are obtained at a reference
width ``b_ref`` (the test wheel's) by matching the pressure there:
``k'c = kc b_ref^(n-1) / c`` and ``k'phi = kphi b_ref^(n-1) / (rho g0)``. The soil then
keeps the published stiffness at that width and adds Reece's unit-weight scaling.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace
from functools import lru_cache

import numpy as np
from scipy.optimize import minimize_scalar

G0_MPS2 = 9.80665


@dataclass(frozen=True)
class PublishedSoil:
    """A published Bekker soil set (SI), the lab's guess and the centre of a truth's soil."""

    name: str
    source: str
    kc: float
    kphi: float
    n: float
    cohesion_pa: float
    friction_angle_deg: float
    shear_modulus_m: float
    density_kg_m3: float


#: published sets a lab could start from (values as tabulated in the sources named)
PUBLISHED = (
    PublishedSoil("wong_dry_sand", "Wong 2008, Theory of Ground Vehicles, 4th ed., Table 2.3, "
                  "dry sand (LLL); K and density typical", 0.99e3, 1528.43e3, 1.1, 1.04e3, 28.0,
                  0.025, 1600.0),
    PublishedSoil("lete_sand", "Wong 2010, Terramechanics and Off-Road Vehicle Engineering, "
                  "LETE sand (Wong & Reece 1967); density typical", 102e3, 5301e3, 0.79, 1.3e3,
                  31.1, 0.0115, 1600.0),
    PublishedSoil("lunar_nominal", "Lunar Sourcebook (Heiken, Vaniman & French 1991), ch. 9, "
                  "nominal lunar soil", 1.4e3, 820e3, 1.0, 0.17e3, 35.0, 0.0178, 1500.0),
    PublishedSoil("ding2011_simulant", "Ding et al. 2011, J. Terramech. 48(1):27-45, Table 2 "
                  "(K = 9.7-13.1 mm, 11 mm used)", 15.6e3, 2407.4e3, 1.10, 250.0, 31.9, 0.011,
                  1605.0),
)


@dataclass(frozen=True)
class ReeceSoil:
    """Reece's pressure-sinkage and Wong's hump shear (SI; ``shear_peak_m`` is ``K_w``)."""

    kc_prime: float
    kphi_prime: float
    n: float
    cohesion_pa: float
    friction_angle_deg: float
    density_kg_m3: float
    shear_peak_m: float
    residual_ratio: float = 1.0
    #: the unit weight the pressure-sinkage sees (N/m^3); None: rho g of the run's gravity
    unit_weight_n_m3: float | None = None

    def __post_init__(self):
        if not (self.n > 0 and self.shear_peak_m > 0 and 0.3 <= self.residual_ratio <= 1.0):
            raise ValueError(f"soil: need n > 0, K_w > 0, 0.3 <= K_r <= 1: {self}")

    def to_dict(self) -> dict:
        return asdict(self)

    def with_(self, **changes) -> ReeceSoil:
        return replace(self, **changes)


def from_published(soil: PublishedSoil, width_m: float) -> ReeceSoil:
    """The Reece soil with the published set's pressure at width ``width_m`` and g0; Wong's
    ``K_w`` at twice the published Janosi K (Janosi's curve reaches 86 % of its strength at
    2 K), residual ratio ``K_r`` = 1 (the campaign draws its own)."""
    scale = width_m ** (soil.n - 1)
    kc_prime = soil.kc * scale / soil.cohesion_pa if soil.cohesion_pa > 0 else 0.0
    kphi_prime = soil.kphi * scale / (soil.density_kg_m3 * G0_MPS2)
    return ReeceSoil(kc_prime=kc_prime, kphi_prime=kphi_prime, n=soil.n,
                     cohesion_pa=soil.cohesion_pa, friction_angle_deg=soil.friction_angle_deg,
                     density_kg_m3=soil.density_kg_m3, shear_peak_m=2 * soil.shear_modulus_m)


def unit_weight(soil: ReeceSoil, gravity_mps2: float) -> float:
    """``gamma`` of the pressure-sinkage term (N/m^3)."""
    if soil.unit_weight_n_m3 is not None:
        return soil.unit_weight_n_m3
    return soil.density_kg_m3 * gravity_mps2


def pressure_pa(soil: ReeceSoil, sinkage_m, width_m: float, gravity_mps2: float):
    """Reece (1965): ``(c k'c + gamma b k'phi) (z/b)^n``; 0 for ``z <= 0``."""
    z = np.maximum(np.asarray(sinkage_m, dtype=float), 0.0)
    modulus = (soil.cohesion_pa * soil.kc_prime
               + unit_weight(soil, gravity_mps2) * width_m * soil.kphi_prime)
    return modulus * (z / width_m) ** soil.n


def _hump(x: float, residual_ratio: float) -> float:
    e = math.e
    k = residual_ratio
    return k * (1 + (1 / (k * (1 - 1 / e)) - 1) * math.exp(1 - x)) * (1 - math.exp(-x))


@lru_cache(maxsize=256)
def _hump_peak(residual_ratio: float) -> float:
    """The largest value of Wong's shape over ``x = j/K_w`` (1.05 at ``K_r`` = 1)."""
    best = minimize_scalar(lambda x: -_hump(x, residual_ratio), bounds=(0.5, 6.0),
                           method="bounded", options={"xatol": 1e-10})
    return max(-best.fun, _hump(1.0, residual_ratio))


def shear_stress_pa(soil: ReeceSoil, normal_pa, displacement_m):
    """Wong's hump curve times the Mohr-Coulomb strength, peak normalised to it; odd in j."""
    j = np.asarray(displacement_m, dtype=float)
    x = np.abs(j) / soil.shear_peak_m
    k = soil.residual_ratio
    e = math.e
    shape = k * (1 + (1 / (k * (1 - 1 / e)) - 1) * np.exp(1 - x)) * (1 - np.exp(-x))
    strength = soil.cohesion_pa + np.asarray(normal_pa) * math.tan(
        math.radians(soil.friction_angle_deg))
    return np.sign(j) * strength * shape / _hump_peak(k)
