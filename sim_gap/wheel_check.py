"""The gap compares like with like: the measured wheel must be the simulated one (radius,
width and grousers within the tolerances of :meth:`swtlab_base.domain.Wheel.mismatches`)."""

from __future__ import annotations

import pandas as pd

from sim_gap.simulated import Simulated
from swtlab_base.errors import InputError


class WheelMismatchError(InputError, ValueError):
    """The measured and the simulated wheel differ; the message says how."""


def check_wheels(points: pd.DataFrame, sim: Simulated, allow_mismatch: bool = False) -> list[str]:
    """How the measured wheel (``points.attrs['wheel']``) differs from the simulated one;
    raises :class:`WheelMismatchError` when they differ or the measured one is unknown,
    unless ``allow_mismatch`` (then the differences are returned, for the report)."""
    measured = points.attrs.get("wheel")
    if measured is None:
        problems = ["the measured wheel's geometry is unknown"]
    else:
        problems = measured.mismatches(sim.wheel)
    if problems and not allow_mismatch:
        raise WheelMismatchError(
            f"measured wheel {getattr(measured, 'name', '?')!r} is not the simulated wheel "
            f"({'; '.join(problems)}, measured vs simulated); simulate the measured wheel, or "
            "allow the mismatch explicitly (--allow-wheel-mismatch / allow_wheel_mismatch=True)")
    return problems
