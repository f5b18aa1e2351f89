"""The Wheel Performance Module at run time: the curve at any load, every quantity at a slip,
and the slip that gives a required DP, torque, sinkage or resistance (RUAG WPM), from a WPM
CSV. Loads between the tested ones are interpolated on curve values exactly as in
:mod:`fitting.load_interp`; all queries are vectorised over numpy arrays.

Caches (docs/wpm-csv.md, "Embedding"): per (curve set, quantity) the curves' parameters as
an exact piecewise polynomial of load (:class:`fitting.load_interp.LoadPolynomial`); per
(curve set, quantity, load) asked for a second time, the curve there with its uncertainty and
its monotone inverse table (:class:`wpm_export.inverse_table.InverseTable`). Loads seen once,
and many loads in one call, go to the row solver (:func:`wpm_export.inverse.solve_slip`).
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable

import numpy as np

from fitting.band import band
from fitting.errors import OutsideSlipRangeWarning
from fitting.load_interp import InterpolatedCurve, LoadCurves, LoadPolynomial, interpolate_loads
from fitting.polynomial import curve_value, horner
from swtlab.domain import Wheel
from wpm_export.inverse import SlipSolution, solve_slip
from wpm_export.inverse_table import InverseTable
from wpm_export.reader import WpmCurve, read_wpm_csv, wheel_geometry
from wpm_export.schema import UNITS, WpmSelectionError

CurveSet = tuple[str, str, int]  # (soil, wheel, multipass)
TABLE_LOADS = 8  # a call with at most this many distinct loads uses (and builds) their tables
MAX_TABLES = 4096  # cached tables kept (oldest dropped first)

def _selection(soil, wheel, multipass) -> str:
    """A curve set as the keyword arguments that select it (``soil='ES-3', wheel='w1',
    multipass=0``, those given; the command line prints them as its flags)."""
    given = {"soil": soil, "wheel": wheel, "multipass": multipass}
    return ", ".join(f"{k}={v!r}" for k, v in given.items() if v is not None)


class WheelPerformanceModule:
    """Curves of one or more (soil, wheel, multipass) sets, each at its tested loads.

    ``load_method``: interpolation across load, ``"auto"`` (PCHIP with 3+ tested loads, else
    linear), ``"linear"`` or ``"pchip"``. Every query takes ``soil``, ``wheel``,
    ``multipass`` to pick the set (needed only when several sets match) and
    ``allow_extrapolation`` for loads outside the tested ones (warned, linear).
    """

    def __init__(self, curves: Iterable[WpmCurve], header: dict[str, str] | None = None,
                 source: str = "<curves>", load_method: str = "auto") -> None:
        self.header, self.source, self.load_method = dict(header or {}), source, load_method
        self.wheels: dict[str, Wheel] = wheel_geometry(self.header, source)
        self._sets: dict[CurveSet, dict[str, dict[float, WpmCurve]]] = {}
        self._polynomials: dict[tuple, LoadPolynomial] = {}
        self._tables: dict[tuple, tuple[InverseTable, InterpolatedCurve]] = {}
        self._seen: set[tuple] = set()
        self._fast: dict[tuple, tuple[InverseTable, InterpolatedCurve]] = {}
        for c in curves:
            by_quantity = self._sets.setdefault((c.soil, c.wheel, c.multipass), {})
            by_quantity.setdefault(c.quantity, {})[c.load_n] = c

    @classmethod
    def load(cls, path, load_method: str = "auto") -> WheelPerformanceModule:
        """Read a WPM CSV (raises :class:`WpmFormatError` naming file, line and problem)."""
        header, curves = read_wpm_csv(path)
        return cls(curves, header, str(path), load_method)

    def sets(self) -> list[CurveSet]:
        return sorted(self._sets)

    def wheel(self, name: str | None = None, needed_for: str = "this") -> Wheel:
        """The geometry of wheel ``name`` (needed only when the curves hold several wheels);
        a one-line error when the file does not carry it (written before the
        ``wheel_geometry`` header, or by a tool that does not write it)."""
        names = sorted({w for _, w, _ in self._sets})
        if name is None:
            if len(names) != 1:
                raise WpmSelectionError(f"{self.source}: several wheels {names}; name one")
            name = names[0]
        if name not in names:
            raise WpmSelectionError(f"{self.source}: no curves of wheel {name!r}; wheels: {names}")
        if name not in self.wheels:
            raise WpmSelectionError(
                f"{self.source}: no wheel geometry (header '# wheel_geometry:'), and {needed_for} "
                f"needs wheel {name!r}'s radius, width and grousers; export the WPM CSV again "
                "with this swtlab, or add the header (docs/wpm-csv.md)")
        return self.wheels[name]

    def select(self, soil: str | None = None, wheel: str | None = None,
               multipass: int | None = None) -> CurveSet:
        """The one set matching the given fields, else :class:`WpmSelectionError` listing
        the choices."""
        match = [k for k in self.sets() if (soil is None or k[0] == soil)
                 and (wheel is None or k[1] == wheel) and (multipass is None or k[2] == multipass)]
        if not match:
            choices = "; ".join(_selection(*k) for k in self.sets())
            raise WpmSelectionError(f"no curves for {_selection(soil, wheel, multipass)} in "
                                    f"{self.source}; choices: {choices}")
        if len(match) > 1:
            raise WpmSelectionError(f"{len(match)} curve sets match in {self.source}; pick one: "
                                    + "; ".join(_selection(*k) for k in match))
        return match[0]

    def quantities(self, **selection) -> list[str]:
        """Quantities the selected set has, in the format's order."""
        have = self._sets[self.select(**selection)]
        return [q for q in UNITS if q in have]

    def _by_load(self, quantity: str, selection: dict) -> dict[float, WpmCurve]:
        key = self.select(**selection)
        if quantity not in self._sets[key]:
            raise WpmSelectionError(f"no {quantity} curves for {key} in {self.source}; it has "
                                    + ", ".join(self.quantities(**selection)))
        return self._sets[key][quantity]

    def _curves_at(self, quantity: str, loads_n, selection: dict, allow_extrapolation: bool,
                   uncertainty: bool = False) -> tuple[LoadCurves, np.ndarray]:
        """Curves at the distinct loads of ``loads_n`` and the index of each load's curve
        (with their covariance only when ``uncertainty``: it costs per load)."""
        unique, inverse = np.unique(np.asarray(loads_n, dtype=float).ravel(), return_inverse=True)
        curves = interpolate_loads(self._by_load(quantity, selection), unique,
                                   method=self.load_method,
                                   allow_extrapolation=allow_extrapolation,
                                   uncertainty=uncertainty)
        return curves, inverse

    def curve(self, quantity: str, load_n: float, *, soil=None, wheel=None, multipass=None,
              allow_extrapolation: bool = False) -> InterpolatedCurve:
        """The ``quantity`` curve at ``load_n`` (N), with its bands (:func:`fitting.band`)."""
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        return self._curves_at(quantity, [load_n], selection, allow_extrapolation,
                               uncertainty=True)[0].curve(0)

    def at_slip(self, slip, load_n, *, soil=None, wheel=None, multipass=None,
                allow_extrapolation: bool = False) -> dict[str, np.ndarray]:
        """Every quantity of the set at ``slip`` and ``load_n`` (broadcast together); warns
        with :class:`OutsideSlipRangeWarning` for slips outside a curve's range."""
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        slip, load = np.broadcast_arrays(np.asarray(slip, dtype=float),
                                         np.asarray(load_n, dtype=float))
        out, outside = {}, []
        for q in self.quantities(**selection):
            curves, index = self._curves_at(q, load, selection, allow_extrapolation)
            if np.any((slip < curves.slip_min) | (slip > curves.slip_max)):
                outside.append(f"{q} [{curves.slip_min:g}, {curves.slip_max:g}]")
            step, slope = curves.below_zero[index].T if curves.below_zero.any() else (0.0, 0.0)
            out[q] = curve_value(curves.coefficients[index], slip.ravel(), step,
                                 slope).reshape(slip.shape)
        if outside:
            warnings.warn("slip outside the range of " + ", ".join(outside) + ": extrapolated",
                          OutsideSlipRangeWarning, stacklevel=2)
        return out

    def _polynomial(self, quantity: str, selection: dict) -> tuple[tuple, LoadPolynomial]:
        key = (self.select(**selection), quantity)
        if key not in self._polynomials:
            self._polynomials[key] = LoadPolynomial(self._by_load(quantity, selection),
                                                    method=self.load_method)
        return key, self._polynomials[key]

    def _table(self, key: tuple, quantity: str, load_n: float, selection: dict,
               allow_extrapolation: bool, build: bool):
        """The cached (inverse table, curve) at one load, built when ``build`` (else None if
        not cached); the load checked (and warned about) on every call."""
        entry = self._tables.get((key, load_n))
        if entry is None:
            if not build:
                return None
            curve = self.curve(quantity, load_n, **selection,
                               allow_extrapolation=allow_extrapolation)
            entry = (InverseTable(curve.coefficients, curve.slip_min, curve.slip_max,
                                  curve.step_below_zero, curve.slope_below_zero), curve)
            if len(self._tables) >= MAX_TABLES:
                del self._tables[next(iter(self._tables))]
            self._tables[(key, load_n)] = entry
        elif entry[1].extrapolated:
            self._polynomials[key].parameters([load_n], allow_extrapolation)  # raise or warn
        return entry

    def slip_for_one(self, quantity: str, target: float, load_n: float, *, soil=None,
                     wheel=None, multipass=None, allow_extrapolation: bool = False
                     ) -> tuple[float, float, str]:
        """:meth:`slip_for` of one target at one load as ``(slip, value, status)`` floats and
        text: the call a simulator makes in its loop (the load's table is built the second
        time the load is asked for, then every call is a table look-up)."""
        fast = self._fast.get((quantity, soil, wheel, multipass, load_n))
        if fast is not None and not fast[1].extrapolated and target - target == 0.0:
            return fast[0].solve(target)
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        key, polynomial = self._polynomial(quantity, selection)
        load_n, target = float(load_n), float(target)
        if target - target != 0.0:
            raise ValueError("targets must be finite numbers")
        seen = (key, load_n) in self._seen
        entry = self._table(key, quantity, load_n, selection, allow_extrapolation, seen)
        if entry is None:
            self._seen.add((key, load_n))
            found = self._rows(polynomial, [target], [load_n], allow_extrapolation)
            return float(found.slip[0]), float(found.value[0]), str(found.status[0])
        if len(self._fast) >= MAX_TABLES:
            del self._fast[next(iter(self._fast))]
        self._fast[(quantity, soil, wheel, multipass, load_n)] = entry
        return entry[0].solve(target)

    @staticmethod
    def _rows(polynomial: LoadPolynomial, target, load, allow_extrapolation: bool
              ) -> SlipSolution:
        unique, index = np.unique(np.asarray(load, dtype=float), return_inverse=True)
        theta, _ = polynomial.parameters(unique, allow_extrapolation)
        degree = polynomial.degree
        return solve_slip(theta[:, :degree + 1], index, target, polynomial.slip_min,
                          polynomial.slip_max, theta[:, degree + 1:])

    def slip_for(self, quantity: str, target, load_n, *, soil=None, wheel=None, multipass=None,
                 allow_extrapolation: bool = False) -> SlipSolution:
        """The smallest slip at which the wheel gives ``target`` of ``quantity`` at ``load_n``
        (broadcast together); slip 1.0 and the maximum where the target is above the curve
        (the maximum over the fitted slip range), slip 0.0 and status ``at_step`` where it
        falls inside the jump at zero slip (:mod:`wpm_export.inverse`); ``value`` is the
        target where it is reached. Exact to 1e-8 in slip (tables) or rounding (rows)."""
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        key, polynomial = self._polynomial(quantity, selection)
        if np.ndim(load_n) == 0:  # one load: its table
            target = np.asarray(target, dtype=float)
            if not np.isfinite(target).all():
                raise ValueError("targets must be finite numbers")
            table, _ = self._table(key, quantity, float(load_n), selection,
                                   allow_extrapolation, True)
            slip, value, status = table.solve_many(target)
            return SlipSolution(slip=slip, value=value, status=status)
        target, load = np.broadcast_arrays(np.asarray(target, dtype=float),
                                           np.asarray(load_n, dtype=float))
        if not np.all(np.isfinite(target)):
            raise ValueError("targets must be finite numbers")
        shape, target, load = target.shape, target.ravel(), load.ravel()
        unique = np.unique(load)
        if unique.size > TABLE_LOADS:
            found = self._rows(polynomial, target, load, allow_extrapolation)
        else:
            slip, value = np.empty(target.shape), np.empty(target.shape)
            status = np.empty(target.shape, dtype="<U9")
            for w in unique.tolist():
                at = load == w if unique.size > 1 else slice(None)
                table, _ = self._table(key, quantity, w, selection, allow_extrapolation, True)
                slip[at], value[at], status[at] = table.solve_many(target[at])
            found = SlipSolution(slip=slip, value=value, status=status)
        return SlipSolution(slip=found.slip.reshape(shape), value=found.value.reshape(shape),
                            status=found.status.reshape(shape))

    def slip_band(self, quantity: str, slip, load_n: float, *, soil=None, wheel=None,
                  multipass=None, allow_extrapolation: bool = False
                  ) -> tuple[np.ndarray, np.ndarray]:
        """95 % half-widths ``(confidence, prediction)`` of the slip found for a target at
        one load: the curve's bands at that slip over its slope there, ``u_slip = u_y /
        |dy/ds|`` (linearised; NaN where the curve has no uncertainty, inf where the slope
        is 0; NaN slips stay NaN)."""
        curve = self.curve(quantity, load_n, soil=soil, wheel=wheel, multipass=multipass,
                           allow_extrapolation=allow_extrapolation)
        s = np.asarray(slip, dtype=float)
        _, conf, pred = band(curve, s)
        a = np.array(curve.coefficients)
        slope = horner(a[1:] * np.arange(1, a.size), s) + np.where(
            s < 0, curve.slope_below_zero, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            return conf / np.abs(slope), pred / np.abs(slope)
