"""Read a WPM CSV (docs/wpm-csv.md), ours or another tool's; every deviation from the page is
a :class:`WpmFormatError` naming file, line and problem, never a silently different curve."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path

from fitting.curve import DEGREES, PowerCurve
from swtlab_base.domain import Wheel
from wpm_export.schema import (BRANCH_COLUMNS, COEFFICIENT_COLUMNS, COLUMNS, FORMAT,
                               UNCERTAINTY_COLUMNS, UNITS, WHEEL_GEOMETRY_KEY, WHEEL_KEYS,
                               WpmFormatError)

#: the column headers a reader accepts: today's, without the uncertainty, without the branch
HEADERS = (COLUMNS + BRANCH_COLUMNS + UNCERTAINTY_COLUMNS, COLUMNS + BRANCH_COLUMNS, COLUMNS)


@dataclass(frozen=True)
class WpmCurve(PowerCurve):
    """One row of a WPM CSV: ``sum_i a_i slip**i + [slip < 0] (J + K slip)`` on
    [slip_min, slip_max], with its uncertainty where the file carries it (``covariance``
    None and NaN ``k95``, ``scatter_sd`` where not: unknown)."""

    soil: str
    wheel: str
    multipass: int
    load_n: float
    quantity: str
    unit: str
    n_points: int
    rmse: float
    line: int


def _number(text: str, column: str, problem) -> float:
    try:
        value = float(text)
    except ValueError:
        raise problem(f"{column} {text!r} is not a number") from None
    if not math.isfinite(value):
        raise problem(f"{column} {text!r} is not finite")
    return value


def _integer(text: str, column: str, problem) -> int:
    try:
        return int(text)
    except ValueError:
        raise problem(f"{column} {text!r} is not an integer") from None


def _curve(fields: list[str], problem, line: int, columns: tuple[str, ...]) -> WpmCurve:
    """One data row -> curve, every rule of the page checked; ``columns``: the file's."""
    if len(fields) != len(columns):
        raise problem(f"{len(fields)} fields, the format has {len(columns)}")
    row = dict(zip(columns, (f.strip() for f in fields)))
    if not row["soil"] or not row["wheel"]:
        raise problem("soil and wheel must not be empty")
    quantity = row["quantity"]
    if quantity not in UNITS:
        raise problem(f"unknown quantity {quantity!r}; known: {', '.join(UNITS)}")
    if row["unit"] != UNITS[quantity]:
        raise problem(f"unit {row['unit']!r} for {quantity}; the format says {UNITS[quantity]!r}")
    degree = _integer(row["degree"], "degree", problem)
    if degree not in DEGREES:
        raise problem(f"degree {degree} outside 3-7")
    multipass = _integer(row["multipass"], "multipass", problem)
    load_n = _number(row["load_n"], "load_n", problem)
    slip_min = _number(row["slip_min"], "slip_min", problem)
    slip_max = _number(row["slip_max"], "slip_max", problem)
    if multipass < 0 or load_n <= 0:
        raise problem(f"multipass {multipass} must be >= 0 and load_n {load_n:g} > 0")
    if not -1.0 <= slip_min < slip_max <= 1.0:
        raise problem(f"slip range [{slip_min:g}, {slip_max:g}]: need -1 <= slip_min < "
                      "slip_max <= 1")
    used = COEFFICIENT_COLUMNS[:degree + 1]
    coefficients = tuple(_number(row[c], c, problem) for c in used)
    for c in COEFFICIENT_COLUMNS[degree + 1:]:
        if row[c] and _number(row[c], c, problem) != 0.0:
            raise problem(f"{c} = {row[c]} beyond degree {degree} (must be empty or 0)")
    n_points = _integer(row["n_points"], "n_points", problem)
    if n_points < degree + 1:
        raise problem(f"n_points {n_points} < degree + 1 = {degree + 1}: underdetermined fit")
    rmse = _number(row["rmse"], "rmse", problem)
    if rmse < 0:
        raise problem(f"rmse {rmse:g} < 0")
    step, slope = (_number(row[c], c, problem) if c in row else 0.0 for c in BRANCH_COLUMNS)
    return WpmCurve(coefficients=coefficients, slip_min=slip_min, slip_max=slip_max,
                    step_below_zero=step, slope_below_zero=slope,
                    **_uncertainty(row, degree, problem),
                    soil=row["soil"], wheel=row["wheel"], multipass=multipass, load_n=load_n,
                    quantity=quantity, unit=row["unit"], n_points=n_points, rmse=rmse, line=line)


