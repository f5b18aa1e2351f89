"""Wong-Reece stress distribution under a rigid wheel, integrated on a fixed Gauss grid.

Normal stress (Wong & Reece 1967, part 1, eqs. for the front and rear regions),
pressure-sinkage of Bekker (1956) in Reece's (1965) form with exponent ``n``::

    front  theta_m <= theta <= theta_1:  sigma = k b^n0 (r (cos theta - cos theta_1)/b)^n
    rear   theta_2 <= theta <  theta_m:  theta* = theta_1 - (theta - theta_2)/(theta_m - theta_2)
                                                  * (theta_1 - theta_m), same law at theta*
    theta_m = (c1 + c2 s) theta_1,   k = kc/b + kphi

Shear stress of Janosi & Hanamoto (1961), ``tau = (c + sigma tan phi)(1 - exp(-|j|/K))``
with the sign of ``j``; shear displacement of Wong & Reece (1967, parts 1 and 2)::

    j(theta) = r_s [(theta_1 - theta) - (v / (r omega)) (sin theta_1 - sin theta)]

``v/(r omega) = 1 - s`` for a driven wheel (``s = (r omega - v)/(r omega)``) and
``1/(1 + s)`` for a braked or towed wheel (skid ``s = (r omega - v)/v`` in [-1, 0)).
"""

from __future__ import annotations

import numpy as np

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)
NODES = 0.5 * (_NODES + 1.0)  # on [0, 1]
WEIGHTS = 0.5 * _WEIGHTS
MIN_SKID = -0.99  # a locked wheel (s = -1) has no finite v/(r omega) in the skid form


def velocity_ratio(slip: np.ndarray) -> np.ndarray:
    """v/(r omega) from the driving (s >= 0) or skid (s < 0) slip definition."""
    s = np.asarray(slip, dtype=float)
    return np.where(s >= 0, 1.0 - s, 1.0 / (1.0 + np.maximum(s, MIN_SKID)))


def max_stress_angle(theta1, theta2, slip, c1, c2):
    """theta_m = (c1 + c2 s) theta_1 (Wong & Reece 1967), kept within [theta_2, theta_1]."""
    return np.clip((c1 + c2 * slip) * theta1, theta2, theta1)


def region_grid(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre angles and weights on [lo, hi] along a new last axis."""
    span = (hi - lo)[..., None]
    return lo[..., None] + span * NODES, span * WEIGHTS


def normal_stress(theta, theta1, theta2, thetam, k_reece_pa, n, radius_m, width_m):
    """Wong-Reece normal stress (Pa); ``k_reece_pa = (kc/b + kphi) b^n0``."""
    t1, t2, tm = theta1[..., None], theta2[..., None], thetam[..., None]
    rear = theta < tm
    span = np.where(tm - t2 > 0, tm - t2, 1.0)
    equiv = np.where(rear, t1 - (theta - t2) / span * (t1 - tm), theta)
    depth = np.maximum(radius_m[..., None] * (np.cos(equiv) - np.cos(t1)), 0.0)
    return k_reece_pa[..., None] * (depth / width_m) ** n[..., None]


def shear_displacement(theta, theta1, shear_radius_m, vel_ratio):
    """Wong-Reece shear displacement j (m) for driven and braked/towed wheels."""
    t1 = theta1[..., None]
    return shear_radius_m[..., None] * ((t1 - theta) - vel_ratio[..., None]
                                        * (np.sin(t1) - np.sin(theta)))


def shear_stress(sigma, j, cohesion_pa, phi_rad, shear_modulus_m):
    """Janosi-Hanamoto shear stress (Pa), signed as the shear displacement."""
    strength = cohesion_pa[..., None] + sigma * np.tan(phi_rad)[..., None]
    return np.sign(j) * strength * -np.expm1(-np.abs(j) / shear_modulus_m[..., None])
