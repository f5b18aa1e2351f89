"""softflow.bspline_warp against scipy's independent spline code and analytic derivatives."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from softflow.bspline_warp import bspline_coefficients, gradient, warp_against


def warp(coefficients, flow):
    """The warped image alone: ``warp_against`` a zero reference gives it in ``both``."""
    both, diff = np.empty_like(coefficients), np.empty_like(coefficients)
    warp_against(np.zeros_like(coefficients), coefficients, flow, both, diff)
    assert np.array_equal(diff, -both)
    return both


@pytest.fixture(scope="module")
def texture():
    rng = np.random.default_rng(0)
    return (ndimage.gaussian_filter(rng.random((97, 130)), 1.2) * 100).astype(np.float32)


def test_coefficients_match_scipy(texture):
    """Gain-free coefficients: scipy's quintic prefilter divided by 120 per axis."""
    ref = ndimage.spline_filter(texture.astype(np.float64), order=5, mode="mirror") / 120 ** 2
    assert np.abs(bspline_coefficients(texture) - ref).max() < 1e-5 * np.abs(ref).max()


def test_warp_matches_scipy_map_coordinates(texture):
    """Random displacements up to 3 px, taps over the edges included (mirror)."""
    flow = np.random.default_rng(1).uniform(-3, 3, texture.shape + (2,)).astype(np.float32)
    y, x = np.mgrid[0:texture.shape[0], 0:texture.shape[1]].astype(np.float64)
    ref = ndimage.map_coordinates(texture.astype(np.float64), [y + flow[..., 1], x + flow[..., 0]],
                                  order=5, mode="mirror")
    assert np.abs(warp(bspline_coefficients(texture), flow) - ref).max() < 2e-4
    zero = warp(bspline_coefficients(texture), np.zeros_like(flow))
    assert np.abs(zero - texture).max() < 1e-4  # interpolating: the samples come back


@pytest.mark.parametrize("omega", [0.5, 0.9, 1.5])
def test_gradient_of_a_sine(omega):
    y, x = np.mgrid[0:80, 0:120].astype(np.float64)
    image = (np.sin(omega * x) + np.cos(0.7 * y)).astype(np.float32)
    gx, gy = gradient(image)
    inner = (slice(12, -12), slice(12, -12))
    assert np.abs(gx - omega * np.cos(omega * x))[inner].max() < 0.005 * omega
    assert np.abs(gy + 0.7 * np.sin(0.7 * y))[inner].max() < 0.005
    if omega >= 0.9:  # 4th-order central differences: 2 % low at 0.9 rad/px, 10 % at 1.5
        d4 = (np.roll(image, 2, 1) - 8 * np.roll(image, 1, 1) + 8 * np.roll(image, -1, 1)
              - np.roll(image, -2, 1)) / 12
        assert np.abs(d4 - omega * np.cos(omega * x))[inner].max() > 5 * np.abs(
            gx - omega * np.cos(omega * x))[inner].max()
