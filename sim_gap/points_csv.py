"""The points CSV (docs/points-csv.md): one row per condition of one source (a campaign, a
paper's curve, another tool's output), with the wheel, the load, multipass, gravity, slip
and each quantity's mean with its standard error or spread. Read for either side of the
gap diagnosis; recognised by its column header (``source``, ``slip``, ``wheel_radius_m``).
"""

from __future__ import annotations

import csv
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

from sim_gap.vocabulary import QUANTITIES
from swtlab_base.domain import G0_MPS2, Wheel
from swtlab_base.errors import InputError

#: columns every points CSV has
REQUIRED = ("source", "wheel_radius_m", "wheel_width_m", "load_set_n", "slip")
#: optional columns and their value when absent or empty (None: per row, see the docs)
OPTIONAL = {"run_id": None, "wheel_name": None, "grouser_count": 0, "grouser_height_m": 0.0,
            "wheel_stiffness_n_per_mm": None, "wheel_load_n": None, "multipass": 0,
            "gravity_mps2": G0_MPS2, "n_repeats": None}
#: per quantity: the mean, and its standard error or its spread (standard deviation)
QUANTITY_COLUMNS = tuple(c for q in QUANTITIES for c in (q, f"{q}_se", f"{q}_sd"))
#: the geometry that makes two rows the same wheel (stiffness is an effect parameter)
WHEEL_KEY = ("wheel_radius_m", "wheel_width_m", "grouser_count", "grouser_height_m")


class PointsFormatError(InputError, ValueError):
    """A points CSV problem: ``file:line: column: problem`` on one line."""


class TowedTorqueWarning(UserWarning):
    """A towed row (slip <= 0) with a torque of exactly 0: most likely the zero a paper
    prints for a towed wheel by convention, which the diagnosis would take as measured."""


def header_of(path: str | Path) -> list[str] | None:
    """The column names of the first row that is neither blank nor a ``#`` comment."""
    with open(path, encoding="utf-8-sig") as f:
        for raw in f:
            if raw.strip() and not raw.startswith("#"):
                return [c.strip() for c in next(csv.reader([raw]))]
    return None


def is_points_csv(path: str | Path) -> bool:
    cols = header_of(path) or []
    return {"source", "slip", "wheel_radius_m"} <= set(cols)


def _number(text: str, where: str, minimum: float | None = None, strict: bool = False,
            integer: bool = False) -> float:
    try:
        value = float(text)
    except ValueError:
        raise PointsFormatError(f"{where}: {text!r} is not a number") from None
    if not math.isfinite(value):
        raise PointsFormatError(f"{where}: {text!r} is not finite")
    if integer and value != int(value):
        raise PointsFormatError(f"{where}: {text!r} is not an integer")
    if minimum is not None and (value < minimum or (strict and value == minimum)):
        raise PointsFormatError(f"{where}: {value:g} must be {'>' if strict else '>='} "
                                f"{minimum:g}")
    return value


#: (minimum, strictly above, integer) of each numeric column
_LIMITS = {"wheel_radius_m": (0.0, True, False), "wheel_width_m": (0.0, True, False),
           "grouser_count": (0.0, False, True), "grouser_height_m": (0.0, False, False),
           "wheel_stiffness_n_per_mm": (0.0, True, False), "load_set_n": (0.0, True, False),
           "wheel_load_n": (0.0, True, False), "multipass": (0.0, False, True),
           "gravity_mps2": (0.0, True, False), "n_repeats": (1.0, False, True),
           "slip": (-1.0, False, False)}


def read_points_csv(path: str | Path, uncertainty: bool = True) -> pd.DataFrame:
    """The rows of a points CSV as a table: ``run_id``, ``source``, ``wheel_name``, the
    wheel columns, ``load_set_n``, ``wheel_load_n``, ``multipass``, ``gravity_mps2``,
    ``slip`` and ``<q>``, ``<q>_se`` for each quantity given. A spread becomes an SE
    (``sd / sqrt(n_repeats)``, the sd itself without ``n_repeats``). ``uncertainty``: each
    quantity needs its SE or spread (measured side); without, they may be left out
    (a simulation's). Raises :class:`PointsFormatError`."""
    path = str(path)
    try:
        lines = Path(path).read_text(encoding="utf-8-sig").splitlines()
    except UnicodeDecodeError:
        raise PointsFormatError(f"{path}: not UTF-8 text") from None
    rows = [(n, raw) for n, raw in enumerate(lines, start=1)
            if raw.strip() and not raw.startswith("#")]
    if not rows:
        raise PointsFormatError(f"{path}: no column header")
    header_line, header = rows[0][0], [c.strip() for c in next(csv.reader([rows[0][1]]))]
    known = set(REQUIRED) | set(OPTIONAL) | set(QUANTITY_COLUMNS)
    for col in header:
        if col not in known:
            raise PointsFormatError(f"{path}:{header_line}: column {col!r}: unknown column "
                                    f"(known: {', '.join(REQUIRED + tuple(OPTIONAL))}, and "
                                    "per quantity <q>, <q>_se or <q>_sd)")
    if len(set(header)) != len(header):
        raise PointsFormatError(f"{path}:{header_line}: a column appears twice")
    for col in REQUIRED:
        if col not in header:
            raise PointsFormatError(f"{path}:{header_line}: column {col!r}: missing")
    quantities = [q for q in QUANTITIES if q in header]
    if not quantities:
        raise PointsFormatError(f"{path}:{header_line}: no quantity column (one of "
                                f"{', '.join(QUANTITIES)})")
    for q in QUANTITIES:
        have = [c for c in (f"{q}_se", f"{q}_sd") if c in header]
        if q in header and len(have) != 1 and (uncertainty or have):
            raise PointsFormatError(f"{path}:{header_line}: column {q!r}: needs exactly one "
                                    f"of {q}_se (standard error) or {q}_sd (spread)")
        if q not in header and have:
            raise PointsFormatError(f"{path}:{header_line}: column {have[0]!r}: without "
                                    f"its mean column {q!r}")
    if len(rows) == 1:
        raise PointsFormatError(f"{path}:{header_line}: no data row after the column header")
    out = [_row(path, n, header, raw, quantities) for n, raw in rows[1:]]
    table = pd.DataFrame(out)
    _one_wheel_per_source(path, table, [n for n, _ in rows[1:]])
    return table


