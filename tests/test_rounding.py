"""Numbers as metrologists write them: the worked examples of the GUM (JCGM 100:2008) and
hand-derived cases."""

from __future__ import annotations

import math

import pytest

from swtlab_base.rounding import decimals, value_and_u


@pytest.mark.parametrize("value, u, shown", [
    (10.05762, 0.027, ("10.058", "0.027")),          # GUM 7.2.6: y = 10.057 62 Ω, u = 27 mΩ
    (100.02147, 0.00035, ("100.02147", "0.00035")),  # GUM 7.2.2: m = 100.021 47 g, u = 0.35 mg
    (0.0001211, 0.0068, ("0.0001", "0.0068")),       # issue 38: towed torque beside its u
    (-0.0000421, 0.0068, ("0.0000", "0.0068")),      # no sign on a zero
    (13.37, 0.0995, ("13.37", "0.10")),              # u rounds up into a new digit
    (1234.5, 340.0, ("1230", "340")),                # decimals left of the point
    (5.0, None, ("5", "")),
    (5.123456, math.nan, ("5.123", "")),
    (None, 0.31, ("", "0.31")),
])
def test_value_to_the_decimal_of_its_uncertainty(value, u, shown):
    assert value_and_u(value, u) == shown


def test_scale_to_the_display_unit():
    assert value_and_u(0.0032871, 0.0000113, scale=1000.0) == ("3.287", "0.011")  # m -> mm


@pytest.mark.parametrize("u, places", [(0.027, 3), (0.0995, 2), (12.0, 0), (340.0, -1),
                                       (1.0, 1), (0.99, 2), (0.996, 1)])
def test_decimals(u, places):
    assert decimals(u) == places
