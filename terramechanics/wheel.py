"""Wheel geometry (SI): radius, width, grousers."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Wheel:
    """A wheel of nominal (rim) radius ``radius_m`` and width ``width_m``.

    ``grouser_count`` and ``grouser_height_m`` only matter when the
    ``grousers`` effect is on.
    """

    radius_m: float
    width_m: float
    grouser_count: int = 0
    grouser_height_m: float = 0.0

    def __post_init__(self) -> None:
        if self.radius_m <= 0 or self.width_m <= 0:
            raise ValueError("wheel radius_m and width_m must be > 0")
        if self.grouser_count < 0 or self.grouser_height_m < 0:
            raise ValueError("grouser_count and grouser_height_m must be >= 0")
