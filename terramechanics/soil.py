"""Soil parameters of the rigid-wheel model, SI units, and literature sets.

Pressure-sinkage (Bekker 1956/1969) ``p = (kc/b + kphi) z^n``, written in the
dimensionless form of Reece (1965) ``p = (kc/b + kphi) b^n (z/b)^n`` so that
the exponent may vary (slip-sinkage effect). Shear strength Mohr-Coulomb
``c + sigma tan(phi)`` with the Janosi & Hanamoto (1961) shear modulus ``K``.
``c1, c2`` set the Wong & Reece (1967) maximum-stress angle
``theta_m = (c1 + c2 s) theta_1``; ``c3`` the rear (exit) angle
``theta_2 = -c3 theta_1``. ``shear_modulus_slip_m`` (K1) and ``c4`` make K and the exit
angle grow with driving slip, ``K = K0 + K1 s`` (K0 = shear_modulus_m) and
``theta_2 = -(c3 + c4 s) theta_1`` (Ding et al. 2015, J. Field Robotics 32(6);
``terramechanics/slip_soil_ding2015.py``); both 0 by default.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SoilParams:
    """One soil, SI units (kc in N/m^(n+1), kphi in N/m^(n+2))."""

    kc: float
    kphi: float
    n: float
    cohesion_pa: float
    friction_angle_deg: float
    shear_modulus_m: float
    density_kg_m3: float
    c1: float = 0.43
    c2: float = 0.32
    c3: float = 0.0
    shear_modulus_slip_m: float = 0.0
    c4: float = 0.0
    name: str = "custom"
    source: str = ""

    def __post_init__(self) -> None:
        if self.n <= 0 or self.shear_modulus_m <= 0 or self.density_kg_m3 <= 0:
            raise ValueError(f"soil {self.name!r}: n, shear_modulus_m, density_kg_m3 must be > 0")
        if not 0 <= self.friction_angle_deg < 90 or self.cohesion_pa < 0:
            raise ValueError(f"soil {self.name!r}: need 0 <= phi < 90 deg and c >= 0")
        if self.kc <= 0 and self.kphi <= 0:
            raise ValueError(f"soil {self.name!r}: kc or kphi must be > 0")
        if self.shear_modulus_m + self.shear_modulus_slip_m <= 0:
            raise ValueError(f"soil {self.name!r}: K + K1 (shear_modulus_slip_m) must be > 0")


_WR = "Wong & Reece 1967 (J. Terramech. 4(1)) c1=0.43, c2=0.32"

WONG_DRY_SAND = SoilParams(
    kc=0.99e3, kphi=1528.43e3, n=1.1, cohesion_pa=1.04e3, friction_angle_deg=28.0,
    shear_modulus_m=0.025, density_kg_m3=1600.0, name="wong_dry_sand",
    source="Wong, Theory of Ground Vehicles (4th ed. 2008), Table 2.3, dry sand (LLL): "
           "n=1.1, kc=0.99 kN/m^(n+1), kphi=1528.43 kN/m^(n+2), c=1.04 kPa, phi=28 deg; "
           f"K=2.5 cm and density are typical values for dry sand, not from the table; {_WR}",
)

LETE_SAND = SoilParams(
    kc=102e3, kphi=5301e3, n=0.79, cohesion_pa=1.3e3, friction_angle_deg=31.1,
    shear_modulus_m=0.0115, density_kg_m3=1600.0, name="lete_sand",
    source="Wong, Terramechanics and Off-Road Vehicle Engineering (2010), LETE sand "
           "(Wong & Reece 1967): n=0.79, kc=102 kN/m^(n+1), kphi=5301 kN/m^(n+2), c=1.3 kPa, "
           f"phi=31.1 deg, K=1.15 cm; density typical; {_WR}",
)

LUNAR_NOMINAL = SoilParams(
    kc=1.4e3, kphi=820e3, n=1.0, cohesion_pa=0.17e3, friction_angle_deg=35.0,
    shear_modulus_m=0.0178, density_kg_m3=1500.0, name="lunar_nominal",
    source="Lunar Sourcebook (Heiken, Vaniman & French 1991, ch. 9, Carrier et al.) nominal "
           "lunar soil after Bekker/Costes: n=1, kc=1.4 kN/m^2, kphi=820 kN/m^3, c=0.17 kPa, "
           f"phi=35 deg, K=1.78 cm, bulk density 1.5 g/cm^3; {_WR}",
)

SOILS: dict[str, SoilParams] = {s.name: s for s in (WONG_DRY_SAND, LETE_SAND, LUNAR_NOMINAL)}