def _uncertainty(row: dict[str, str], degree: int, problem) -> dict:
    """``k95``, ``scatter_sd``, ``covariance`` of a row (docs/wpm-csv.md, "Uncertainty"):
    all three empty (or absent) = unknown; else k95 > 0, scatter_sd >= 0 and the
    (degree + 3)(degree + 4)/2 numbers of the upper triangle, diagonal >= 0."""
    fields = [row.get(c, "") for c in UNCERTAINTY_COLUMNS]
    if not any(fields):
        return {}
    if not all(fields):
        raise problem(f"{', '.join(UNCERTAINTY_COLUMNS)}: give all three or none")
    k95 = _number(fields[0], "k95", problem)
    scatter = _number(fields[1], "scatter_sd", problem)
    if k95 <= 0 or scatter < 0:
        raise problem(f"k95 {k95:g} must be > 0 and scatter_sd {scatter:g} >= 0")
    upper = [_number(v, "covariance", problem) for v in fields[2].split()]
    m = degree + 3
    if len(upper) != m * (m + 1) // 2:
        raise problem(f"covariance has {len(upper)} numbers; degree {degree} needs "
                      f"{m * (m + 1) // 2} (upper triangle of {m} x {m})")
    matrix = [[0.0] * m for _ in range(m)]
    k = 0
    for i in range(m):
        for j in range(i, m):
            matrix[i][j] = matrix[j][i] = upper[k]
            k += 1
    if any(matrix[i][i] < 0 for i in range(m)):
        raise problem("covariance has a negative variance on its diagonal")
    return {"k95": k95, "scatter_sd": scatter,
            "covariance": tuple(tuple(r) for r in matrix)}


def wheel_geometry(header: dict[str, str], path="<text>", line: int = 0) -> dict[str, Wheel]:
    """Wheel name -> :class:`swtlab_base.domain.Wheel` from the header key ``wheel_geometry``
    (empty for a file without it: older files and other tools' may lack it)."""
    text = header.get(WHEEL_GEOMETRY_KEY)
    if text is None:
        return {}
    try:
        table = json.loads(text)
    except json.JSONDecodeError as exc:
        raise WpmFormatError(path, line, f"{WHEEL_GEOMETRY_KEY} is not JSON: {exc}") from None
    if not isinstance(table, dict) or not all(isinstance(v, dict) for v in table.values()):
        raise WpmFormatError(path, line, f"{WHEEL_GEOMETRY_KEY} must map each wheel name to "
                                         f"its {', '.join(WHEEL_KEYS)}")
    out = {}
    for name, values in table.items():
        missing = [k for k in WHEEL_KEYS if k not in values]
        unknown = sorted(set(values) - set(WHEEL_KEYS))
        if missing or unknown:
            raise WpmFormatError(path, line, f"{WHEEL_GEOMETRY_KEY} of wheel {name!r}: "
                                             f"missing {missing}, unknown {unknown}")
        try:
            out[name] = Wheel(name=name, **values)
        except ValueError as exc:
            raise WpmFormatError(path, line, f"{WHEEL_GEOMETRY_KEY}: {exc}") from None
    return out


def parse_wpm_csv(text: str, path="<text>") -> tuple[dict[str, str], list[WpmCurve]]:
    """``(header, curves)`` of WPM CSV text; ``header`` maps the comment keys to values.
    The ``wheel_geometry`` header, when there, must give every curve's wheel."""
    header: dict[str, str] = {}
    lines: dict[str, int] = {}
    curves: list[WpmCurve] = []
    seen: dict[tuple, int] = {}
    columns_line, columns = 0, COLUMNS
    for number, raw in enumerate(text.splitlines(), start=1):
        def problem(message: str, _n=number) -> WpmFormatError:
            return WpmFormatError(path, _n, message)
        if not raw.strip():
            continue
        if not columns_line:
            if raw.startswith("#"):
                key, sep, value = raw[1:].partition(":")
                if not sep:
                    raise problem("header comment must read '# key: value'")
                header[key.strip()] = value.strip()
                lines[key.strip()] = number
                if len(header) == 1 and key.strip() != "format":
                    raise problem(f"first line must be '# format: {FORMAT}'")
                continue
            if header.get("format") != FORMAT:
                raise problem(f"missing '# format: {FORMAT}' line before the column header"
                              if "format" not in header else
                              f"format {header['format']!r}, this reader reads {FORMAT!r}")
            columns = tuple(f.strip() for f in next(csv.reader([raw])))
            if columns not in HEADERS:
                raise problem(f"column header must be {','.join(HEADERS[0])} (or without "
                              f"{', '.join(UNCERTAINTY_COLUMNS)}, or without those and "
                              f"{', '.join(BRANCH_COLUMNS)})")
            columns_line = number
            continue
        curve = _curve(next(csv.reader([raw])), problem, number, columns)
        key = (curve.soil, curve.wheel, curve.multipass, curve.load_n, curve.quantity)
        if key in seen:
            raise problem(f"duplicate curve {key} (also line {seen[key]})")
        seen[key] = number
        curves.append(curve)
    if not columns_line:
        raise WpmFormatError(path, 0, "no column header" if header else
                             f"empty file: no '# format: {FORMAT}' line")
    if not curves:
        raise WpmFormatError(path, columns_line, "no curve rows after the column header")
    wheels = wheel_geometry(header, path, lines.get(WHEEL_GEOMETRY_KEY, 0))
    lacking = sorted({c.wheel for c in curves} - set(wheels))
    if wheels and lacking:
        raise WpmFormatError(path, lines[WHEEL_GEOMETRY_KEY],
                             f"{WHEEL_GEOMETRY_KEY} lacks wheel(s) {lacking} of the curves")
    return header, curves


def read_wpm_csv(path) -> tuple[dict[str, str], list[WpmCurve]]:
    """Read a WPM CSV file; raises :class:`WpmFormatError` (also for a non-UTF-8 file)."""
    data = Path(path).read_bytes()
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise WpmFormatError(path, data[:exc.start].count(b"\n") + 1, "not UTF-8") from None
    return parse_wpm_csv(text, path)
