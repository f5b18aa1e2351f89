"""Whether a soil-flow measurement holds: sled velocity, each decay fit, the contact region.

A measurement that fails is an error (:class:`FlowMeasurementError`), never a result
of blanks: ``swtlab flow`` exits non-zero and ``swtlab process`` stores a
``soil_flow_failure`` row with the reason. A single angle whose profile cannot be
fitted is kept as a ``None`` fit with its reason in words.

Thresholds: a component's rate is defined where its rim velocity is at least 30 % of
the travel velocity (swtlab issue 21; for ``v_r`` the rim value is ``V sin(theta)``,
for ``v_theta`` the fitted rim amplitude ``V cos(theta) - R omega``); a fit is kept
with R² >= 0.5 and a 95 % CI narrower than the rate itself (half-width < 50 %).
An estimated ``eps_vol^P`` is resolved where its uncertainty bound
(:func:`softflow.volumetric_strain.strain_by_beta`, plus ``FLOW_FIELD_ERROR``) is at most
0.01 (issue 21: sand compacts by about 0.01-0.15); only resolved bins go into alpha1 and
alpha2.
"""

from __future__ import annotations

import numpy as np

from softflow.decay_fit import DecayFit
from swtlab_base.errors import InputError

MIN_RIM_FRACTION = 0.3
MIN_R2 = 0.5
MAX_CI_HALF_FRACTION = 0.5
#: far soil moves along the travel direction: a vertical part above this fraction is implausible
MAX_VERTICAL_FRACTION = 0.1
#: spread (IQR / 1.349 of the far-field speed along travel) above this fraction: not one motion
MAX_FAR_SPREAD_FRACTION = 0.1
#: largest uncertainty bound of an estimated eps_vol^P that counts as resolved
EPS_RESOLUTION = 0.01
#: contact region of the checks, image angle beta (deg): below the axle
CONTACT_BETA_DEG = (-160.0, -20.0)


class FlowMeasurementError(InputError, ValueError):
    """The frames were read but the soil flow could not be measured from them."""


def check_sled_velocity(sled_mps: np.ndarray, spread_mps: float, direction: int) -> None:
    """Raise unless the far soil moves as one body along the travel direction."""
    vx, vy = float(sled_mps[0]), float(sled_mps[1])
    where = f"sled velocity ({vx:.4f}, {vy:.4f}) m/s"
    if not (np.isfinite(vx) and np.isfinite(vy)) or vx * direction <= 0:
        raise FlowMeasurementError(f"implausible {where}: the far soil does not move against "
                                   f"the travel direction ({'+x' if direction > 0 else '-x'})")
    if abs(vy) > MAX_VERTICAL_FRACTION * abs(vx):
        raise FlowMeasurementError(f"implausible {where}: vertical part above "
                                   f"{MAX_VERTICAL_FRACTION:.0%} of the horizontal")
    if spread_mps > MAX_FAR_SPREAD_FRACTION * abs(vx):
        raise FlowMeasurementError(f"implausible {where}: the far-field soil speed spreads by "
                                   f"{spread_mps:.4f} m/s (> {MAX_FAR_SPREAD_FRACTION:.0%})")


def fit_reason(fit: DecayFit | None, points: int, rim_fraction: float) -> str | None:
    """Why a bin's rate is not reported (None: it is). ``rim_fraction``: |rim velocity| / |V|."""
    if fit is None:
        return f"no fit ({points} profile points; at least 5 and a converged fit needed)"
    if rim_fraction < MIN_RIM_FRACTION:
        return (f"not defined: rim velocity {rim_fraction:.0%} of the travel velocity "
                f"(< {MIN_RIM_FRACTION:.0%})")
    if fit.rate_per_m <= 0:
        return f"the profile does not decay (rate {fit.rate_per_m:.1f} /m)"
    if fit.r2 < MIN_R2:
        return f"not exponential (R2 {fit.r2:.2f} < {MIN_R2})"
    half = (fit.ci95_per_m[1] - fit.ci95_per_m[0]) / 2
    if half > MAX_CI_HALF_FRACTION * fit.rate_per_m:
        return f"rate not resolved (95 % CI +-{half:.1f} /m on {fit.rate_per_m:.1f} /m)"
    return None


def eps_reason(eps: float, bound: float) -> str | None:
    """Why an estimated bin's ``eps_vol^P`` is not resolved (None: it is)."""
    if not np.isfinite(eps):
        return "no value (no streamline from undisturbed soil upstream)"
    if not np.isfinite(bound):
        return "no uncertainty bound (no value at twice the smoothing scale)"
    if bound > EPS_RESOLUTION:
        return (f"not resolvable: {eps:.3f} +- {bound:.3f} (smoothing bias, scatter, strain "
                f"left upstream, flow-field error; > {EPS_RESOLUTION})")
    return None


def alpha12_reason(eps_reasons: list, k_ok: np.ndarray) -> str:
    """Why alpha1 and alpha2 are not given: fewer than 3 bins with a resolved eps and a k."""
    with_k = [r for r, ok in zip(eps_reasons, k_ok) if ok]
    unresolved = sum(1 for r in with_k if r and r.startswith("not resolvable"))
    usable = sum(1 for r in with_k if r is None)
    if unresolved:
        return (f"eps_vol^P not resolvable to {EPS_RESOLUTION} in {unresolved} of the "
                f"{len(with_k)} bins with a k fit ({usable} left, 3 needed)")
    return f"fewer than 3 bins with both eps_vol^P and a k fit ({usable})"


def in_contact(beta_rad: np.ndarray) -> np.ndarray:
    deg = np.rad2deg(beta_rad)
    return (deg > CONTACT_BETA_DEG[0]) & (deg < CONTACT_BETA_DEG[1])


def check_contact_fits(beta_rad: np.ndarray, radial: list, tangential: list) -> None:
    """Raise when no bin of the contact region has a rate of either component."""
    if not any(radial[i] or tangential[i] for i in np.flatnonzero(in_contact(beta_rad))):
        lo, hi = CONTACT_BETA_DEG
        raise FlowMeasurementError(f"no decay rate could be fitted in the contact region "
                                   f"(beta {lo:.0f} to {hi:.0f} deg)")
