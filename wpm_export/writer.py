"""Write fitted curves as a WPM CSV (docs/wpm-csv.md) and hash the inputs they came from."""

from __future__ import annotations

import csv
import hashlib
import io
import json
from collections.abc import Iterable

import numpy as np
import pandas as pd

from fitting.curve import CurveFit
from fitting.table import KEY_COLUMNS, MEASURED
from wpm_export.reader import parse_wpm_csv
from swtlab_base.atomic import write_atomically
from swtlab_base.domain import Wheel
from wpm_export.schema import (BRANCH_COLUMNS, COLUMNS, FORMAT, MAX_DEGREE,
                               UNCERTAINTY_COLUMNS, UNITS, WHEEL_GEOMETRY_KEY, WHEEL_KEYS)

#: the columns of a results table the fits read, in the order they are hashed
HASHED_COLUMNS = (KEY_COLUMNS + ("slip", "slip_se", "wheel_load_n", "wheel_load_n_se")
                  + tuple(c for q in MEASURED for c in (q, f"{q}_se")))


def _text(value) -> str:
    """Exact, locale-free text of a table cell: shortest round-trip repr for numbers."""
    if isinstance(value, str):
        return value
    if pd.isna(value):
        return "nan"
    return repr(float(value))


def inputs_sha256(results_table: pd.DataFrame) -> str:
    """sha256 of the fitted inputs: the columns of :data:`HASHED_COLUMNS` present, in that
    order, rows sorted, numbers as shortest round-trip decimals (so row order, extra columns
    and int-vs-float storage do not change it)."""
    cols = [c for c in HASHED_COLUMNS if c in results_table]
    table = results_table[cols].copy()
    for c in cols:
        if c in ("wheel", "soil"):
            table[c] = table[c].astype(str)
        elif c == "multipass":
            table[c] = table[c].astype(int)
        else:
            table[c] = table[c].astype(float)
    rows = sorted(",".join(_text(v) for v in row)
                  for row in table.itertuples(index=False, name=None))
    return hashlib.sha256("\n".join([",".join(cols), *rows]).encode()).hexdigest()


def _row(fit: CurveFit) -> list[str]:
    coefficients = [repr(float(a)) for a in fit.coefficients]
    return [fit.soil, fit.wheel, str(int(fit.multipass)), repr(float(fit.load_n)), fit.quantity,
            UNITS[fit.quantity], str(fit.degree), repr(float(fit.slip_min)),
            repr(float(fit.slip_max)), *coefficients, *[""] * (MAX_DEGREE + 1 - len(coefficients)),
            str(int(fit.n_points)), repr(float(fit.rmse)),
            repr(float(fit.step_below_zero)), repr(float(fit.slope_below_zero)),
            *_uncertainty(fit)]


def _uncertainty(fit: CurveFit) -> list[str]:
    """``k95``, ``scatter_sd`` and the covariance's upper triangle (row-major, space
    separated); three empty fields for a curve without uncertainty."""
    if fit.covariance is None:
        return ["", "", ""]
    c = np.asarray(fit.covariance, dtype=float)
    upper = c[np.triu_indices(c.shape[0])]
    return [repr(float(fit.k95)), repr(float(fit.scatter_sd)),
            " ".join(repr(float(v)) for v in upper)]


def _geometry(wheels: dict[str, Wheel], names: set[str]) -> str:
    lacking = sorted(names - set(wheels))
    if lacking:
        raise ValueError(f"no geometry for wheel(s) {lacking}: the WPM CSV carries each "
                         "curve's wheel (radius, width, grousers, stiffness)")
    return json.dumps({name: {k: getattr(wheels[name], k) for k in WHEEL_KEYS}
                       for name in sorted(names)}, separators=(", ", ": "))


def wpm_csv_text(fits: Iterable[CurveFit], inputs_sha256: str, swtlab_version: str,
                 created: str | None = None, wheels: dict[str, Wheel] | None = None) -> str:
    """The WPM CSV as text: header comments, column row, one row per curve sorted by
    (soil, wheel, multipass, load_n, quantity in the format's order). ``wheels`` (name ->
    geometry) must hold every curve's wheel. The text is read back before it is returned, so
    nothing the reader would refuse is ever written."""
    order = {q: i for i, q in enumerate(UNITS)}
    rows = sorted(fits, key=lambda f: (f.soil, f.wheel, f.multipass, f.load_n, order[f.quantity]))
    out = io.StringIO()
    out.write(f"# format: {FORMAT}\n# swtlab_version: {swtlab_version}\n"
              f"# inputs_sha256: {inputs_sha256}\n")
    if created:
        out.write(f"# created: {created}\n")
    if wheels is not None:
        out.write(f"# {WHEEL_GEOMETRY_KEY}: {_geometry(wheels, {f.wheel for f in rows})}\n")
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS + BRANCH_COLUMNS + UNCERTAINTY_COLUMNS)
    writer.writerows(_row(f) for f in rows)
    parse_wpm_csv(out.getvalue(), "<WPM CSV being written>")
    return out.getvalue()


def write_wpm_csv(fits: Iterable[CurveFit], path, inputs_sha256: str, swtlab_version: str,
                  created: str | None = None, wheels: dict[str, Wheel] | None = None) -> str:
    """Write the WPM CSV to ``path`` (UTF-8, ``\\n`` line ends) atomically
    (``swtlab_base.atomic``); return the file's sha256."""
    data = wpm_csv_text(fits, inputs_sha256, swtlab_version, created, wheels).encode("utf-8")
    write_atomically(path, data)
    return hashlib.sha256(data).hexdigest()
