"""State passed between the model and its effects (arrays broadcast over conditions)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from swtlab_base.domain.gravity import G0_MPS2

#: the gravity the soil parameters hold at (their unit weight rho g): standard gravity
EARTH_GRAVITY_MPS2 = G0_MPS2


@dataclass(frozen=True)
class Condition:
    """Operating point(s): wheel load, slip, multipass index, gravity (broadcast arrays)."""

    load_n: np.ndarray
    slip: np.ndarray
    multipass: np.ndarray
    gravity_mps2: np.ndarray


@dataclass(frozen=True)
class SoilState:
    """Soil parameters in use at each condition, after the effects adjusted them."""

    kc: np.ndarray
    kphi: np.ndarray
    n0: np.ndarray
    n_slope: np.ndarray  # dn/ds when driving (slip-sinkage), 0 without the effect
    n_skid_slope: np.ndarray  # dn/d|s| when braked (skid ratio s < 0), 0 without it
    cohesion_pa: np.ndarray
    phi_rad: np.ndarray
    shear_modulus_m: np.ndarray
    unit_weight_n_m3: np.ndarray  # gamma = rho g
    c1: np.ndarray
    c2: np.ndarray
    c3: np.ndarray


@dataclass(frozen=True)
class Geometry:
    """Wheel geometry at each condition: deflection and shear-radius offset from the effects."""

    radius_m: float
    width_m: float
    deflection_m: np.ndarray
    shear_offset_m: np.ndarray  # lambda h of the grousers

    def contact_radius_m(self, sinkage_m: np.ndarray) -> np.ndarray:
        """Radius of the equivalent rigid wheel: the same contact length as the deflected one.

        A wheel deflected by delta and sunk z meets the surface at x ~ sqrt(2 r (z + delta)),
        a rigid wheel of radius r_e at sqrt(2 r_e z), so r_e = r (z + delta)/z (the
        equivalent-rigid-wheel idea of Wong, Terramechanics and Off-Road Vehicle
        Engineering 2010, ch. 4). Equals r for a rigid wheel.
        """
        return self.radius_m * (1.0 + self.deflection_m / sinkage_m)

    @property
    def arm_radius_m(self) -> np.ndarray:
        """Loaded radius r - delta: the lever arm of the soil shear about the hub."""
        return self.radius_m - self.deflection_m


@dataclass(frozen=True)
class Contact:
    """Solved contact: sinkage, angles (rad) and shear displacement at the exit."""

    sinkage_m: np.ndarray
    theta1_rad: np.ndarray
    theta2_rad: np.ndarray
    thetam_rad: np.ndarray
    exit_shear_displacement_m: np.ndarray


@dataclass(frozen=True)
class ExtraForces:
    """Forces an effect adds outside the stress integrals, each named in ``terms`` (N)."""

    dp_n: np.ndarray | float = 0.0
    torque_nm: np.ndarray | float = 0.0
    terms: dict[str, np.ndarray] = field(default_factory=dict)
