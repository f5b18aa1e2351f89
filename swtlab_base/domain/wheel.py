"""The wheel: geometry and stiffness (SI), validated on construction, and the check that two
descriptions are the same wheel."""

from __future__ import annotations

import math
import numbers
from dataclasses import asdict, dataclass

#: relative tolerance on radius and width when two wheels are compared
WHEEL_SIZE_REL_TOL = 0.02
#: absolute tolerance on the grouser height when two wheels are compared, m
GROUSER_HEIGHT_TOL_M = 0.001


def _finite(name: str, value: object, minimum: float, strict: bool) -> None:
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
        raise ValueError(f"wheel {name} {value!r} must be a finite number")
    if value < minimum or (strict and value == minimum):
        raise ValueError(f"wheel {name} {value:g} must be {'>' if strict else '>='} {minimum:g}")


@dataclass(frozen=True)
class Wheel:
    """A wheel: rim radius ``radius_m`` (without grousers) and ``width_m``; ``grouser_count``
    grousers of ``grouser_height_m``; radial ``stiffness_n_per_mm`` (None: rigid); ``mass_kg``
    (None: unknown); ``name`` as the lab calls it (metadata ``swt.run.wheel``)."""

    radius_m: float
    width_m: float
    grouser_count: int = 0
    grouser_height_m: float = 0.0
    stiffness_n_per_mm: float | None = None
    mass_kg: float | None = None
    name: str = ""

    def __post_init__(self) -> None:
        _finite("radius_m", self.radius_m, 0.0, True)
        _finite("width_m", self.width_m, 0.0, True)
        if isinstance(self.grouser_count, bool) or int(self.grouser_count) != self.grouser_count \
                or self.grouser_count < 0:
            raise ValueError(f"wheel grouser_count {self.grouser_count!r} must be an integer >= 0")
        _finite("grouser_height_m", self.grouser_height_m, 0.0, False)
        for name in ("stiffness_n_per_mm", "mass_kg"):
            if getattr(self, name) is not None:
                _finite(name, getattr(self, name), 0.0, True)
        object.__setattr__(self, "grouser_count", int(self.grouser_count))

    def geometry(self) -> dict:
        """Radius, width, grousers and stiffness as a plain dict (no name, no mass)."""
        out = asdict(self)
        del out["name"], out["mass_kg"]
        return out

    def mismatches(self, other: Wheel) -> list[str]:
        """How ``other`` differs from this wheel beyond the tolerances (radius and width
        within 2 %, the same grouser count, grouser height within 1 mm); empty when they
        agree. Stiffness is not compared (a model states it as an effect parameter)."""
        out = []
        for name in ("radius_m", "width_m"):
            a, b = getattr(self, name), getattr(other, name)
            if abs(a - b) > WHEEL_SIZE_REL_TOL * max(a, b):
                out.append(f"{name} {a:g} vs {b:g} (tolerance {100 * WHEEL_SIZE_REL_TOL:g} %)")
        if self.grouser_count != other.grouser_count:
            out.append(f"grouser_count {self.grouser_count} vs {other.grouser_count}")
        if abs(self.grouser_height_m - other.grouser_height_m) > GROUSER_HEIGHT_TOL_M:
            out.append(f"grouser_height_m {self.grouser_height_m:g} vs "
                       f"{other.grouser_height_m:g} (tolerance {GROUSER_HEIGHT_TOL_M:g} m)")
        return out
