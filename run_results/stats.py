"""Window statistics of one quantity: mean, standard deviation and an honest standard error.

The standard error is corrected for autocorrelation by the statistical inefficiency
(``stable_phase.autocorr``: integrated autocorrelation time with Geyer's initial positive
sequence; Sokal 1997, Geyer 1992; Flyvbjerg & Petersen 1989 for the equivalent blocking).

The grouser oscillation is deterministic and periodic: the window holds a whole number of
periods, so it adds nothing to the mean beyond the rounding of the period to samples. It
would, however, make the autocorrelation ring and inflate ``g`` for no statistical reason,
so it is removed (least-squares harmonic series at the measured passing frequency, see
``oscillation``) before ``g`` and the SE are computed. ``std`` is the plain spread of the
samples, oscillation included (what a single reading scatters by).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from stable_phase.autocorr import statistical_inefficiency


@dataclass(frozen=True)
class QuantityStats:
    """Mean, sample standard deviation, autocorrelation-corrected SE, samples, effective samples."""

    mean: float
    std: float
    se: float
    n: int
    n_eff: float
    unit: str

    def to_dict(self) -> dict:
        return asdict(self)


def quantity_stats(y, unit: str, periodic=None) -> QuantityStats | None:
    """Stats of ``y`` over the window; ``periodic`` (same length) is removed for the SE only.

    None when fewer than two samples are finite.
    """
    y = np.asarray(y, float)
    ok = np.isfinite(y)
    n = int(ok.sum())
    if n < 2:
        return None
    resid = y[ok] if periodic is None else y[ok] - np.nan_to_num(np.asarray(periodic)[ok])
    g = statistical_inefficiency(resid)
    se = float(np.std(resid, ddof=1) * np.sqrt(g / n))
    return QuantityStats(mean=float(np.mean(y[ok])), std=float(np.std(y[ok], ddof=1)), se=se,
                         n=n, n_eff=float(n / g), unit=unit)
