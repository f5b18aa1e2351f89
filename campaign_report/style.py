"""One look for every figure of a page: a fixed colour per load, a line style and marker per
multipass, and the plain name, unit and display scale of each quantity, fitted parameter
and effect that a page shows (the code names stay in the JSON and the database)."""

from __future__ import annotations

from dataclasses import dataclass

from matplotlib.lines import Line2D

def plain_text(text: str) -> str:
    """``text`` from a raw file or the database (run id, wheel, soil, flags) as matplotlib
    draws it literally: every ``$`` escaped, so a pair of them never starts math text (a run
    id like ``run $\\frac{$ x`` would make the mathtext parser fail the whole figure)."""
    return str(text).replace("$", r"\$")


#: colour-blind-safe, assigned to the campaign's loads in rising order: Okabe & Ito (2008),
#: then Paul Tol's "muted" scheme (2021) for campaigns of more loads
LOAD_COLOURS = ("#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442",
                "#000000", "#332288", "#88CCEE", "#44AA99", "#117733", "#999933", "#DDCC77",
                "#CC6677", "#882255", "#AA4499")
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
    "wheel_load_n": Quantity("wheel load", "N"),
    "travel_velocity_mps": Quantity("travel velocity", "mm/s", 1000.0),
    "slip": Quantity("slip", "%", 100.0),
    "t_s": Quantity("time", "s"),
}
#: quantities of the performance-curve figures, in panel order
CURVE_QUANTITIES = ("dp_n", "torque_nm", "sinkage_m", "resistance_n")
#: what a residual over load is relative to, per quantity (sim_gap.regions normalisation)
PER_LOAD_OF = {"dp_n": "W", "torque_nm": "W·r", "sinkage_m": "r", "resistance_n": "W"}

#: fitted model parameters under their dotted model names (docs/model-file.md): symbol and
#: plain name, display unit ("-": dimensionless) and the factor from SI
PARAMETERS = {
    "soil.kphi": Quantity("k_φ (frictional modulus)", "kN/m^(n+2)", 1e-3),
    "soil.friction_angle_deg": Quantity("φ (friction angle)", "°"),
    "soil.shear_modulus_m": Quantity("K (shear deformation modulus)", "mm", 1000.0),
    "effects.grousers.shear_radius_factor": Quantity("λ (grouser shear-radius factor)", "-"),
    "effects.slip_sinkage.n1": Quantity("n₁ (sinkage exponent gain per unit slip)", "-"),
    "effects.reduced_gravity.bearing_exponent": Quantity("α (k_φ ∝ g^α)", "-"),
    "effects.wheel_flexibility.radial_stiffness_n_m": Quantity("radial wheel stiffness",
                                                              "kN/m", 1e-3),
    "effects.wheel_flexibility.hysteresis_coefficient": Quantity(
        "μ_h (hysteresis resistance / load)", "-"),
    "effects.multipass.stiffness_gain_per_pass": Quantity("soil stiffness gain per pass", "-"),
    "effects.bulldozing.coefficient": Quantity("bulldozing factor (1 = the law as published)",
                                               "-"),
    "effects.grousers.lug_sinkage_gain": Quantity("κ (lug-induced sinkage gain)", "-"),
    "effects.grousers.lug_slip_gain": Quantity("g (lugs' slip-sinkage: Lyasko's factor^(g h/r))",
                                               "-"),
    "effects.slip_sinkage.coefficient": Quantity("κ (exponent on Lyasko's slip-sinkage factor)",
                                                 "-"),
    "effects.wheel_flexibility.ground_pressure_pa": Quantity("p_g (wheel ground pressure)", "kPa",
                                                             1e-3),
    "effects.multipass.elastic_stiffness_pa_m": Quantity("K_e (rut reloading stiffness)",
                                                         "MPa/m", 1e-6),
    "effects.slip_sinkage.load_exponent": Quantity("a (load exponent of the strength)", "-"),
    "effects.wheel_flexibility.load_exponent": Quantity("a (load exponent of the strength)", "-"),
    "effects.bulldozing.depth_exponent": Quantity("a (rut-depth exponent of the resistance)",
                                                  "-"),
}
#: the effects of the built-in model (terramechanics.EFFECTS) in plain words
EFFECTS = {"grousers": "grousers", "slip_sinkage": "slip sinkage",
           "reduced_gravity": "reduced gravity", "wheel_flexibility": "wheel flexibility",
           "multipass": "multipass", "bulldozing": "bulldozing"}


def value_text(quantity: Quantity, si_value: float, digits: int = 3) -> str:
    """``si_value`` in the display unit, with the unit (none when dimensionless)."""
    value = float(f"{si_value * quantity.scale:.{digits}g}")
    number = f"{value:g}" if 1e-3 <= abs(value) < 1e6 else f"{value:.{digits}g}"
    if quantity.unit == "-":
        return number
    return f"{number}{'' if quantity.unit in ('°', '%') else ' '}{quantity.unit}"


def load_colours(count: int) -> tuple[str, ...]:
    """``count`` distinct colours: :data:`LOAD_COLOURS`, then (a campaign of more loads) the
    others evenly spaced along the ``turbo`` colour map; no two loads share one."""
    extra = count - len(LOAD_COLOURS)
    if extra <= 0:
        return LOAD_COLOURS[:count]
    from matplotlib import colormaps
    from matplotlib.colors import to_hex

    more = [to_hex(c) for c in colormaps["turbo"]([(i + 0.5) / extra for i in range(extra)])]
    return LOAD_COLOURS + tuple(more)


class Palette:
    """Colour per load (each its own, :func:`load_colours`) and line style/marker per
    multipass, fixed for one campaign."""

    def __init__(self, loads_n, multipasses) -> None:
        self.loads = sorted({float(x) for x in loads_n})
        self.multipasses = sorted({int(m) for m in multipasses})
        self.colours = load_colours(len(self.loads))

    def colour(self, load_n: float) -> str:
        return self.colours[self.loads.index(float(load_n))]

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
