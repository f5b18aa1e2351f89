"""libswtwpm from Python (ctypes): the C Wheel Performance Module (libswtwpm/swtwpm.h) that
simulators link, built into the package at install (setup.py) as ``wpm_export/_libswtwpm*.so``.

:class:`CWheelPerformanceModule` answers the runtime's queries (forward values and bands,
the inverse) from the C library, with the runtime's exceptions and warnings for bad input
(:class:`WpmFormatError`, :class:`WpmSelectionError`, :class:`fitting.errors.LoadRangeError`,
``ValueError`` for NaN queries; :class:`LoadExtrapolationWarning`,
:class:`OutsideSlipRangeWarning`), each with the C library's message, which is the
runtime's text.
"""

from __future__ import annotations

import ctypes
import warnings
from pathlib import Path

import numpy as np

from fitting.errors import LoadExtrapolationWarning, LoadRangeError, OutsideSlipRangeWarning
from wpm_export.inverse import SlipSolution
from wpm_export.schema import UNITS, WpmFormatError, WpmSelectionError

QUANTITIES = tuple(UNITS)  # the C enum's order
STATUS = np.array(["ok", "above_max", "below_min", "at_step"])
WARN_SLIP_OUTSIDE, WARN_LOAD_EXTRAPOLATED = 1, 2
E_FORMAT, E_IO, E_MEMORY, E_SELECTION, E_LOAD_RANGE, E_NOT_FINITE = -1, -2, -3, -4, -5, -6
ALLOW_EXTRAPOLATION = 1
MAX_PARAMETERS = 10
MESSAGE_SIZE = 2048


class Curve(ctypes.Structure):
    """``swtwpm_curve``: the curve of one quantity at one load with its covariance."""

    _fields_ = [("degree", ctypes.c_int), ("a", ctypes.c_double * 8),
                ("step_below_zero", ctypes.c_double), ("slope_below_zero", ctypes.c_double),
                ("slip_min", ctypes.c_double), ("slip_max", ctypes.c_double),
                ("load_n", ctypes.c_double), ("extrapolated", ctypes.c_int),
                ("has_uncertainty", ctypes.c_int),
                ("covariance", (ctypes.c_double * MAX_PARAMETERS) * MAX_PARAMETERS),
                ("k95", ctypes.c_double), ("scatter_sd", ctypes.c_double)]


def library_path() -> Path:
    """The shared object built at install (raises ``OSError`` naming the fix when absent)."""
    found = sorted(Path(__file__).parent.glob("_libswtwpm*.so"))
    if not found:
        raise OSError("libswtwpm is not built: install swtlab with `pip install -e .` (or "
                      "`make test`), which compiles libswtwpm/ with the C compiler")
    return found[0]


_LIB = None


def library() -> ctypes.CDLL:
    """The loaded library, its functions typed."""
    global _LIB
    if _LIB is not None:
        return _LIB
    lib = ctypes.CDLL(str(library_path()))
    p, d, i, c = ctypes.c_void_p, ctypes.c_double, ctypes.c_int, ctypes.c_char_p
    dp, ip, sz = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int), ctypes.c_size_t
    signatures = {
        "swtwpm_open": (i, [c, ctypes.POINTER(p), c, sz]),
        "swtwpm_free": (None, [p]),
        "swtwpm_header": (c, [p, c]),
        "swtwpm_set_count": (i, [p]),
        "swtwpm_set_info": (i, [p, i, ctypes.POINTER(c), ctypes.POINTER(c),
                                ctypes.POINTER(ctypes.c_longlong)]),
        "swtwpm_select": (i, [p, c, c, ctypes.c_longlong, c, sz]),
        "swtwpm_has_quantity": (i, [p, i, i]),
        "swtwpm_tested_loads": (i, [p, i, i, dp, i]),
        "swtwpm_slip_range": (i, [p, i, i, dp, dp]),
        "swtwpm_wheel_geometry": (i, [p, c, dp, c, sz]),
        "swtwpm_value": (i, [p, i, i, d, d, i, dp, c, sz]),
        "swtwpm_slip_for": (i, [p, i, i, d, d, i, dp, dp, ip, c, sz]),
        "swtwpm_curve_at": (i, [p, i, i, d, i, ctypes.POINTER(Curve), c, sz]),
        "swtwpm_curve_eval": (i, [ctypes.POINTER(Curve), d, dp, dp, dp]),
        "swtwpm_value_band": (i, [p, i, i, d, d, i, dp, dp, dp, c, sz]),
        "swtwpm_value_many": (i, [p, i, i, sz, dp, dp, i, dp, ip]),
        "swtwpm_slip_for_many": (i, [p, i, i, sz, dp, dp, i, dp, dp, ip, ip]),
    }
    for name, (restype, argtypes) in signatures.items():
        function = getattr(lib, name)
        function.restype, function.argtypes = restype, argtypes
    _LIB = lib
    return lib


