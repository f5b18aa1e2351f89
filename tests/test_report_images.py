"""The report's figures to PNG: palette encoding (exact where the colours fit, nearest colour
otherwise, median cut for a non-plot), thumbnails from the same pixels, the note for error
bars hidden by their markers (checked by hand against the axes' pixel scale), and the
curves' bands (half-widths by hand from a known covariance). The time series are SVG
(tests/test_report_timeseries.py)."""

from __future__ import annotations

import io
from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from PIL import Image

from campaign_report import figures, images
from fitting import PowerCurve


def _decoded(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def _rgba(rgb: np.ndarray) -> np.ndarray:
    return np.dstack([rgb, np.full(rgb.shape[:2], 255, np.uint8)]).astype(np.uint8)


def test_a_few_colours_are_encoded_losslessly_and_others_take_the_nearest():
    rgb = np.full((40, 60, 3), 255, np.uint8)
    rgb[5:15, :] = (0x00, 0x72, 0xB2)       # a load colour
    rgb[20:30, :] = (200, 10, 10)           # a colour of the figure's own
    rgb[35, 3] = (2, 112, 180)              # one rare pixel, nearest to the load colour
    rendered = images.Rendered(_rgba(rgb), *images._palette(images._keys(_rgba(rgb))))
    out = _decoded(images.encode(rendered.rgba, rendered.palette))
    expected = rgb.copy()
    # by hand: the rare pixel (2, 112, 180) is in the palette too (<= 256 colours): kept
    assert (out == expected).all()
    # a palette without it: squared distance to (0, 114, 178) is 4 + 4 + 4 = 12, to
    # (200, 10, 10) 40000+: the load colour
    palette = np.array([images._key(c) for c in ("#ffffff", "#0072B2", "#c80a0a")], np.uint32)
    out = _decoded(images.encode(rendered.rgba, palette))
    expected[35, 3] = (0x00, 0x72, 0xB2)
    assert (out == expected).all()


def test_a_non_plot_is_quantised_by_median_cut():
    rng = np.random.default_rng(3)
    rgb = rng.integers(0, 256, (64, 64, 3), dtype=np.uint8)  # noise: no colour is frequent
    assert images._palette(images._keys(_rgba(rgb)))[0] is None
    out = _decoded(images.encode(_rgba(rgb), None))
    assert out.shape == rgb.shape and np.abs(out.astype(int) - rgb).mean() < 40


def test_thumbnail_is_300_px_wide_from_the_same_pixels():
    fig = Figure(figsize=(8.0, 6.4))
    fig.subplots().plot([0, 1], [0, 1], color="#E69F00", lw=6)
    png, rendered = images.to_png(fig)
    full, thumb = _decoded(png), _decoded(images.thumbnail(rendered))
    assert full.shape == (640, 800, 3) and thumb.shape == (240, 300, 3)
    assert (full == rendered.rgba[..., :3]).mean() > 0.99  # a plot: (nearly) lossless
    assert ((thumb == (0xE6, 0x9F, 0x00)).all(axis=2)).any()  # the load colour kept


def test_error_bars_hidden_by_their_markers_are_named_with_their_size():
    fig = Figure(figsize=(6.0, 4.0), dpi=100)
    ax = fig.add_axes((0.1, 0.1, 0.8, 0.8))   # 320 px high
    rows = pd.DataFrame({"slip": [0.1, 0.2], "dp_n": [10.0, 50.0], "dp_n_se": [0.01, 10.0],
                         "dp_n_k": [2.0, 2.0]})
    figures._errorbars(ax, rows, "dp_n", "#0072B2", "o", fitted=True)
    ax.set_ylim(0.0, 100.0)
    images.render(fig)
    # by hand: U = k se = 0.02 N is 0.064 px, under the marker radius 5 pt / 2 = 3.5 px;
    # U = 20 N is 64 px, seen
    text = figures.hidden_errorbars(fig, ["dp_n"])
    assert text.startswith("Error bars smaller than the markers: U(drawbar pull) ≤ 0.02 N "
                           "(1 of 2 points)")
    assert figures.expanded_uncertainty(rows, "dp_n").tolist() == pytest.approx([0.02, 20.0])
    ax.set_ylim(9.99, 10.01)   # now 0.02 N spans 640 px: every bar is seen
    images.render(fig)
    assert figures.hidden_errorbars(fig, ["dp_n"]) is None


@dataclass(frozen=True)
class _Curve(PowerCurve):
    quantity: str = "dp_n"


def test_bands_are_shaded_and_their_half_widths_named_by_hand():
    # by hand: C = diag(0.3**2, 0, ...) gives g^T C g = 0.09 at every slip (g_0 = 1), so
    # confidence = k95 * 0.3 = 0.6 N and prediction = 2 * sqrt(0.09 + 0.4**2) = 1.0 N
    cov = np.zeros((6, 6))
    cov[0, 0] = 0.09
    curve = _Curve((1.0, 2.0, 0.0, 0.0), 0.0, 0.5, covariance=tuple(map(tuple, cov)),
                   scatter_sd=0.4, k95=2.0)
    text = figures.band_text([curve], ["dp_n"])
    assert "drawbar pull ± 0.6 / ± 1 N" in text
    fig = Figure()
    ax = fig.subplots()
    assert figures._bands(ax, curve, "dp_n", "#0072B2")
    lows = [c.get_paths()[0].vertices[:, 1].min() for c in ax.collections]
    # lowest edge at slip 0: mean 1.0 N minus the half-width (prediction first, confidence)
    assert lows == pytest.approx([0.0, 0.4])
    bare = _Curve((1.0, 2.0, 0.0, 0.0), 0.0, 0.5)
    assert not figures._bands(ax, bare, "dp_n", "#0072B2") and len(ax.collections) == 2
    assert "carry no uncertainty" in figures.band_text([bare], ["dp_n"])
