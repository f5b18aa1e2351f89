"""Figures to compact PNG bytes: full size at a moderate resolution, and small thumbnails."""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")  # no display, no GUI toolkit: the page is rendered headless

from matplotlib.figure import Figure  # noqa: E402
from PIL import Image  # noqa: E402

FULL_DPI = 100
THUMB_WIDTH_PX = 300
#: palette size of the quantised PNGs (a third of the bytes of RGB); median cut keeps the
#: load colours of small markers distinct, where a fast octree merged orange into vermilion
COLOURS = 128


def _quantised_png(image: Image.Image) -> bytes:
    out = io.BytesIO()
    image.convert("RGB").quantize(COLOURS, method=Image.Quantize.MEDIANCUT).save(
        out, format="PNG")
    return out.getvalue()


def to_png(fig: Figure, dpi: int = FULL_DPI) -> tuple[bytes, Image.Image]:
    """The figure as a palette PNG, and the full-resolution image (for a thumbnail)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi, facecolor="white")
    image = Image.open(io.BytesIO(buffer.getvalue()))
    image.load()
    return _quantised_png(image), image


def thumbnail(image: Image.Image, width: int = THUMB_WIDTH_PX) -> bytes:
    """``image`` scaled down to ``width`` pixels wide (aspect kept), as a palette PNG."""
    height = max(1, round(image.height * width / image.width))
    return _quantised_png(image.convert("RGB").resize((width, height), Image.Resampling.LANCZOS))
