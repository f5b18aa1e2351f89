"""Figures to compact PNG bytes: each figure drawn once into memory (Agg), its pixels mapped
onto one palette and encoded once at full size, and its thumbnail scaled from the same
pixels and encoded once (no PNG is decoded again).

Palette PNGs are a third of the bytes of RGB ones. A plot (its 256 most frequent colours
cover :data:`PLOT_COVERAGE` of its pixels: flat areas, lines, text) gets a palette of white,
the colours of :data:`EXACT` it holds (the load colours of small markers and thin curves),
then its most frequent colours; every pixel takes its nearest palette colour (Euclidean in
RGB), so a colour of the palette stays itself: a figure of at most 256 colours is encoded
losslessly, and the anti-aliased edges, its rarest colours, move to the nearest common one.
Anything else (a camera frame, a colour map) is quantised by median cut instead.
"""

from __future__ import annotations

import io
from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")  # no display, no GUI toolkit: the page is rendered headless

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from PIL import Image

from campaign_report.style import LOAD_COLOURS

FULL_DPI = 100
#: matplotlib settings the page's figures are made and drawn with: unhinted glyphs (no
#: visible difference at these sizes; a figure of the time series draws in three quarters
#: of the time)
RENDER_RC = {"text.hinting": "no_hinting"}
THUMB_WIDTH_PX = 300
PALETTE_SIZE = 256
PLOT_COVERAGE = 0.9
#: colours a plot's palette holds whenever they occur, whatever their area
EXACT = ("#ffffff", "#000000", *LOAD_COLOURS)
#: colours of a median-cut palette (not a plot)
MEDIAN_CUT_COLOURS = 128
WHITE_KEY = 0xFFFFFF
#: colour key (R | G << 8 | B << 16) -> palette index; only the keys of the image being
#: mapped are set and read, so it is reused without clearing (16 MiB, allocated lazily)
_INDEX = np.zeros(1 << 24, np.uint8)
_CHUNK = 8192  # colours per distance block (8192 x 256 float32: 8 MiB)


@dataclass(frozen=True)
class Rendered:
    """A figure's pixels (RGBA, opaque), its palette (colour keys, white first; None: not a
    plot, quantised by median cut) and its colours other than white (sorted keys)."""

    rgba: np.ndarray
    palette: np.ndarray | None
    colours: np.ndarray


def _key(colour: str) -> int:
    r, g, b = (int(colour[i:i + 2], 16) for i in (1, 3, 5))
    return r | g << 8 | b << 16


def _keys(rgba: np.ndarray) -> np.ndarray:
    """One uint32 key per pixel of an (h, w, 4) uint8 image, alpha dropped."""
    return np.ascontiguousarray(rgba).view("<u4").reshape(-1) & 0xFFFFFF


def _rgb(keys: np.ndarray) -> np.ndarray:
    return np.stack([keys & 255, (keys >> 8) & 255, keys >> 16], axis=1).astype(np.float32)


def _palette(keys: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """White, the colours of :data:`EXACT` present, then the most frequent others
    (:data:`PALETTE_SIZE` in all; None when the image is not a plot), and the image's
    colours other than white."""
    colours, counts = np.unique(keys[keys != WHITE_KEY], return_counts=True)
    order = np.argsort(-counts, kind="stable")
    if counts[order[:PALETTE_SIZE - 1]].sum() + (keys.size - counts.sum()) \
            < PLOT_COVERAGE * keys.size:
        return None, colours
    present = set(colours.tolist())
    exact = [k for c in EXACT if (k := _key(c)) == WHITE_KEY or k in present]
    chosen = dict.fromkeys(exact + colours[order][:PALETTE_SIZE].tolist())
    return np.fromiter(chosen, np.uint32)[:PALETTE_SIZE], colours


def _indices(keys: np.ndarray, palette: np.ndarray, colours: np.ndarray | None = None
             ) -> np.ndarray:
    """Each pixel's nearest palette index (uint8); ``colours``: the image's colours other
    than white, if known."""
    if colours is None:
        colours = np.unique(keys[keys != WHITE_KEY])
    _INDEX[palette] = np.arange(palette.size)  # a palette colour is its own nearest
    colours = colours[~np.isin(colours, palette, assume_unique=True)]
    p = _rgb(palette)
    p_sq = (p * p).sum(axis=1)
    for start in range(0, colours.size, _CHUNK):
        block = colours[start:start + _CHUNK]
        c = _rgb(block)
        _INDEX[block] = np.argmin(p_sq[None, :] - 2.0 * (c @ p.T), axis=1)
    _INDEX[WHITE_KEY] = 0  # white: the palette's first colour
    return _INDEX[keys]


def encode(rgba: np.ndarray, palette: np.ndarray | None,
           colours: np.ndarray | None = None) -> bytes:
    """An (h, w, 4) image as a PNG of ``palette``'s colours (nearest colour, no dithering);
    ``None``: of its median-cut colours. ``colours``: the image's colours other than white,
    if known."""
    if palette is None:
        image = Image.fromarray(rgba[..., :3]).quantize(MEDIAN_CUT_COLOURS,
                                                        method=Image.Quantize.MEDIANCUT)
    else:
        image = Image.fromarray(_indices(_keys(rgba), palette, colours).reshape(rgba.shape[:2]),
                                "P")
        image.putpalette(_rgb(palette).astype(np.uint8).ravel().tolist())
    out = io.BytesIO()
    image.save(out, format="PNG")
    return out.getvalue()


def render(fig: Figure, dpi: int = FULL_DPI) -> Rendered:
    """``fig`` drawn once at ``dpi`` on white (its pixels copied out of the canvas), and its
    palette."""
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    if fig.dpi != dpi:
        fig.set_dpi(dpi)
    fig.patch.set_facecolor("white")
    canvas.draw()
    rgba = np.array(canvas.buffer_rgba(), copy=True)
    return Rendered(rgba, *_palette(_keys(rgba)))


def png(rendered: Rendered) -> bytes:
    """A rendered figure as a palette PNG (:func:`encode` with its palette and colours)."""
    return encode(rendered.rgba, rendered.palette, rendered.colours)


def to_png(fig: Figure, dpi: int = FULL_DPI) -> tuple[bytes, Rendered]:
    """The figure as a palette PNG, and its pixels and palette (for :func:`thumbnail`)."""
    rendered = render(fig, dpi)
    return png(rendered), rendered


def thumbnail(rendered: Rendered, width: int = THUMB_WIDTH_PX) -> bytes:
    """The figure scaled down to ``width`` pixels wide (aspect kept; Hamming filter: a
    third of Lanczos' cost), as a PNG of the full figure's palette (median cut of its own if
    the figure is not a plot)."""
    h, w = rendered.rgba.shape[:2]
    small = Image.fromarray(rendered.rgba, "RGBA").convert("RGB").resize(
        (width, max(1, round(h * width / w))), Image.Resampling.HAMMING).convert("RGBA")
    return encode(np.asarray(small), rendered.palette)