def _row(path: str, number: int, header: list[str], raw: str, quantities: list[str]) -> dict:
    cells = [c.strip() for c in next(csv.reader([raw]))]
    if len(cells) != len(header):
        raise PointsFormatError(f"{path}:{number}: {len(cells)} cells, the header has "
                                f"{len(header)} columns")
    cell = dict(zip(header, cells))
    where = lambda col: f"{path}:{number}: column {col!r}"  # noqa: E731
    row: dict = {}
    for col in REQUIRED[1:] + tuple(OPTIONAL):
        text = cell.get(col, "")
        if col in ("run_id", "wheel_name"):
            row[col] = text or None
        elif not text:
            if col in REQUIRED:
                raise PointsFormatError(f"{where(col)}: empty")
            row[col] = OPTIONAL[col]
        else:
            lo, strict, integer = _LIMITS[col]
            row[col] = _number(text, where(col), lo, strict, integer)
    if not cell["source"]:
        raise PointsFormatError(f"{where('source')}: empty")
    if row["slip"] > 1.0:
        raise PointsFormatError(f"{where('slip')}: {row['slip']:g} must be <= 1")
    row["source"] = cell["source"]
    row["run_id"] = row["run_id"] or f"{cell['source']}/line{number}"
    row["wheel_name"] = row["wheel_name"] or cell["source"]
    row["wheel_load_n"] = row["wheel_load_n"] or row["load_set_n"]
    row["grouser_count"] = int(row["grouser_count"])
    row["multipass"] = int(row["multipass"])
    measured = False
    for q in quantities:
        spread = f"{q}_se" if f"{q}_se" in cell else f"{q}_sd"
        if spread not in cell:  # a simulation's quantity without uncertainty
            row[q], row[f"{q}_se"] = (_number(cell[q], where(q)) if cell[q] else np.nan), np.nan
            measured = measured or bool(cell[q])
            continue
        if not cell[q]:
            if cell[spread]:
                raise PointsFormatError(f"{where(spread)}: given without the mean {q!r}")
            row[q], row[f"{q}_se"] = np.nan, np.nan
            continue
        row[q] = _number(cell[q], where(q))
        if q == "torque_nm" and row[q] == 0.0 and row["slip"] <= 0.0:
            _warn_towed_torque(where(q), row["slip"])
        if not cell[spread]:
            raise PointsFormatError(f"{where(spread)}: empty, but {q!r} is given")
        value = _number(cell[spread], where(spread), 0.0)
        if spread.endswith("_sd") and row["n_repeats"]:
            value /= math.sqrt(row["n_repeats"])
            if row["n_repeats"] >= 2:  # the spread of repeats: measured repeatability
                row[f"{q}_repeat_sd"] = value
        row[f"{q}_se"] = value
        measured = True
    if not measured:
        raise PointsFormatError(f"{path}:{number}: no quantity measured on this row")
    del row["n_repeats"]
    return row


def _warn_towed_torque(where: str, slip: float) -> None:
    """A driven wheel at slip > 0 needs a torque > 0 (thrust T/r; Wong, Theory of Ground
    Vehicles, ch. 4), a braked one < 0; only a towed or free-rolling wheel (slip <= 0) has
    none applied, and a paper prints that torque as 0 by convention, not as a measurement."""
    warnings.warn(f"{where}: exactly 0 on a towed row (slip {slip:g} <= 0): if the paper "
                  "prints a towed wheel's torque as 0 by convention, leave the cell (and its "
                  "_se or _sd) blank; a 0 is taken as a measured torque", TowedTorqueWarning,
                  stacklevel=4)


def _one_wheel_per_source(path: str, table: pd.DataFrame, numbers: list[int]) -> None:
    for source, idx in table.groupby("source", sort=False).indices.items():
        first = table.iloc[idx[0]]
        for i in idx[1:]:
            for col in WHEEL_KEY + ("wheel_stiffness_n_per_mm", "wheel_name"):
                a, b = first[col], table.iloc[i][col]
                if not (a == b or (pd.isna(a) and pd.isna(b))):
                    raise PointsFormatError(
                        f"{path}:{numbers[i]}: column {col!r}: {b} differs from {a} on line "
                        f"{numbers[idx[0]]} of the same source {source!r} (one wheel per "
                        "source)")


def wheel_of(row: pd.Series) -> Wheel:
    """The :class:`swtlab_base.domain.Wheel` of a row of :func:`read_points_csv`."""
    stiffness = row.get("wheel_stiffness_n_per_mm")
    return Wheel(radius_m=float(row["wheel_radius_m"]), width_m=float(row["wheel_width_m"]),
                 grouser_count=int(row["grouser_count"]),
                 grouser_height_m=float(row["grouser_height_m"]),
                 stiffness_n_per_mm=None if pd.isna(stiffness) else float(stiffness),
                 name=str(row["wheel_name"]))
