"""The testbed's steady-state wheel-soil solver: Iagnemma's linearised stress distribution on
Reece's pressure-sinkage and Wong's hump shear (:mod:`testbeds.apart.soil`).

Stress distribution, Iagnemma, Kang, Shibly & Dubowsky (2004), "Online terrain parameter
estimation for wheeled mobile robots with application to planetary rovers", IEEE Trans.
Robotics 20(5):921-927: normal and shear stress rise linearly from 0 at the entry angle
``theta1`` to their peaks at ``theta_m`` and fall linearly to 0 at the exit angle
``theta2``; the peaks are the stresses of the rim at ``theta_m``::

    sigma_m = p(r (cos theta_m - cos theta1)),   tau_m = g tau(sigma_m, j(theta_m))

``g`` is the lugs' shear gain (1 on a smooth rim; :mod:`testbeds.apart.effects`). Here
``theta_m = (0.38 + 0.22 s) theta1`` over the whole slip range ``s`` in [-1, 1] (one linear
law for braked and driven wheels, so nothing jumps at s = 0; Iagnemma et al. take the peak
angle linear in slip) and a small rebound behind the wheel, ``theta2 = -0.1 theta1``.

Kinematics for every slip: ``j(theta) = r (theta1 - theta) - (v / omega)(sin theta1 -
sin theta)`` with ``v / (r omega) = 1 - s`` driving and ``1 / (1 + s)`` braked (the raw-run
spec's skid), continuous with its derivative at s = 0.

Forces per unit of the stress profile ``f`` (closed-form integrals of linear functions times
``cos``, ``sin``; Wong 2008, eqs. 2.69-2.71 for the force balance)::

    W  = r b  int (sigma cos + tau sin),  DP = r b int (tau cos - sigma sin),
    T  = r^2 b int tau

A flexible wheel (deflection ``delta``) has a flat chord of half-length
``l = sqrt(2 r delta - delta^2)`` at the sinkage ``z``: uniform ``sigma_f = p(z)`` on it, its
shear at the mean slip displacement over the chord, ``(r omega / v - 1) l`` (as on the flat
contact of a tyre, Wong 2008 §2.4: ``j = i x`` from the front of the flat, the tread moving
with the ground at zero slip), lever arm ``r - delta``; linear arcs in front (entry
``theta1 = acos(1 - (z + delta)/r)``, the rim's kinematics) and behind (rebound
``0.1 (theta1 - theta_f)``).
The vertical equilibrium ``W = load`` is solved for the sinkage by Brent's method.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import brentq

from testbeds.apart.soil import ReeceSoil, pressure_pa, shear_stress_pa

PEAK_RATIO_AT_ZERO_SLIP = 0.38
PEAK_RATIO_PER_SLIP = 0.22
REAR_RATIO = 0.1
#: largest entry angle searched (sinkage 0.64 r): deeper, the wheel has no equilibrium
THETA1_MAX_RAD = 1.2


class NoEquilibrium(ValueError):
    """The soil cannot carry the load within the searched sinkage."""


@dataclass(frozen=True)
class Contact:
    """What the solver needs of one condition: the soil the wheel meets (effects applied),
    the rim, its deflection and the lugs' shear gain, the gravity the soil feels."""

    soil: ReeceSoil
    radius_m: float
    width_m: float
    gravity_mps2: float
    deflection_m: float = 0.0
    shear_gain: float = 1.0


def speed_ratio(slip: float) -> float:
    """``v / (r omega)`` for the spec's slip (driving ``1 - s``, skid ``1 / (1 + s)``)."""
    if not -1 < slip < 1:
        raise ValueError(f"slip {slip} outside (-1, 1)")
    return 1.0 - slip if slip >= 0 else 1.0 / (1.0 + slip)


def linear_integrals(a: float, b: float, fa: float, fb: float) -> tuple[float, float, float]:
    """``int_a^b f cos``, ``int_a^b f sin``, ``int_a^b f`` for ``f`` linear from ``fa`` at
    ``a`` to ``fb`` at ``b`` (closed form)."""
    if b - a <= 0:
        return 0.0, 0.0, 0.0
    slope = (fb - fa) / (b - a)
    cos_int = fa * (math.sin(b) - math.sin(a)) + slope * (
        (b - a) * math.sin(b) + math.cos(b) - math.cos(a))
    sin_int = fa * (math.cos(a) - math.cos(b)) + slope * (
        -(b - a) * math.cos(b) + math.sin(b) - math.sin(a))
    return cos_int, sin_int, 0.5 * (fa + fb) * (b - a)


