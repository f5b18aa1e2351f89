"""The Wheel Performance Module at run time: the curve at any load, every quantity at a slip
with its 95 % bands, and the slip that gives a required DP, torque, sinkage or resistance
(RUAG WPM), from a WPM CSV. Loads between the tested ones are interpolated on curve values as
:mod:`fitting.load_interp` documents (docs/wpm-csv.md).

Each (curve set, quantity) is packed once, at its first query, into one table
(:func:`wpm_export.kernel.pack`): the curve parameters and their covariance as exact
piecewise polynomials of load. Every query, one scalar or arrays of them, at any load, is
then answered from that table by the compiled kernels of :mod:`wpm_export.kernel` (numba,
imported at the first query): a query of numbers (a simulator's time step) by the kernel's
machine code straight to floats, arrays in one kernel call.
:meth:`WheelPerformanceModule.curve` alone builds the full
:class:`fitting.load_interp.InterpolatedCurve` (with its fit diagnostics) from the tested
curves.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable

import numpy as np

from fitting.errors import LoadExtrapolationWarning, LoadRangeError, OutsideSlipRangeWarning
from fitting.load_interp import InterpolatedCurve, LoadPolynomial, interpolate_loads
from swtlab_base.domain import Wheel
from wpm_export.inverse import SlipSolution
from wpm_export.reader import WpmCurve, read_wpm_csv, wheel_geometry
from wpm_export.schema import UNITS, WpmSelectionError

CurveSet = tuple[str, str, int]  # (soil, wheel, multipass)
#: status text by kernel code (status + 4 when the load was extrapolated)
STATUS = ("ok", "above_max", "below_min", "at_step") * 2
#: a query of one number (Python's or NumPy's): answered as floats; anything else as arrays
NUMBER = (float, int, np.floating, np.integer)
_solution = tuple.__new__  # SlipSolution(slip, value, status) without its checked __new__


def _selection_text(soil, wheel, multipass) -> str:
    """A curve set as the keyword arguments that select it (those given; the command line
    prints them as its flags)."""
    given = {"soil": soil, "wheel": wheel, "multipass": multipass}
    return ", ".join(f"{k}={v!r}" for k, v in given.items() if v is not None)


class WheelPerformanceModule:
    """Curves of one or more (soil, wheel, multipass) sets, each at its tested loads.

    ``load_method``: interpolation across load, ``"auto"`` (PCHIP with 3+ tested loads, else
    linear), ``"linear"`` or ``"pchip"``. Every query takes ``soil``, ``wheel``,
    ``multipass`` to pick the set (needed only when several sets match) and
    ``allow_extrapolation`` for loads outside the tested ones (warned, linear). Bad input
    raises a one-line error naming the keyword argument (docs/wpm-csv.md, "Errors").
    """

    def __init__(self, curves: Iterable[WpmCurve], header: dict[str, str] | None = None,
                 source: str = "<curves>", load_method: str = "auto") -> None:
        self.header, self.source, self.load_method = dict(header or {}), source, load_method
        self.wheels: dict[str, Wheel] = wheel_geometry(self.header, source)
        self._sets: dict[CurveSet, dict[str, dict[float, WpmCurve]]] = {}
        self._polynomials: dict[tuple, LoadPolynomial] = {}
        self._packed: dict[tuple, np.ndarray] = {}  # (quantity, soil, wheel, multipass) as asked
        self._kernel = None  # wpm_export.kernel, imported at the first query
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
        the choices as keyword arguments."""
        match = [k for k in self.sets() if (soil is None or k[0] == soil)
                 and (wheel is None or k[1] == wheel) and (multipass is None or k[2] == multipass)]
        if not match:
            choices = "; ".join(_selection_text(*k) for k in self.sets())
            raise WpmSelectionError(f"no curves for {_selection_text(soil, wheel, multipass)} "
                                    f"in {self.source}; choices: {choices}")
        if len(match) > 1:
            raise WpmSelectionError(f"{len(match)} curve sets match in {self.source}; pick one: "
                                    + "; ".join(_selection_text(*k) for k in match))
        return match[0]

    def quantities(self, **selection) -> list[str]:
        """Quantities the selected set has, in the format's order."""
        have = self._sets[self.select(**selection)]
        return [q for q in UNITS if q in have]

    def _by_load(self, quantity: str, selection: dict) -> dict[float, WpmCurve]:
        key = self.select(**selection)
        if quantity not in self._sets[key]:
            raise WpmSelectionError(f"quantity={quantity!r}: no such curves for "
                                    f"{_selection_text(*key)} in {self.source}; it has "
                                    + ", ".join(self.quantities(**selection)))
        return self._sets[key][quantity]

    def _polynomial(self, quantity: str, selection: dict) -> LoadPolynomial:
        key = (self.select(**selection), quantity)
        if key not in self._polynomials:
            self._polynomials[key] = LoadPolynomial(self._by_load(quantity, selection),
                                                    method=self.load_method)
        return self._polynomials[key]

    def _table(self, quantity: str, soil, wheel, multipass) -> np.ndarray:
        """The packed table of a quantity of the selected set (built at its first query)."""
        table = self._packed.get((quantity, soil, wheel, multipass))
        if table is None:
            if self._kernel is None:
                from wpm_export import kernel
                self._kernel = kernel
            selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
            table = self._kernel.pack(self._polynomial(quantity, selection))
            self._packed[(quantity, soil, wheel, multipass)] = table
        return table

    def _tested(self, table: np.ndarray) -> np.ndarray:
        first = int(table[self._kernel.TESTED])
        return table[first:first + int(table[self._kernel.LOADS])]

    def _outcome(self, code: int, quantity: str, table: np.ndarray, load_n, value=None,
                 name: str = "target", count: int = 1) -> None:
        """Raise for an error code of the kernel (the message names the keyword argument),
        else warn that ``count`` loads were extrapolated."""
        k, tested = self._kernel, self._tested(table)
        if isinstance(load_n, NUMBER):  # NumPy's numbers, ints: as the C library prints them
            load_n = float(load_n)
        value = _shown(value)
        span = f"{tested[0]:g}-{tested[-1]:g} N" if tested.size > 1 else f"{tested[0]:g} N"
        if code == k.BAD_TARGET or code == k.BAD_SLIP:
            raise ValueError(f"{name}={value}: {quantity} queries need a finite number")
        if code == k.BAD_LOAD:
            raise LoadRangeError(f"load_n={load_n!r}: the wheel load must be a finite number "
                                 "> 0 N")
        if code == k.ONE_LOAD:
            raise LoadRangeError(f"load_n={load_n:g} N: {quantity} was tested at {span} only, "
                                 "nothing to interpolate from")
        if code == k.OUTSIDE:
            raise LoadRangeError(f"load_n={load_n:g} N is outside the tested loads ({span}) of "
                                 f"{quantity}; pass allow_extrapolation=True to extrapolate "
                                 "linearly from the two nearest loads")
        warnings.warn(f"{count} load(s) outside the tested loads ({span}) of {quantity}, e.g. "
                      f"load_n={load_n:g} N: extrapolated linearly", LoadExtrapolationWarning,
                      stacklevel=3)

    def curve(self, quantity: str, load_n: float, *, soil=None, wheel=None, multipass=None,
              allow_extrapolation: bool = False) -> InterpolatedCurve:
        """The ``quantity`` curve at ``load_n`` (N), with its bands (:func:`fitting.band`) and
        the diagnostics of its refit (:func:`fitting.interpolate_loads`)."""
        table = self._table(quantity, soil, wheel, multipass)
        code = self._kernel.value_one(table, 0.0, float(load_n), bool(allow_extrapolation))[3]
        if code < 0 or code >= self._kernel.EXTRAPOLATED:
            self._outcome(code, quantity, table, load_n)
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", LoadExtrapolationWarning)
            return interpolate_loads(self._by_load(quantity, selection), [load_n],
                                     method=self.load_method,
                                     allow_extrapolation=allow_extrapolation).curve(0)

    def _many(self, quantity: str, x, load_n, selection: tuple, allow: bool, mode: str | None):
        """The kernel over ``x`` (targets, or slips with ``mode``: VALUES, BANDS, SLIP_BANDS
        of :func:`wpm_export.kernel.values_many`) and ``load_n`` broadcast: (shape, three
        output arrays, status codes of the inverse)."""
        table = self._table(quantity, *selection)
        k = self._kernel
        x, load = np.broadcast_arrays(*_numbers(x, load_n, "target" if mode is None else "slip"))
        shape = x.shape
        x, load = np.array(x.ravel()), np.array(load.ravel())  # contiguous, writable copies
        out = np.empty(x.size), np.empty(x.size), np.empty(x.size)
        status = np.empty(x.size, dtype=np.int8) if mode is None else None
        if mode is None:
            code, at, extrapolated = k.solve_many(table, x, load, bool(allow), out[0], out[1],
                                                  status)
        else:
            code, at, extrapolated = k.values_many(table, x, load, bool(allow), *out,
                                                   getattr(k, mode))
        if code:
            self._outcome(code, quantity, table, float(load[at]), float(x[at]),
                          "target" if mode is None else "slip")
        if extrapolated:
            tested = self._tested(table)
            outside = load[(load < tested[0]) | (load > tested[-1])]
            self._outcome(k.EXTRAPOLATED, quantity, table, float(outside[0]),
                          count=extrapolated)
        return shape, out, status

    def at_slip(self, slip, load_n, *, soil=None, wheel=None, multipass=None,
                allow_extrapolation: bool = False) -> dict[str, np.ndarray]:
        """Every quantity of the set at ``slip`` and ``load_n`` (broadcast together); warns
        with :class:`OutsideSlipRangeWarning` for slips outside a curve's range."""
        selection = (soil, wheel, multipass)
        out, outside = {}, []
        for q in self.quantities(soil=soil, wheel=wheel, multipass=multipass):
            shape, (value, _, _), _ = self._many(q, slip, load_n, selection,
                                                 allow_extrapolation, "VALUES")
            table = self._table(q, *selection)
            lo, hi = table[self._kernel.SLIP_MIN], table[self._kernel.SLIP_MAX]
            if np.any((np.asarray(slip) < lo) | (np.asarray(slip) > hi)):
                outside.append(f"{q} [{lo:g}, {hi:g}]")
            out[q] = value.reshape(shape)
        if outside:
            warnings.warn("slip outside the range of " + ", ".join(outside) + ": extrapolated",
                          OutsideSlipRangeWarning, stacklevel=2)
        return out

    def band(self, quantity: str, slip, load_n, *, soil=None, wheel=None, multipass=None,
             allow_extrapolation: bool = False) -> tuple:
        """``(value, conf_half95, pred_half95)`` of ``quantity`` at ``slip`` and ``load_n``,
        as :func:`fitting.band` of :meth:`curve` gives them: the 95 % half-widths of the true
        curve and of one new run's mean (NaN where the file carries no uncertainty). Two
        numbers (a simulator's time step): three floats; arrays (broadcast together, 0-d
        included): three arrays. No warning outside the fitted slip range."""
        if isinstance(slip, NUMBER) and isinstance(load_n, NUMBER):
            table = self._packed.get((quantity, soil, wheel, multipass))
            if table is None:
                table = self._table(quantity, soil, wheel, multipass)
            try:
                value, conf, pred, code = self._kernel.value_number(table, slip, load_n,
                                                                    allow_extrapolation)
            except (TypeError, OverflowError):  # e.g. an int beyond the doubles
                raise TypeError(f"slip={_shown(slip)}, load_n={_shown(load_n)}: numbers "
                                "expected") from None
            if code:
                self._outcome(code, quantity, table, load_n, slip, "slip")
            return value, conf, pred
        shape, out, _ = self._many(quantity, slip, load_n, (soil, wheel, multipass),
                                   allow_extrapolation, "BANDS")
        return tuple(a.reshape(shape) for a in out)

    #: :meth:`band` (its name for one slip at one load since 0.14.0)
    band_one = band

    def slip_for(self, quantity: str, target, load_n, *, soil=None, wheel=None, multipass=None,
                 allow_extrapolation: bool = False) -> SlipSolution:
        """The smallest slip at which the wheel gives ``target`` of ``quantity`` at ``load_n``;
        slip 1.0 and the maximum where the target is above the curve (the maximum over the
        fitted slip range), slip 0.0 and status ``at_step`` where it falls inside the jump at
        zero slip (:mod:`wpm_export.inverse`); ``value`` is the target where it is reached.
        Exact to rounding (the root to 1e-14). Two numbers (a simulator's time step, at
        whatever load): floats and the status text; arrays (broadcast together, 0-d
        included): arrays."""
        if isinstance(target, NUMBER) and isinstance(load_n, NUMBER):
            table = self._packed.get((quantity, soil, wheel, multipass))
            if table is None:
                table = self._table(quantity, soil, wheel, multipass)
            try:
                slip, value, code = self._kernel.solve_number(table, target, load_n,
                                                              allow_extrapolation)
            except (TypeError, OverflowError):  # e.g. an int beyond the doubles
                raise TypeError(f"target={_shown(target)}, load_n={_shown(load_n)}: numbers "
                                "expected") from None
            if code < 0 or code >= 4:
                self._outcome(code, quantity, table, load_n, target)
            return _solution(SlipSolution, (slip, value, STATUS[code]))
        shape, (slip, value, _), status = self._many(quantity, target, load_n,
                                                     (soil, wheel, multipass),
                                                     allow_extrapolation, None)
        return SlipSolution(slip=slip.reshape(shape), value=value.reshape(shape),
                            status=np.array(STATUS[:4], dtype="<U9")[status].reshape(shape))

    #: :meth:`slip_for` (its name for one target at one load since 0.14.0)
    slip_for_one = slip_for

    def slip_band(self, quantity: str, slip, load_n, *, soil=None, wheel=None,
                  multipass=None, allow_extrapolation: bool = False
                  ) -> tuple[np.ndarray, np.ndarray]:
        """95 % half-widths ``(confidence, prediction)`` of the slip found for a target: the
        curve's bands at that slip over its slope there, ``u_slip = u_y / |dy/ds|``
        (linearised; NaN where the curve has no uncertainty, inf where the slope is 0; NaN
        slips stay NaN); ``slip`` and ``load_n`` broadcast together."""
        if isinstance(slip, NUMBER) and isinstance(load_n, NUMBER):
            table = self._table(quantity, soil, wheel, multipass)
            conf, pred, code = self._kernel.slip_band_one(table, slip, load_n,
                                                          allow_extrapolation)
            if code:
                self._outcome(code, quantity, table, load_n, slip, "slip")
            return np.float64(conf), np.float64(pred)
        shape, (_, conf, pred), _ = self._many(quantity, slip, load_n,
                                               (soil, wheel, multipass), allow_extrapolation,
                                               "SLIP_BANDS")
        return conf.reshape(shape), pred.reshape(shape)


    def answer_for(self, quantity: str, target: float, load_n: float, *, soil=None,
                   wheel=None, multipass=None, allow_extrapolation: bool = False) -> dict:
        """:meth:`slip_for` of one ``target`` with its 95 % half-widths, as ``swtlab wpm
        query --dp/--torque/...`` answers it (docs/wpm-csv.md): the slip's (:meth:`slip_band`)
        where the target is reached, the value's (:func:`fitting.band`) there or, above the
        curve, at the curve's maximum (:func:`max_slip`); JSON-ready (null: not defined)."""
        from fitting.band import band

        chosen = {"soil": soil, "wheel": wheel, "multipass": multipass,
                  "allow_extrapolation": allow_extrapolation}
        found = self.slip_for(quantity, target, load_n, **chosen)
        curve = self.curve(quantity, load_n, **chosen)
        slip = float(found.slip)
        uncertainty = {"slip_conf_half95": None, "slip_pred_half95": None,
                       "value_conf_half95": None, "value_pred_half95": None}
        if curve.covariance is not None and str(found.status) in ("ok", "above_max"):
            at = slip if str(found.status) == "ok" else max_slip(curve)
            _, conf, pred = band(curve, at)
            uncertainty.update(value_conf_half95=float(conf), value_pred_half95=float(pred))
            if str(found.status) == "ok":
                slip_conf, slip_pred = self.slip_band(quantity, slip, load_n, **chosen)
                uncertainty.update(slip_conf_half95=_finite(slip_conf),
                                   slip_pred_half95=_finite(slip_pred))
        return {"quantity": quantity, "unit": UNITS[quantity], "target": target,
                "slip": slip if slip == slip else None,  # NaN (below the curve) -> null
                "value": float(found.value), "status": str(found.status),
                "uncertainty_known": curve.covariance is not None, **uncertainty,
                "slip_min": curve.slip_min, "slip_max": curve.slip_max, "method": curve.method,
                "tested_loads_n": list(curve.tested_loads_n),
                "extrapolated_load": curve.extrapolated}

    def answer_at(self, slip: float, load_n: float, *, soil=None, wheel=None, multipass=None,
                  allow_extrapolation: bool = False) -> dict:
        """Every quantity at one ``slip`` with its 95 % half-widths (:func:`fitting.band`) and
        whether the slip is outside its fitted range, as ``swtlab wpm query --slip`` answers
        it; JSON-ready."""
        from fitting.band import band

        chosen = {"soil": soil, "wheel": wheel, "multipass": multipass}
        out = {"slip": slip, "values": {}, "units": {}, "outside_slip_range": {},
               "conf_half95": {}, "pred_half95": {}}
        for quantity in self.quantities(**chosen):
            curve = self.curve(quantity, load_n, **chosen,
                               allow_extrapolation=allow_extrapolation)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                out["values"][quantity] = float(curve.evaluate(slip))
            _, conf, pred = band(curve, slip)
            out["conf_half95"][quantity], out["pred_half95"][quantity] = (_finite(conf),
                                                                          _finite(pred))
            out["units"][quantity] = UNITS[quantity]
            out["outside_slip_range"][quantity] = bool(curve.outside_range(slip))
            out.update(method=curve.method, tested_loads_n=list(curve.tested_loads_n),
                       extrapolated_load=curve.extrapolated)
        return out


