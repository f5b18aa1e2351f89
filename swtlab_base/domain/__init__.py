"""The one definition of each domain thing: wheel, soil, test condition, gravity and the
run-results table schema. Imports nothing of the stages (they import from here)."""

from swtlab_base.domain.condition import MODES, Soil, TestCondition
from swtlab_base.domain.gravity import G0_MPS2, MARS_GRAVITY_MPS2, MOON_GRAVITY_MPS2
from swtlab_base.domain.results import (COLUMNS, QUANTITIES, STATS, STATUSES, WHEEL_COLUMNS,
                                   check_results, wheel_columns, wheels_of)
from swtlab_base.domain.wheel import Wheel

__all__ = ["COLUMNS", "G0_MPS2", "MARS_GRAVITY_MPS2", "MODES", "MOON_GRAVITY_MPS2",
           "QUANTITIES", "STATS", "STATUSES", "Soil", "TestCondition", "WHEEL_COLUMNS", "Wheel",
           "check_results", "wheel_columns", "wheels_of"]
