"""Decay rates fitted jointly over neighbouring angles (softflow.decay_fit.fit_decay_across,
softflow.field_analysis.fit_profiles): profiles drawn here from A exp(-k rho) with k linear in the
angle, plus white noise of a known size."""

from __future__ import annotations

import numpy as np
import pytest

from softflow.decay_fit import fit_decay, fit_decay_across
from softflow.field_analysis import BIN_WIDTH_DEG, fit_profiles

RHO_M = np.arange(0.014, 0.08, 0.002)
STEP_RAD = np.deg2rad(BIN_WIDTH_DEG)
K0_PER_M, SLOPE_PER_M_RAD = 50.0, 40.0  # k = 50 + 40 dbeta: 43.0, 50.0, 57.0 /m at -10, 0, 10 deg
AMPLITUDE_MPS = 0.03
NOISE_MPS = 3e-4


def _profiles(rng):
    out = []
    for i in range(3):
        k = K0_PER_M + SLOPE_PER_M_RAD * (i - 1) * STEP_RAD
        out.append(AMPLITUDE_MPS * np.exp(-k * RHO_M) + rng.normal(0, NOISE_MPS, RHO_M.size))
    return out


def test_joint_fit_is_unbiased_for_a_linear_rate_and_scatters_less():
    """Three profiles of about equal information: the centre rate's scatter falls towards
    1/sqrt(3) of the single fit's (the slope is orthogonal to it), with no bias."""
    rng = np.random.default_rng(11)
    sigma = [np.full(RHO_M.size, NOISE_MPS)] * 3
    offsets = np.array([-1.0, 0.0, 1.0]) * STEP_RAD
    joint, own, covered = [], [], []
    for _ in range(300):
        values = _profiles(rng)
        f = fit_decay_across([RHO_M] * 3, values, sigma, offsets, 1)
        joint.append(f.rate_per_m)
        covered.append(f.ci95_per_m[0] <= K0_PER_M <= f.ci95_per_m[1])
        own.append(fit_decay(RHO_M, values[1], sigma[1]).rate_per_m)
        assert f.points == RHO_M.size and f.joint_offsets_deg == (-10.0, 0.0, 10.0)
    joint, own = np.array(joint) - K0_PER_M, np.array(own) - K0_PER_M
    assert abs(joint.mean()) < 0.01 * K0_PER_M  # the slope is fitted: no bias from it
    rms_joint, rms_own = np.sqrt(np.mean(joint ** 2)), np.sqrt(np.mean(own ** 2))
    assert rms_joint < 0.7 * rms_own, (rms_joint, rms_own)
    assert np.mean(covered) >= 0.9


def test_fit_profiles_takes_the_next_bins_inwards_at_the_end_of_the_data():
    """Bins 3-8 hold profiles (k linear in the angle, no noise): bin 3 is fitted with 4 and 5,
    bin 5 with 4 and 6, and the rates are the law's; a bin alone keeps its own fit."""
    n = int(round(360 / BIN_WIDTH_DEG))
    rim_px, px_per_m = 72.0, 1000.0
    r_px = rim_px + RHO_M * px_per_m
    empty = (np.empty(0), np.empty(0), np.empty(0))
    prof = [empty] * n
    law = {j: K0_PER_M + SLOPE_PER_M_RAD * (j - 5) * STEP_RAD for j in (*range(3, 9), 20)}
    for j, k in law.items():
        prof[j] = (r_px, AMPLITUDE_MPS * np.exp(-k * RHO_M), np.full(RHO_M.size, NOISE_MPS))
    fits = fit_profiles(prof, rim_px, px_per_m)
    assert fits[3].joint_offsets_deg == (0.0, 10.0, 20.0)
    assert fits[5].joint_offsets_deg == (-10.0, 0.0, 10.0)
    assert fits[8].joint_offsets_deg == (-20.0, -10.0, 0.0)
    assert fits[20].joint_offsets_deg == (0.0,)
    assert fits[0] is None and fits[12] is None
    for j, k in law.items():
        assert fits[j].rate_per_m == pytest.approx(k, rel=1e-6), j
