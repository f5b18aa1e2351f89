"""Wong-Reece stress distribution under a rigid wheel, integrated on a fixed Gauss grid.

Normal stress (Wong & Reece 1967, J. Terramech. 4(1), part I, front and rear regions),
pressure-sinkage of Bekker (1956) in Reece's (1965) form with exponent ``n``::

    front  theta_m <= theta <= theta_1:  sigma = k b^n0 (r (cos theta - cos theta_1)/b)^n
    rear   theta_2 <= theta <  theta_m:  theta* = theta_1 - (theta - theta_2)/(theta_m - theta_2)
                                                  * (theta_1 - theta_m), same law at theta*
    k = kc/b + kphi

Shear stress of Janosi & Hanamoto (1961), ``tau = (c + sigma tan phi)(1 - exp(-|j|/K))``
with the sign of ``j``.

Driven wheel, ``s = (r omega - v)/(r omega)`` in [0, 1] (part I):
``theta_m = (c1 + c2 s) theta_1`` and, from the entry,
``j = r_s [(theta_1 - theta) - (1 - s)(sin theta_1 - sin theta)]``.

Braked or towed wheel, skid ``s = (r omega - v)/v`` in [-1, 0), so ``r omega/v = 1 + s``
(Wong & Reece 1967, J. Terramech. 4(2), part II): two soil flow zones meet at the
transition angle ``theta_t``, where the absolute velocity of the rim makes the angle
``45 deg - phi/2`` with the radius::

    tan(45 deg - phi/2) = (cos theta_t - r omega/v) / sin theta_t

The normal stress peaks there (``theta_m = theta_t``). In front of it the soil of the
flow zone moves with the rim, the shear displacement vanishes at both ends of the zone
and the shear drives; behind it the rim slides forward over the soil and the shear
brakes::

    front  j = (v/omega) [(theta_1 - theta)(sin theta_1 - sin theta_t)/(theta_1 - theta_t)
                          - (sin theta_1 - sin theta)]
    rear   j = (v/omega) [(r omega/v)(theta_t - theta) - (sin theta_t - sin theta)]

with ``v/omega = r_s/(1 + s)``. A locked wheel (s = -1, omega = 0) has |j| infinite:
the shear is fully mobilised, which the exponential law takes as its limit.
"""

from __future__ import annotations

import numpy as np

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(24)
NODES = 0.5 * (_NODES + 1.0)  # on [0, 1]
WEIGHTS = 0.5 * _WEIGHTS


def kinematic_slip(slip):
    """Part I's slip ``i = 1 - v/(r omega)`` of a condition given as driving slip (s >= 0,
    the same) or skid (s < 0, ``s/(1 + s)``; a locked wheel is taken as i = -1e9). Part I's
    shear displacement is the rim's slip velocity ``r omega - v cos(theta)`` integrated over
    the contact (Wong & Reece 1967, part I), so its formula holds for a braked wheel at this
    signed slip; the rover models of Ishigami et al. 2007 (J. Field Robotics 24(3):233-250)
    use part I's laws at a signed slip on both branches, which meet at s = 0 without a step."""
    s = np.asarray(slip, dtype=float)
    return np.where(s < 0, s / np.maximum(1.0 + s, 1e-9), s)


def max_stress_angle(theta1, theta2, slip, c1, c2):
    """theta_m = (c1 + c2 s) theta_1 of a driven wheel (Wong & Reece 1967, part I), kept
    within [theta_2, theta_1]."""
    return np.clip((c1 + c2 * slip) * theta1, theta2, theta1)


def transition_angle(slip, phi_rad):
    """Transition angle theta_t (rad) of a braked or towed wheel, skid ``slip`` in [-1, 0]:
    the root of ``tan(pi/4 - phi/2) = (cos t - (1 + s))/sin t`` (Wong & Reece 1967,
    J. Terramech. 4(2), part II), i.e. ``arccos((1 + s) cos(a)) - a`` with
    ``a = pi/4 - phi/2``. 0 at s = 0, ``pi/4 + phi/2`` for a locked wheel."""
    a = np.pi / 4 - np.asarray(phi_rad, dtype=float) / 2
    rolling = 1.0 + np.clip(slip, -1.0, 0.0)
    return np.arccos(rolling * np.cos(a)) - a


def region_grid(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre angles and weights on [lo, hi] along a new last axis."""
    span = (hi - lo)[..., None]
    return lo[..., None] + span * NODES, span * WEIGHTS


def normal_stress(rear, cos_front, theta1, theta2, thetam, k_reece_pa, n, radius_m, width_m):
    """Wong-Reece normal stress (Pa) on the rear grid ``rear`` (angles in [theta_2,
    theta_m]) and the front grid (given by its cosines), joined rear first;
    ``k_reece_pa = (kc/b + kphi) b^n0``."""
    t1, t2, tm = theta1[..., None], theta2[..., None], thetam[..., None]
    span = np.where(tm - t2 > 0, tm - t2, 1.0)
    equiv = t1 - (rear - t2) / span * (t1 - tm)
    cos_t1 = np.cos(t1)
    depth = np.maximum(radius_m[..., None]
                       * (np.concatenate([np.cos(equiv), cos_front], axis=-1) - cos_t1), 0.0)
    return k_reece_pa[..., None] * (depth / width_m) ** n[..., None]


def shear_displacement(theta, sin_theta, theta1, shear_radius_m, slip):
    """Shear displacement j (m) of a driven wheel, slip in [0, 1] (Wong & Reece 1967, part I);
    ``sin_theta``: the sines of the angles ``theta``."""
    t1 = theta1[..., None]
    return shear_radius_m[..., None] * ((t1 - theta) - (1.0 - slip)[..., None]
                                        * (np.sin(t1) - sin_theta))


def skid_shear_displacement(theta, sin_theta, theta1, thetat, shear_radius_m, slip):
    """Shear displacement j (m) of a braked or towed wheel, skid in [-1, 0) (Wong & Reece
    1967, part II): flow zone in front of ``thetat``, reversed shear behind it; +-inf for a
    locked wheel (0 where the bracket vanishes, at theta_t and theta_1)."""
    t1, tt = theta1[..., None], thetat[..., None]
    rolling = (1.0 + slip)[..., None]
    chord = (np.sin(t1) - np.sin(tt)) / np.where(t1 > tt, t1 - tt, 1.0)
    shape = np.where(theta > tt, (t1 - theta) * chord - (np.sin(t1) - sin_theta),
                     rolling * (tt - theta) - (np.sin(tt) - sin_theta))
    with np.errstate(divide="ignore", invalid="ignore"):
        j = shear_radius_m[..., None] * shape / rolling
    return np.where(shape == 0, 0.0, j)


def shear_stress(sigma, j, cohesion_pa, phi_rad, shear_modulus_m):
    """Janosi-Hanamoto shear stress (Pa), signed as the shear displacement."""
    strength = cohesion_pa[..., None] + sigma * np.tan(phi_rad)[..., None]
    return np.sign(j) * strength * -np.expm1(-np.abs(j) / shear_modulus_m[..., None])
