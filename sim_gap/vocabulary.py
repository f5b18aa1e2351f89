"""Names shared by the gap diagnosis: quantities, effects, slip bands, uncertainty floors."""

from __future__ import annotations

import numpy as np

from terramechanics import EFFECTS

#: measured quantities compared with the simulation (SI units in the names)
QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")
#: the fixed verdict vocabulary: the effects of the built-in model (terramechanics.EFFECTS)
EFFECT_NAMES = tuple(EFFECTS)
#: slip bands of the residual map (left-closed; the last one closed)
SLIP_BAND_EDGES = np.array([-1.0, 0.0, 0.2, 0.4, 0.6, 1.0])


def slip_band_labels() -> list[str]:
    e = SLIP_BAND_EDGES
    return [f"[{e[i]:.1f},{e[i + 1]:.1f})" for i in range(len(e) - 1)]


def slip_band(slip: np.ndarray) -> np.ndarray:
    """Index of each slip's band in :data:`SLIP_BAND_EDGES` (slips outside are clipped)."""
    idx = np.searchsorted(SLIP_BAND_EDGES, np.asarray(slip, dtype=float), side="right") - 1
    return np.clip(idx, 0, len(SLIP_BAND_EDGES) - 2)


def model_error_floor(quantity: str, load_n: np.ndarray, radius_m: float) -> np.ndarray:
    """Assumed run-to-run repeatability, added in quadrature to a measurement's own
    uncertainty when fitting where the source did not measure it (no replicates): 1 % of
    the wheel load for forces (torque: times the radius), 0.3 mm for sinkage; soil
    preparation and transients that one run's uncertainty budget does not contain."""
    load_n = np.asarray(load_n, dtype=float)
    if quantity == "sinkage_m":
        return np.full(load_n.shape, 3e-4)
    if quantity == "torque_nm":
        return 0.01 * load_n * radius_m + 0.05
    return 0.01 * load_n + 0.3
