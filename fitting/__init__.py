"""Performance-curve fits: weighted least-squares polynomials in slip per (wheel, soil,
multipass, load) and quantity, degree 3-7 set or chosen, with a braked branch (step and
slope below zero slip) where the data call for one, with diagnostics; the curve at any
load by interpolation across the tested loads; the 120 N-style validation of it.

Method after RUAG's Wheel Parametric Analytical Tool (WPAT) and Wheel Performance Module
(WPM). Pure functions on tables and arrays; see docs/fitting.md.
"""

from fitting.band import band
from fitting.curve import DEGREES, QUANTITY_UNITS, CurveFit, PowerCurve
from fitting.errors import (DegreeError, FittingError, LoadExtrapolationWarning, LoadRangeError,
                            OutsideSlipRangeWarning, TooFewPointsError)
from fitting.fit import fit_curve
from fitting.load_interp import InterpolatedCurve, LoadCurves, interpolate_load, interpolate_loads
from fitting.table import (curves_by_load, fit_results, from_run_results, quantities_in,
                           with_dp_over_w)
from fitting.validation import ValidationResult, validate_load_interpolation

__all__ = [
    "DEGREES", "QUANTITY_UNITS", "band", "CurveFit", "DegreeError", "FittingError", "InterpolatedCurve",
    "LoadCurves", "LoadExtrapolationWarning", "LoadRangeError", "OutsideSlipRangeWarning",
    "PowerCurve", "TooFewPointsError", "ValidationResult", "curves_by_load", "fit_curve",
    "fit_results", "from_run_results", "interpolate_load", "interpolate_loads", "quantities_in",
    "validate_load_interpolation", "with_dp_over_w",
]