def displacement_m(radius_m: float, theta1: float, theta: float, ratio: float) -> float:
    """Shear displacement of the rim at ``theta``; ``ratio`` is ``v / (r omega)``."""
    return radius_m * ((theta1 - theta) - ratio * (math.sin(theta1) - math.sin(theta)))


def forces_at(contact: Contact, theta1: float, slip: float) -> dict[str, float]:
    """Vertical force, drawbar pull, torque and the stresses at a given entry angle."""
    r, b, soil, g = contact.radius_m, contact.width_m, contact.soil, contact.gravity_mps2
    ratio = speed_ratio(slip)
    delta = contact.deflection_m
    if delta <= 0:
        theta_m = (PEAK_RATIO_AT_ZERO_SLIP + PEAK_RATIO_PER_SLIP * slip) * theta1
        theta2 = -REAR_RATIO * theta1
        sigma_m = float(pressure_pa(soil, r * (math.cos(theta_m) - math.cos(theta1)), b, g))
        tau_m = contact.shear_gain * float(shear_stress_pa(
            soil, sigma_m, displacement_m(r, theta1, theta_m, ratio)))
        rear = linear_integrals(theta2, theta_m, 0.0, 1.0)
        front = linear_integrals(theta_m, theta1, 1.0, 0.0)
        ic, is_, i1 = (x + y for x, y in zip(rear, front))
        return {"fz_n": r * b * (sigma_m * ic + tau_m * is_),
                "dp_n": r * b * (tau_m * ic - sigma_m * is_), "torque_nm": r * r * b * tau_m * i1,
                "sinkage_m": r * (1 - math.cos(theta1)), "theta1_rad": theta1,
                "theta_m_rad": theta_m, "sigma_peak_pa": sigma_m, "tau_peak_pa": tau_m}
    half = math.sqrt(2 * r * delta - delta * delta)
    theta_f = math.asin(half / r)
    z = r * (1 - math.cos(theta1)) - delta
    sigma_f = float(pressure_pa(soil, z, b, g))
    j_front = displacement_m(r, theta1, theta_f, ratio)
    tau_arc = contact.shear_gain * float(shear_stress_pa(soil, sigma_f, j_front))
    tau_flat = contact.shear_gain * float(shear_stress_pa(soil, sigma_f,
                                                          (1 / ratio - 1) * half))
    theta2 = -theta_f - REAR_RATIO * (theta1 - theta_f)
    front = linear_integrals(theta_f, theta1, 1.0, 0.0)
    rear = linear_integrals(theta2, -theta_f, 0.0, 1.0)
    fz = r * b * (sigma_f * (front[0] + rear[0]) + tau_arc * front[1] + tau_flat * rear[1])
    dp = r * b * (tau_arc * front[0] + tau_flat * rear[0] - sigma_f * (front[1] + rear[1]))
    torque = r * r * b * (tau_arc * front[2] + tau_flat * rear[2])
    flat = 2 * half * b
    return {"fz_n": fz + flat * sigma_f, "dp_n": dp + flat * tau_flat,
            "torque_nm": torque + flat * tau_flat * (r - delta), "sinkage_m": z,
            "theta1_rad": theta1, "theta_m_rad": theta_f, "sigma_peak_pa": sigma_f,
            "tau_peak_pa": tau_flat}


def solve(contact: Contact, load_n: float, slip: float) -> dict[str, float]:
    """Steady state at ``load_n`` and ``slip``: sinkage from ``W = load`` (to 1e-9 W), then
    drawbar pull and torque. Raises :class:`NoEquilibrium` when the wheel would sink past
    ``THETA1_MAX_RAD``."""
    r, delta = contact.radius_m, contact.deflection_m
    low = math.acos(1 - delta / r) + 1e-9 if delta > 0 else 1e-7
    high = THETA1_MAX_RAD
    if forces_at(contact, high, slip)["fz_n"] < load_n:
        raise NoEquilibrium(f"no equilibrium at {load_n:.0f} N, slip {slip:.2f}: the soil "
                            f"carries less than the load at {r * (1 - math.cos(high)):.3f} m")
    theta1 = brentq(lambda t: forces_at(contact, t, slip)["fz_n"] - load_n, low, high,
                    xtol=1e-12, rtol=1e-12)
    return forces_at(contact, theta1, slip)
