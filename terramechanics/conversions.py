"""Mohr-Coulomb <-> linear Drucker-Prager soil strength parameters.

As used for continuum wheel-soil models in "Dynamic response of rigid wheels on
deformable terrains" (the relation the paper gives for its linear Drucker-Prager
soil): ``beta = arctan(2 sin phi)``, ``d = 2 c cos phi``; inverted exactly here.
"""

from __future__ import annotations

import numpy as np


def mohr_coulomb_to_drucker_prager(cohesion_pa, friction_angle_deg):
    """(c, phi) -> (d in Pa, beta in deg): beta = arctan(2 sin phi), d = 2 c cos phi."""
    phi = np.radians(friction_angle_deg)
    return 2.0 * np.asarray(cohesion_pa) * np.cos(phi), np.degrees(np.arctan(2.0 * np.sin(phi)))


def drucker_prager_to_mohr_coulomb(d_pa, beta_deg):
    """(d, beta) -> (c in Pa, phi in deg), the inverse; needs tan beta <= 2."""
    tan_beta = np.tan(np.radians(beta_deg))
    if np.any(tan_beta > 2.0) or np.any(tan_beta < 0.0):
        raise ValueError("linear Drucker-Prager beta must satisfy 0 <= tan(beta) <= 2")
    phi = np.arcsin(tan_beta / 2.0)
    return np.asarray(d_pa) / (2.0 * np.cos(phi)), np.degrees(phi)
