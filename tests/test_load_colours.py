"""No two loads of a campaign share a colour, however many loads it has."""

from __future__ import annotations

import pytest

from campaign_report.style import LOAD_COLOURS, Palette


@pytest.mark.parametrize("count", [1, 8, 9, len(LOAD_COLOURS), len(LOAD_COLOURS) + 1, 60])
def test_each_load_its_own_colour(count):
    loads = [20.0 + 10.0 * i for i in range(count)]
    palette = Palette(loads, [0])
    colours = [palette.colour(x) for x in loads]
    assert len(set(colours)) == count
    assert colours[:min(count, 8)] == list(LOAD_COLOURS[:min(count, 8)])  # the usual first
