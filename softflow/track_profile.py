"""Where the grouser marks are: track direction, the strip holding them, its 1-D profile.

The marks are stripes across the track repeating along it, so they show as a peak
of the image's power spectrum whose frequency vector points along the track
(Fourier slice theorem: that peak is the periodicity of the projection along the
stripes). Candidates come from the spectrum whitened by its radial mean (sand is
isotropic); the strip is the band of image rows along that direction whose mean,
demodulated at that frequency, carries the pattern with the best signal-to-noise; the
direction is refined from the phase ramp across that band.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import cv2
import numpy as np
from scipy.ndimage import map_coordinates, maximum_filter1d, uniform_filter1d

STEP_PX = 0.5  # along-track sampling of the profile
BAND_BLOCK_ROWS = 64  # first rows of the bands find_band scores at once (memory, not results)


@dataclass(frozen=True)
class Strip:
    """The image resampled along a direction: rows across, columns along the track."""

    angle_rad: float  # along-track direction, image x right, y down
    samples: np.ndarray  # rows (1 px apart) x columns (STEP_PX apart)
    valid: np.ndarray  # same shape, True inside the image
    along_start_px: float  # position of column 0 along the track from the image centre

    @cached_property
    def counts(self) -> np.ndarray:
        """Valid samples in each row."""
        return self.valid.sum(axis=1)

    @cached_property
    def centred(self) -> np.ndarray:
        """Samples minus their row mean, zero outside the image."""
        n = np.maximum(self.counts, 1).astype(np.float32)
        x = np.where(self.valid, self.samples, np.float32(0))
        return np.subtract(x, (x.sum(axis=1) / n)[:, None], out=x, where=self.valid)


def direction_candidates(gray: np.ndarray, min_period_px: float, max_period_px: float,
                         separation_deg: float = 10.0) -> list[tuple[float, np.ndarray]]:
    """Candidate (direction in rad in [0, pi), frequencies in cycles/px), likeliest first.

    The power spectrum is resampled on a polar grid and divided by its mean over angle
    (sand and noise are isotropic). The marks put power along the track direction and
    the track's straight edges across it, so the two angles of highest mean whitened
    power are taken, each with its perpendicular; the frequencies are the three strongest
    local peaks along the candidate direction.
    """
    h, w = gray.shape
    win = np.outer(np.hanning(h), np.hanning(w)).astype(np.float32)
    power = np.abs(np.fft.fftshift(np.fft.fft2((gray - gray.mean()) * win, s=(2 * h, 2 * w)))) ** 2
    theta = np.radians(np.arange(0.0, 180.0, 0.5))
    freq = np.arange(1 / max_period_px, 1 / min_period_px, 1 / (4 * max(h, w)))
    cols = w + 2 * w * np.outer(np.cos(theta), freq)
    rows = h + 2 * h * np.outer(np.sin(theta), freq)
    polar = map_coordinates(power, [rows, cols], order=1)
    polar = uniform_filter1d(polar / (polar.mean(axis=0) + 1e-30), 3, axis=0, mode="wrap")
    strength = polar.mean(axis=1)
    angles = []
    for _ in range(2):
        best = theta[int(np.argmax(strength))]
        angles += [best, (best + np.pi / 2) % np.pi]
        for angle in angles[-2:]:
            strength[_angle_gap(theta, angle) < np.radians(separation_deg)] = -np.inf
    out = []
    for angle in dict.fromkeys(angles):
        i = int(np.argmin(_angle_gap(theta, angle)))
        line = polar[i]
        peaks = np.flatnonzero((line == maximum_filter1d(line, 9)) & (line > 0))
        out.append((float(angle), freq[peaks[np.argsort(line[peaks])[::-1][:3]]]))
    return out


def _angle_gap(theta: np.ndarray, angle: float) -> np.ndarray:
    """Distance between axis directions (mod pi)."""
    return np.abs((theta - angle + np.pi / 2) % np.pi - np.pi / 2)


def resample(gray: np.ndarray, angle_rad: float) -> Strip:
    """Sample the whole image on a grid along ``angle_rad`` centred on the image centre."""
    h, w = gray.shape
    half_len = 0.5 * np.hypot(h, w)
    a = np.arange(-half_len, half_len, STEP_PX, dtype=np.float32)
    c = np.arange(-half_len, half_len + 1, 1.0, dtype=np.float32)
    cos, sin = np.cos(angle_rad), np.sin(angle_rad)
    shape = (c.size, a.size)  # maps computed in float64, stored as float32
    map_x = np.subtract((w - 1) / 2 + a * cos, (c * sin)[:, None],
                        out=np.empty(shape, np.float32), casting="same_kind")
    map_y = np.add((h - 1) / 2 + a * sin, (c * cos)[:, None],
                   out=np.empty(shape, np.float32), casting="same_kind")
    samples = cv2.remap(gray, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    valid = cv2.bitwise_and(cv2.inRange(map_x, 0, w - 1), cv2.inRange(map_y, 0, h - 1)) != 0
    return Strip(angle_rad, samples, valid, float(a[0]))


def _row_demodulation(strip: Strip, freq_per_sample: float) -> np.ndarray:
    """Complex amplitude of each row at the frequency (mean over its valid samples)."""
    arg = (2 * np.pi * freq_per_sample * np.arange(strip.samples.shape[1])) % (2 * np.pi)
    both = strip.centred @ np.stack([np.cos(arg), -np.sin(arg)], axis=1).astype(np.float32)
    return (both[:, 0] + 1j * both[:, 1]) / np.maximum(strip.counts, 1)


def find_band(strip: Strip, freq_per_sample: float, min_len: float) -> tuple[int, int, float]:
    """Rows [lo, hi) whose summed profile carries the pattern at the frequency with the
    best signal-to-noise ratio: |coherent sum of the rows' complex amplitudes| over the
    square root of the samples summed (noise adds up incoherently), maximised over every
    contiguous band of at least 3 rows among the rows at least ``min_len`` long; and that
    ratio (in units of the image noise)."""
    n = strip.counts
    rows = np.flatnonzero(n >= min_len)
    if rows.size < 3:
        return 0, 0, 0.0
    first, last = rows[0], rows[-1] + 1
    n = n[first:last] * (n[first:last] >= min_len)
    z = _row_demodulation(strip, freq_per_sample)[first:last] * n
    total = np.concatenate([[0.0], np.cumsum(z)])
    count = np.concatenate([[0], np.cumsum(n)])
    best, lo_best, hi_best = 0.0, 0, 0
    for start in range(0, z.size - 2, BAND_BLOCK_ROWS):  # bands [lo, hi) with hi >= lo + 3
        lo = np.arange(start, min(start + BAND_BLOCK_ROWS, z.size))[:, None]
        hi = np.arange(start + 3, z.size + 1)[None, :]
        snr = np.abs(total[hi] - total[lo]) / np.sqrt(np.maximum(count[hi] - count[lo], 1))
        snr[:, :lo.size] = np.triu(snr[:, :lo.size])  # hi - lo < 3 below that diagonal
        row, col = divmod(int(np.argmax(snr)), snr.shape[1])
        if snr[row, col] > best:  # the first of equal maxima, as one argmax over all bands
            best, lo_best, hi_best = float(snr[row, col]), start + row, start + 3 + col
    return int(first + lo_best), int(first + hi_best), best


def shear_slope(strip: Strip, lo: int, hi: int, freq_per_sample: float) -> float:
    """Along-track shift of the pattern per row across rows [lo, hi) (px per px): the
    linear phase ramp across the rows that maximises their coherent sum. The direction
    is off by ``atan`` of it."""
    cols = strip.valid[lo:hi].all(axis=0)
    rows = Strip(strip.angle_rad, np.where(cols, strip.samples[lo:hi], 0.0),
                 np.broadcast_to(cols, (hi - lo, cols.size)), strip.along_start_px)
    z = _row_demodulation(rows, freq_per_sample)
    slopes = np.linspace(-0.5, 0.5, 1001)
    ramp = -2 * np.pi * freq_per_sample * slopes / STEP_PX  # phase step per row
    total = np.abs(np.exp(-1j * np.outer(ramp, np.arange(z.size))) @ z)
    i = int(np.clip(np.argmax(total), 1, slopes.size - 2))
    lo_, mid, hi_ = total[i - 1:i + 2]
    shift = 0.5 * (lo_ - hi_) / (lo_ - 2 * mid + hi_) if lo_ - 2 * mid + hi_ < 0 else 0.0
    return float(slopes[i] + shift * (slopes[1] - slopes[0]))


def coherence(strip: Strip, lo: int, hi: int, freq_per_sample: float) -> float:
    """How well rows [lo, hi) agree in phase at the frequency (1: stripes square to the
    direction; a wrong direction makes the phase turn across the band)."""
    cols = strip.valid[lo:hi].all(axis=0)
    rows = Strip(strip.angle_rad, np.where(cols, strip.samples[lo:hi], 0.0),
                 np.broadcast_to(cols, (hi - lo, cols.size)), strip.along_start_px)
    z = _row_demodulation(rows, freq_per_sample)
    return float(np.abs(z.sum()) / (np.abs(z).sum() + 1e-30))


def band_profile(strip: Strip, lo: int, hi: int) -> tuple[np.ndarray, int]:
    """Mean across rows [lo, hi) over the columns valid in every row, and its first column."""
    cols = np.flatnonzero(strip.valid[lo:hi].all(axis=0))
    if hi <= lo or cols.size == 0:
        return np.zeros(0), 0
    first, last = cols[0], cols[-1] + 1
    return strip.samples[lo:hi, first:last].mean(axis=0).astype(float), int(first)