def _pointer(array: np.ndarray, kind=ctypes.c_double):
    return array.ctypes.data_as(ctypes.POINTER(kind))


class CWheelPerformanceModule:
    """A WPM CSV loaded by libswtwpm; queries as :class:`wpm_export.WheelPerformanceModule`
    (``load_method`` "auto" only: PCHIP with 3+ tested loads, else linear)."""

    def __init__(self, path) -> None:
        self.source = str(path)
        self._lib = library()
        self._model = ctypes.c_void_p()
        message = ctypes.create_string_buffer(MESSAGE_SIZE)
        code = self._lib.swtwpm_open(self.source.encode(), ctypes.byref(self._model), message,
                                     MESSAGE_SIZE)
        if code < 0:
            self._model = None
            self._raise(code, message.value.decode(errors="replace"))

    load = classmethod(lambda cls, path: cls(path))

    def __del__(self) -> None:
        if getattr(self, "_model", None):
            self._lib.swtwpm_free(self._model)
            self._model = None

    def _raise(self, code: int, message: str):
        if code == E_FORMAT:
            prefix = self.source + ":"
            line, _, problem = message[len(prefix):].partition(": ") \
                if message.startswith(prefix) else ("0", "", message)
            raise WpmFormatError(self.source, int(line) if line.isdigit() else 0, problem)
        if code == E_IO:
            raise OSError(message)
        if code == E_SELECTION:
            raise WpmSelectionError(message)
        if code == E_LOAD_RANGE:
            raise LoadRangeError(message)
        raise ValueError(message)

    def header(self, key: str) -> str | None:
        value = self._lib.swtwpm_header(self._model, key.encode())
        return None if value is None else value.decode()

    def sets(self) -> list[tuple[str, str, int]]:
        out = []
        for k in range(self._lib.swtwpm_set_count(self._model)):
            soil, wheel, multipass = ctypes.c_char_p(), ctypes.c_char_p(), ctypes.c_longlong()
            self._lib.swtwpm_set_info(self._model, k, ctypes.byref(soil), ctypes.byref(wheel),
                                      ctypes.byref(multipass))
            out.append((soil.value.decode(), wheel.value.decode(), multipass.value))
        return out

    def select(self, soil=None, wheel=None, multipass=None) -> int:
        """Index of the one set matching the given fields (else :class:`WpmSelectionError`)."""
        message = ctypes.create_string_buffer(MESSAGE_SIZE)
        index = self._lib.swtwpm_select(self._model, None if soil is None else soil.encode(),
                                        None if wheel is None else wheel.encode(),
                                        -1 if multipass is None else int(multipass), message,
                                        MESSAGE_SIZE)
        if index < 0:
            self._raise(index, message.value.decode())
        return index

    def tested_loads(self, quantity: str = "dp_n", **selection) -> list[float]:
        """The tested loads (N) of a quantity of the selected set."""
        loads = (ctypes.c_double * 256)()
        count = self._lib.swtwpm_tested_loads(self._model, self.select(**selection),
                                              QUANTITIES.index(quantity), loads, 256)
        return list(loads[:max(count, 0)])

    def wheel_geometry(self, wheel: str | None = None) -> dict[str, float | None]:
        """radius_m, width_m, grouser_count, grouser_height_m, stiffness_n_per_mm (None:
        rigid) of the file's wheel_geometry header."""
        out = (ctypes.c_double * 5)()
        message = ctypes.create_string_buffer(MESSAGE_SIZE)
        code = self._lib.swtwpm_wheel_geometry(self._model, None if wheel is None else
                                               wheel.encode(), out, message, MESSAGE_SIZE)
        if code < 0:
            self._raise(code, message.value.decode())
        keys = ("radius_m", "width_m", "grouser_count", "grouser_height_m",
                "stiffness_n_per_mm")
        return {k: (None if v != v else v) for k, v in zip(keys, out)}

    def _one_error(self, codes: np.ndarray, call) -> None:
        """Raise for the first element with an error (its message from one scalar call);
        warn once when loads were extrapolated, with their count (as the runtime does)."""
        bad = np.flatnonzero(codes < 0)
        if bad.size:
            code, message = call(int(bad[0]))
            self._raise(code, message)
        extrapolated = np.flatnonzero(codes & WARN_LOAD_EXTRAPOLATED)
        if extrapolated.size:
            _, message = call(int(extrapolated[0]))  # "1 load(s) outside ...": one query's
            warnings.warn(f"{extrapolated.size}{message[1:]}", LoadExtrapolationWarning,
                          stacklevel=3)

    def value(self, quantity: str, slip, load_n, *, soil=None, wheel=None, multipass=None,
              allow_extrapolation: bool = False) -> np.ndarray:
        """``quantity`` at ``slip`` and ``load_n`` (broadcast together)."""
        k, q = self.select(soil, wheel, multipass), QUANTITIES.index(quantity)
        flags = ALLOW_EXTRAPOLATION if allow_extrapolation else 0
        s, w = (np.ascontiguousarray(x, dtype=float).ravel() for x in
                np.broadcast_arrays(np.asarray(slip, float), np.asarray(load_n, float)))
        shape = np.broadcast_shapes(np.shape(slip), np.shape(load_n))
        out, codes = np.empty(s.size), np.empty(s.size, dtype=np.intc)
        self._lib.swtwpm_value_many(self._model, k, q, s.size, _pointer(w), _pointer(s), flags,
                                    _pointer(out), _pointer(codes, ctypes.c_int))

        def call(i):
            message, v = ctypes.create_string_buffer(MESSAGE_SIZE), ctypes.c_double()
            code = self._lib.swtwpm_value(self._model, k, q, w[i], s[i], flags, ctypes.byref(v),
                                          message, MESSAGE_SIZE)
            return code, message.value.decode()

        self._one_error(codes, call)
        if np.any(codes & WARN_SLIP_OUTSIDE):
            lo, hi = ctypes.c_double(), ctypes.c_double()
            self._lib.swtwpm_slip_range(self._model, k, q, ctypes.byref(lo), ctypes.byref(hi))
            warnings.warn(f"slip outside the range of {quantity} [{lo.value:g}, {hi.value:g}]: "
                          "extrapolated", OutsideSlipRangeWarning, stacklevel=2)
        return out.reshape(shape)

    def slip_for(self, quantity: str, target, load_n, *, soil=None, wheel=None,
                 multipass=None, allow_extrapolation: bool = False) -> SlipSolution:
        """The smallest slip giving ``target`` at ``load_n`` (broadcast together)."""
        k, q = self.select(soil, wheel, multipass), QUANTITIES.index(quantity)
        flags = ALLOW_EXTRAPOLATION if allow_extrapolation else 0
        t, w = (np.ascontiguousarray(x, dtype=float).ravel() for x in
                np.broadcast_arrays(np.asarray(target, float), np.asarray(load_n, float)))
        shape = np.broadcast_shapes(np.shape(target), np.shape(load_n))
        slip, value = np.empty(t.size), np.empty(t.size)
        status, codes = np.empty(t.size, dtype=np.intc), np.empty(t.size, dtype=np.intc)
        self._lib.swtwpm_slip_for_many(self._model, k, q, t.size, _pointer(w), _pointer(t),
                                       flags, _pointer(slip), _pointer(value),
                                       _pointer(status, ctypes.c_int),
                                       _pointer(codes, ctypes.c_int))

        def call(i):
            message = ctypes.create_string_buffer(MESSAGE_SIZE)
            s, v, st = ctypes.c_double(), ctypes.c_double(), ctypes.c_int()
            code = self._lib.swtwpm_slip_for(self._model, k, q, w[i], t[i], flags,
                                             ctypes.byref(s), ctypes.byref(v), ctypes.byref(st),
                                             message, MESSAGE_SIZE)
            return code, message.value.decode()

        self._one_error(codes, call)
        return SlipSolution(slip=slip.reshape(shape), value=value.reshape(shape),
                            status=STATUS[np.clip(status, 0, 3)].reshape(shape))

    def curve(self, quantity: str, load_n: float, *, soil=None, wheel=None, multipass=None,
              allow_extrapolation: bool = False) -> Curve:
        """The curve at ``load_n`` with its covariance (a :class:`Curve`)."""
        k, q = self.select(soil, wheel, multipass), QUANTITIES.index(quantity)
        out, message = Curve(), ctypes.create_string_buffer(MESSAGE_SIZE)
        code = self._lib.swtwpm_curve_at(self._model, k, q, float(load_n),
                                         ALLOW_EXTRAPOLATION if allow_extrapolation else 0,
                                         ctypes.byref(out), message, MESSAGE_SIZE)
        if code < 0:
            self._raise(code, message.value.decode())
        if code & WARN_LOAD_EXTRAPOLATED:
            warnings.warn(message.value.decode(), LoadExtrapolationWarning, stacklevel=2)
        return out

    def band(self, quantity: str, slip, load_n, *, soil=None, wheel=None, multipass=None,
             allow_extrapolation: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(value, conf_half95, pred_half95)`` at ``slip`` and ``load_n`` (broadcast
        together; the curve with its covariance computed once per run of equal loads)."""
        k, q = self.select(soil, wheel, multipass), QUANTITIES.index(quantity)
        flags = ALLOW_EXTRAPOLATION if allow_extrapolation else 0
        s, w = (np.ascontiguousarray(x, dtype=float).ravel() for x in
                np.broadcast_arrays(np.asarray(slip, float), np.asarray(load_n, float)))
        shape = np.broadcast_shapes(np.shape(slip), np.shape(load_n))
        out = np.empty((3, s.size))
        curve, message = Curve(), ctypes.create_string_buffer(MESSAGE_SIZE)
        value, conf, pred = ctypes.c_double(), ctypes.c_double(), ctypes.c_double()
        last, code, extrapolated, warning = None, 0, 0, ""
        for i in range(s.size):
            if not np.isfinite(s[i]) or w[i] != last:  # the checks, in the runtime's order
                code = self._lib.swtwpm_value_band(
                    self._model, k, q, w[i], s[i], flags, ctypes.byref(value),
                    ctypes.byref(conf), ctypes.byref(pred), message, MESSAGE_SIZE)
                if code < 0:
                    self._raise(code, message.value.decode())
                if code & WARN_LOAD_EXTRAPOLATED and not warning:
                    warning = message.value.decode()
                self._lib.swtwpm_curve_at(self._model, k, q, w[i], flags, ctypes.byref(curve),
                                          None, 0)
                last = w[i]
            extrapolated += bool(code & WARN_LOAD_EXTRAPOLATED)
            self._lib.swtwpm_curve_eval(ctypes.byref(curve), s[i], ctypes.byref(value),
                                        ctypes.byref(conf), ctypes.byref(pred))
            out[:, i] = value.value, conf.value, pred.value
        if extrapolated:
            warnings.warn(f"{extrapolated}{warning[1:]}", LoadExtrapolationWarning, stacklevel=2)
        return tuple(row.reshape(shape) for row in out)
