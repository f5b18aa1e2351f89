"""Bulldozing after Bekker: the soil wedge pushed ahead of the wheel.

Bekker (1969) "Introduction to terrain-vehicle systems", after Hegedus (1960),
as given by Wong (Theory of Ground Vehicles, 4th ed. 2008, ch. 2, bulldozing resistance)::

    R_b = b sin(a + phi) / (2 sin a cos phi) (2 z c K_c + gamma z^2 K_g)
          + l0^3 gamma / 3 (pi/2 - phi) + c l0^2 (1 + tan(pi/4 + phi/2))
    a = arccos(1 - 2 z / D),  l0 = z tan^2(pi/4 - phi/2),
    K_c = (N_c - tan phi) cos^2 phi,  K_g = (2 N_g / tan phi + 1) cos^2 phi

Terzaghi's N_q and N_c, Vesic's (1973) N_g = 2 (N_q + 1) tan phi. It lowers the
drawbar pull at the same torque. ``coefficient`` scales it (1 = the formula). Derived
for a vertical blade of the rut depth (Hegedus' bulldozing blade), fitted to tyres of
off-road vehicles in soft soil; for small ruts in cohesive-frictional soil it gives tens
of newtons, more than small planetary wheels show (hence the coefficient).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from terramechanics.effects.base import Effect, FitParam
from terramechanics.state import ExtraForces


def terzaghi_nq(phi_rad: np.ndarray) -> np.ndarray:
    """Terzaghi's bearing capacity factor N_q."""
    a = np.exp((0.75 * np.pi - phi_rad / 2) * np.tan(phi_rad))
    return a**2 / (2 * np.cos(np.pi / 4 + phi_rad / 2) ** 2)


def terzaghi_nc(phi_rad: np.ndarray) -> np.ndarray:
    """Terzaghi's N_c = (N_q - 1) cot phi, 1.5 pi + 1 at phi = 0."""
    tan_phi = np.tan(phi_rad)
    safe = np.where(tan_phi > 1e-9, tan_phi, 1.0)
    return np.where(tan_phi > 1e-9, (terzaghi_nq(phi_rad) - 1) / safe, 1.5 * np.pi + 1)


def bulldozing_resistance_n(sinkage_m, diameter_m, width_m, cohesion_pa, phi_rad, gamma_n_m3):
    """Bekker's bulldozing resistance (N) of a wheel sunk ``sinkage_m``."""
    z = np.maximum(sinkage_m, 1e-12)
    alpha = np.arccos(np.clip(1 - 2 * z / diameter_m, -1.0, 1.0))
    cos2 = np.cos(phi_rad) ** 2
    k_c = (terzaghi_nc(phi_rad) - np.tan(phi_rad)) * cos2
    k_g = (4 * (terzaghi_nq(phi_rad) + 1) + 1) * cos2  # 2 N_g / tan phi with Vesic's N_g
    l0 = z * np.tan(np.pi / 4 - phi_rad / 2) ** 2
    wedge = (width_m * np.sin(alpha + phi_rad) / (2 * np.sin(alpha) * np.cos(phi_rad))
             * (2 * z * cohesion_pa * k_c + gamma_n_m3 * z**2 * k_g))
    return (wedge + l0**3 * gamma_n_m3 / 3 * (np.pi / 2 - phi_rad)
            + cohesion_pa * l0**2 * (1 + np.tan(np.pi / 4 + phi_rad / 2)))


@dataclass(frozen=True)
class BulldozingBekker1969(Effect):
    """``coefficient``: multiplier on Bekker's bulldozing resistance (1 = as published)."""

    coefficient: float = 1.0
    name = "bulldozing"
    law = "bekker1969"
    terms = ("bulldozing_n",)
    fit = (FitParam("coefficient", 0.5, 0.0, 5.0),)

    def forces(self, contact, soil, geo, cond, wheel):
        r_b = self.coefficient * bulldozing_resistance_n(
            contact.sinkage_m, 2 * wheel.radius_m, wheel.width_m, soil.cohesion_pa,
            soil.phi_rad, soil.unit_weight_n_m3)
        return ExtraForces(dp_n=-r_b, terms={"bulldozing_n": r_b})
