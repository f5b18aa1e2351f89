"""Side force of a steered wheel against its slip angle (the truth of ``steered`` runs).

A rigid rover wheel on loose sand builds side force with slip angle and saturates
within 10-20 degrees (Ishigami, Miwa, Nagatani & Yoshida 2007, "Terramechanics-based
model for steering maneuver of planetary exploration rovers on loose soil", J. Field
Robotics 24(3), figs. 10-11). The testbed uses the saturating form
``F_y = mu_y W (1 - exp(-|beta| / beta_0)) sign(beta)``, positive towards the side the
wheel is steered to (wheel frame, y along the axle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LateralLaw:
    """Saturating side-force law: ``mu_y`` (side force / load at saturation), ``beta_0``."""

    side_force_ratio_max: float = 0.35
    slip_angle_scale_deg: float = 8.0

    def side_force_n(self, load_n, slip_angle_deg) -> np.ndarray:
        beta = np.asarray(slip_angle_deg, float)
        return (self.side_force_ratio_max * np.asarray(load_n, float)
                * (1.0 - np.exp(-np.abs(beta) / self.slip_angle_scale_deg)) * np.sign(beta))


DEFAULT_LATERAL = LateralLaw()
