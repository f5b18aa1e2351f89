"""Errors and warnings of the curve fits and the load interpolation."""

from __future__ import annotations

from swtlab_base.errors import InputError


class FittingError(InputError, ValueError):
    """Input a fit cannot honestly use; the message names the group, quantity and problem."""


class DegreeError(FittingError):
    """A polynomial degree outside 3-7 (the range of the RUAG WPAT paper)."""


class TooFewPointsError(FittingError):
    """Fewer distinct slips than the degree needs (degree + 2: degree + 1 to determine the
    polynomial, one more for its leave-one-out error)."""


class LoadRangeError(FittingError):
    """A load outside the tested loads without ``allow_extrapolation``, or no loads to use."""


class OutsideSlipRangeWarning(UserWarning):
    """A curve evaluated outside the slip range of the points it was fitted to."""


class LoadExtrapolationWarning(UserWarning):
    """A curve extrapolated beyond the tested loads (asked for with ``allow_extrapolation``)."""
