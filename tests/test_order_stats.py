"""swtlab_base.order_stats.median against np.median (the number it replaces)."""

from __future__ import annotations

import numpy as np
import pytest

from swtlab_base.order_stats import median


@pytest.mark.parametrize("size", [1, 2, 3, 4, 7, 10, 1001, 60_000])
def test_median_is_np_median_to_the_bit(size):
    rng = np.random.default_rng(size)
    for x in (rng.normal(size=size), rng.integers(0, 4, size).astype(float),  # ties
              np.diff(np.cumsum(rng.integers(900_000, 1_100_000, size + 1)) * 1e-9)):
        assert median(x) == float(np.median(x))  # == on floats: the same bits here


def test_median_of_nan_or_nothing_is_nan():
    x = np.arange(10.0)
    x[3] = np.nan
    assert np.isnan(median(x)) and np.isnan(median(np.array([])))
