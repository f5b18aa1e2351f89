"""Slip-dependent shear modulus and exit angle after Ding et al. (2015).

Ding, Deng, Gao, Tao, Iagnemma & Liu (2015) "Interaction mechanics model for rigid
driving wheels of planetary rovers moving on sandy terrain with consideration of
multiple physical effects", J. Field Robotics 32(6):827-859 (doi:10.1002/rob.21533),
after the single-wheel tests of Ding, Gao, Deng, Nagatani & Yoshida (2011), J.
Terramech. 48(1):27-45: for a driven wheel on sand the Janosi-Hanamoto shear
deformation modulus and the rear (exit) contact angle grow linearly with slip::

    K = K0 + K1 s                       (K0 = soil.shear_modulus_m, K1 = shear_modulus_slip_m)
    theta_2 = -(c3 + c4 s) theta_1      (here theta_2 < 0 is behind the vertical)

beside their ``theta_m = (c1 + c2 s) theta_1`` (Wong & Reece 1967) and ``N = n0 + n1 s``
(``effects/slip_sinkage_ding2011.py``). A reading of the trend (swtlab's, not the
paper's words): at low slip the rim shears a thin, stiff zone and the thrust builds up
at once; at higher slip the sheared zone deepens and the soil flows, so the same
displacement mobilises less of the strength. Ding et al. identified the coefficients
per wheel on their lunar simulant at slips 0-0.6. The form is quoted as cited; the
paper's coefficient values are not in the sources swtlab could read, so ``K1`` and
``c4`` default to 0 (the constant-K Wong-Reece model) and any value used is fitted. On
the Ding et al. 2011 smooth wheel at 80 N (``bench/bench_ding2011.py``, kc and kphi
scaled to its zero-slip sinkage) the fit gives K0 = 3.6 mm, K1 = 17.8 mm, which passes
through the paper's K = 9.7-13.1 mm at s = 0.34-0.53 and holds on their 10 mm lug wheel
(held out); c4 fitted there ends on its bound 0. It holds for driven rigid wheels on
dry sand-like simulants at slips 0-0.6; the skid branch (Wong & Reece 1967 part II)
keeps K0 and c3.
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
