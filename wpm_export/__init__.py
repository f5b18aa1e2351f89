"""WPM export: fitted curves as a WPM CSV (docs/wpm-csv.md) and the Wheel Performance Module
that answers from one (curve at a load, quantities at a slip, the slip for a required DP,
torque, sinkage or resistance), after RUAG's Wheel Performance Module."""

from wpm_export.inverse import SlipSolution, solve_slip
from wpm_export.reader import WpmCurve, parse_wpm_csv, read_wpm_csv
from wpm_export.runtime import WheelPerformanceModule
from wpm_export.schema import COLUMNS, FORMAT, UNITS, WpmFormatError, WpmSelectionError
from wpm_export.writer import inputs_sha256, wpm_csv_text, write_wpm_csv

__all__ = [
    "COLUMNS", "FORMAT", "SlipSolution", "UNITS", "WheelPerformanceModule", "WpmCurve",
    "WpmFormatError", "WpmSelectionError", "inputs_sha256", "parse_wpm_csv", "read_wpm_csv",
    "solve_slip", "wpm_csv_text", "write_wpm_csv",
]
