"""Grouser passing oscillation: frequency, grousers in contact and waveform shape."""

from __future__ import annotations

import numpy as np


def passing_frequency_hz(grouser_count: int, omega_radps) -> np.ndarray:
    """Grouser passing frequency ``n*omega/2pi`` (Irani et al., J. Terramech. 48, 2011)."""
    return grouser_count * np.asarray(omega_radps, float) / (2.0 * np.pi)


def grousers_in_contact(sinkage_m: float, radius_m: float, grouser_height_m: float,
                        grouser_count: int) -> float:
    """Number of grousers in the soil, clipped to the 2-3 seen on sandy SWT runs.

    The contact arc is taken as twice the entry angle of the grouser tips,
    ``acos(1 - (z + h_g)/(r + h_g))`` (front and rear contact roughly equal).
    """
    r_tip = radius_m + grouser_height_m
    entry_rad = np.arccos(1.0 - (sinkage_m + grouser_height_m) / r_tip)
    pitch_rad = 2.0 * np.pi / grouser_count
    return float(np.clip(2.0 * entry_rad / pitch_rad, 2.0, 3.0))


def oscillation_shape(wheel_angle_rad, grouser_count: int, in_contact: float) -> np.ndarray:
    """Zero-mean, unit-RMS periodic load waveform of the grousers in contact.

    Each grouser's load grows quadratically while it digs through the contact
    arc and is released as it leaves; the sum over the ``in_contact`` grousers
    sharing the load gives a waveform at the passing frequency with harmonics.
    """
    pitch_rad = 2.0 * np.pi / grouser_count
    grid = np.linspace(0.0, pitch_rad, 512, endpoint=False)
    phase = grid[:, None] + pitch_rad * np.arange(int(np.ceil(in_contact)) + 1)[None, :]
    u = phase / (in_contact * pitch_rad)
    load = np.where(u < 1.0, u * u, 0.0).sum(axis=1)
    load = (load - load.mean()) / load.std()
    psi = np.mod(np.asarray(wheel_angle_rad, float), pitch_rad)
    return np.interp(psi, np.append(grid, pitch_rad), np.append(load, load[0]))
