"""Slip-dependent shear modulus and exit angle after Ding et al. (2015).

Ding, Deng, Gao, Tao, Iagnemma & Liu (2015) "Interaction mechanics model for rigid
driving wheels of planetary rovers moving on sandy terrain with consideration of
multiple physical effects", J. Field Robotics 32(6):827-859, building on the single-wheel
tests of Ding, Gao, Deng, Nagatani & Yoshida (2011), J. Terramech. 48(1):27-45: on sand
the Janosi-Hanamoto shear deformation modulus of a driven wheel grows with slip, and so
does the rear (exit) contact angle, both linearly::

    K = K0 + K1 s                       (K0 = soil.shear_modulus_m, K1 = shear_modulus_slip_m)
    theta_2 = -(c3 + c4 s) theta_1      (here theta_2 < 0 is behind the vertical)

beside their ``theta_m = (c1 + c2 s) theta_1`` (Wong & Reece 1967) and ``N = n0 + n1 s``
(``effects/slip_sinkage_ding2011.py``). Physically: at low slip the soil under the
rim is sheared over a short, stiff zone (small K, the thrust builds up at once); at high
slip the sheared zone deepens and the soil flows, so the same shear displacement
mobilises less stress. Ding et al. identified the coefficients per wheel from their own
driving tests (slips 0-0.6) on their lunar simulant; swtlab has no copy of their values,
so ``K1`` and ``c4`` default to 0 (the constant-K Wong-Reece model) and any value used
on Ding's curves is fitted (``bench/bench_ding2011.py`` says on which wheel). The law
is for driving slips only: the skid branch (Wong & Reece 1967 part II) keeps K0 and c3.
"""

from __future__ import annotations

import numpy as np


def driving_slip(slip) -> np.ndarray:
    """The slip the law sees: s for a driven wheel, 0 on the skid branch."""
    return np.maximum(np.asarray(slip, dtype=float), 0.0)


def shear_modulus_m(k0_m: float, k1_m: float, slip) -> np.ndarray:
    """Janosi-Hanamoto K (m) at each slip: ``K0 + K1 s`` (K0 under skid)."""
    return k0_m + k1_m * driving_slip(slip)


def exit_angle_coefficient(c3: float, c4: float, slip) -> np.ndarray:
    """``c3 + c4 s`` of ``theta_2 = -(c3 + c4 s) theta_1`` (c3 under skid)."""
    return c3 + c4 * driving_slip(slip)