def max_slip(curve: InterpolatedCurve) -> float:
    """The slip of the curve's maximum over its fitted range (a grid of 4001 slips)."""
    s = np.linspace(curve.slip_min, curve.slip_max, 4001)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(s[np.argmax(curve.evaluate(s))])


def _finite(x) -> float | None:
    """A finite float, else None (JSON null: a zero slope leaves the slip undetermined)."""
    x = float(x)
    return x if np.isfinite(x) else None


def _numbers(x, load_n, name: str) -> tuple[np.ndarray, np.ndarray]:
    """``x`` and ``load_n`` as float64 arrays (0-d for numbers); ``TypeError`` naming them for
    text or anything else that is not numbers."""
    try:
        given = np.asarray(x), np.asarray(load_n)
        if any(a.dtype.kind in "SUV" for a in given):
            raise TypeError
        return tuple(a.astype(float, copy=False) for a in given)
    except (TypeError, ValueError):
        raise TypeError(f"{name}={_shown(x)}, load_n={_shown(load_n)}: numbers "
                        "expected") from None


def _shown(given) -> str:
    """A query's argument in a message: a number as a float, other scalars as typed, arrays
    by type and dtype."""
    try:
        array = np.asarray(given)
    except ValueError:  # ragged nesting
        return f"<{type(given).__name__}>"
    if array.ndim:
        return f"<{type(given).__name__} of {array.dtype}>"
    try:
        return repr(float(given)) if isinstance(given, NUMBER) else repr(given)
    except OverflowError:  # an int beyond the doubles
        return repr(given)
