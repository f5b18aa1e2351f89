"""One look for every figure of a page: a fixed colour per load, a line style and marker per
multipass, and each plotted quantity's label, unit and display scale."""

from __future__ import annotations

from dataclasses import dataclass

from matplotlib.lines import Line2D

#: colour-blind-safe (Okabe & Ito 2008), assigned to the campaign's loads in rising order
LOAD_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
                "#000000")
#: multipass 0, 1, 2, ... (cycled beyond)
MULTIPASS_LINES = ("-", "--", ":", "-.")
MULTIPASS_MARKERS = ("o", "s", "^", "D")


@dataclass(frozen=True)
class Quantity:
    """How one quantity is shown: axis label with its unit, and the factor from SI."""

    label: str
    unit: str
    scale: float = 1.0

    @property
    def axis_label(self) -> str:
        return f"{self.label} [{self.unit}]"


QUANTITIES = {
    "dp_n": Quantity("drawbar pull", "N"),
    "torque_nm": Quantity("torque", "N·m"),
    "sinkage_m": Quantity("sinkage", "mm", 1000.0),
    "resistance_n": Quantity("motion resistance", "N"),
    "dp_over_w": Quantity("drawbar pull / wheel load", "-"),
    "slip": Quantity("slip", "%", 100.0),
    "t_s": Quantity("time", "s"),
}
#: quantities of the performance-curve figures, in panel order
CURVE_QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")


class Palette:
    """Colour per load and line style/marker per multipass, fixed for one campaign."""

    def __init__(self, loads_n, multipasses) -> None:
        self.loads = sorted({float(x) for x in loads_n})
        self.multipasses = sorted({int(m) for m in multipasses})

    def colour(self, load_n: float) -> str:
        return LOAD_COLOURS[self.loads.index(float(load_n)) % len(LOAD_COLOURS)]

    def line(self, multipass: int) -> str:
        return MULTIPASS_LINES[self.multipasses.index(int(multipass)) % len(MULTIPASS_LINES)]

    def marker(self, multipass: int) -> str:
        return MULTIPASS_MARKERS[self.multipasses.index(int(multipass)) % len(MULTIPASS_MARKERS)]

    def legend_handles(self, loads_n=None, multipasses=None) -> list[Line2D]:
        """Proxy artists: one coloured line per load, one black style per multipass."""
        loads = self.loads if loads_n is None else sorted({float(x) for x in loads_n})
        passes = self.multipasses if multipasses is None else sorted({int(m) for m in multipasses})
        handles = [Line2D([], [], color=self.colour(x), lw=2.5, label=f"{x:g} N") for x in loads]
        if len(passes) > 1:
            handles += [Line2D([], [], color="0.2", ls=self.line(m), marker=self.marker(m),
                               label=f"multipass {m}") for m in passes]
        return handles
