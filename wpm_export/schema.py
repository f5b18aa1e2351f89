"""The WPM CSV format ``swtlab-wpm/1`` (docs/wpm-csv.md): columns, quantities, errors."""

from __future__ import annotations

from fitting.curve import DEGREES, QUANTITY_UNITS
from swtlab_base.errors import InputError

FORMAT = "swtlab-wpm/1"
MAX_DEGREE = max(DEGREES)
COEFFICIENT_COLUMNS = tuple(f"a{i}" for i in range(MAX_DEGREE + 1))
COLUMNS = (("soil", "wheel", "multipass", "load_n", "quantity", "unit", "degree", "slip_min",
            "slip_max") + COEFFICIENT_COLUMNS + ("n_points", "rmse"))
#: the braked branch ``[slip < 0] (J + K slip)`` (docs/fitting.md), written after the others;
#: a file without them (older swtlab, other tools) reads as J = K = 0
BRANCH_COLUMNS = ("step_below_zero", "slope_below_zero")
#: the curve's uncertainty (docs/wpm-csv.md, "Uncertainty"), written after the branch: the
#: 95 % factor, the run-to-run SD and the upper triangle of the covariance of
#: (a0 ... a_n, J, K); a file without them reads as unknown uncertainty
UNCERTAINTY_COLUMNS = ("k95", "scatter_sd", "covariance")
UNITS = QUANTITY_UNITS  # dp_n N, torque_nm N*m, sinkage_m m, resistance_n N, dp_over_w 1
#: header key of the wheels' geometry (JSON: name -> WHEEL_KEYS)
WHEEL_GEOMETRY_KEY = "wheel_geometry"
WHEEL_KEYS = ("radius_m", "width_m", "grouser_count", "grouser_height_m", "stiffness_n_per_mm")


class WpmFormatError(InputError, ValueError):
    """A WPM CSV that does not follow docs/wpm-csv.md; names file, line and problem."""

    def __init__(self, path, line: int, problem: str) -> None:
        super().__init__(f"{path}:{line}: {problem}")
        self.path, self.line, self.problem = str(path), line, problem


class WpmSelectionError(InputError, ValueError):
    """A query the loaded curves cannot answer unambiguously (no or several matching curve
    sets, a quantity the set lacks); lists the choices."""
