"""The Wheel Performance Module at run time: the curve at any load, every quantity at a slip,
and the slip that gives a required DP, torque, sinkage or resistance (RUAG WPM), from a WPM
CSV. Loads between the tested ones are interpolated on curve values exactly as in
:mod:`fitting.load_interp`; all queries are vectorised over numpy arrays.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable

import numpy as np

from fitting.errors import OutsideSlipRangeWarning
from fitting.load_interp import InterpolatedCurve, LoadCurves, interpolate_loads
from fitting.polynomial import curve_value
from wpm_export.inverse import SlipSolution, solve_slip
from swtlab.domain import Wheel
from wpm_export.reader import WpmCurve, read_wpm_csv, wheel_geometry
from wpm_export.schema import UNITS, WpmSelectionError

CurveSet = tuple[str, str, int]  # (soil, wheel, multipass)


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
        choices = "; ".join(f"--soil {s} --wheel {w} --multipass {m}" for s, w, m in self.sets())
        if not match:
            raise WpmSelectionError(f"no curves for soil={soil} wheel={wheel} "
                                    f"multipass={multipass} in {self.source}; choices: {choices}")
        if len(match) > 1:
            raise WpmSelectionError(f"{len(match)} curve sets match in {self.source}; pick one: "
                                    + "; ".join(f"--soil {s} --wheel {w} --multipass {m}"
                                                for s, w, m in match))
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

    def _curves_at(self, quantity: str, loads_n, selection: dict,
                   allow_extrapolation: bool) -> tuple[LoadCurves, np.ndarray]:
        """Curves at the distinct loads of ``loads_n`` and the index of each load's curve."""
        unique, inverse = np.unique(np.asarray(loads_n, dtype=float).ravel(), return_inverse=True)
        curves = interpolate_loads(self._by_load(quantity, selection), unique,
                                   method=self.load_method,
                                   allow_extrapolation=allow_extrapolation)
        return curves, inverse

    def curve(self, quantity: str, load_n: float, *, soil=None, wheel=None, multipass=None,
              allow_extrapolation: bool = False) -> InterpolatedCurve:
        """The ``quantity`` curve at ``load_n`` (N)."""
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        return self._curves_at(quantity, [load_n], selection, allow_extrapolation)[0].curve(0)

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

    def slip_for(self, quantity: str, target, load_n, *, soil=None, wheel=None, multipass=None,
                 allow_extrapolation: bool = False) -> SlipSolution:
        """The smallest slip at which the wheel gives ``target`` of ``quantity`` at ``load_n``
        (broadcast together); slip 1.0 and the maximum where the target is above the curve,
        slip 0.0 and status ``at_step`` where it falls inside the jump at zero slip
        (:mod:`wpm_export.inverse`)."""
        selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
        target, load = np.broadcast_arrays(np.asarray(target, dtype=float),
                                           np.asarray(load_n, dtype=float))
        curves, index = self._curves_at(quantity, load, selection, allow_extrapolation)
        found = solve_slip(curves.coefficients, index, target.ravel(), curves.slip_min,
                           curves.slip_max, curves.below_zero)
        shape = target.shape
        return SlipSolution(slip=found.slip.reshape(shape), value=found.value.reshape(shape),
                            status=found.status.reshape(shape))
