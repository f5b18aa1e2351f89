"""The uncertainty budget's parts against hand calculations and independent numerics
(run_results.uncertainty_budget, run_results.rest_readings, run_results.stats)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from scipy import integrate, stats

from run_results.rest_readings import quantisation_u as quantisation
from run_results.rest_readings import rest_readings, resolution
from run_results.stats import batch_se
from run_results.uncertainty_budget import (BudgetParams, QuantityBudget, Term, bridge_factor,
                                            combine, pooled_diffusion, rect_normal_quantile,
                                            zero_at_window)


def test_bridge_factor_matches_a_numerical_double_integral():
    # Var of the mean of a standard Brownian bridge over [p, q]: (1/L^2) iint min(u,v) - uv
    assert bridge_factor(0.0, 1.0) == pytest.approx(1 / 12)      # the known 1/12
    assert bridge_factor(0.0, 0.5) == pytest.approx(5 / 48)      # by hand: 0.026042 / 0.25
    for p, q in ((0.2, 0.9), (0.55, 0.95)):
        value, _ = integrate.dblquad(lambda u, v: min(u, v) - u * v, p, q, p, q)
        assert bridge_factor(p, q) == pytest.approx(value / (q - p) ** 2, rel=1e-6)


def test_bridge_factor_against_simulated_bridges():
    rng = np.random.default_rng(3)
    n, runs = 400, 4000
    walk = np.cumsum(rng.normal(0, math.sqrt(1 / n), (runs, n)), axis=1)
    u = np.arange(1, n + 1) / n
    bridge = walk - u * walk[:, -1:]
    inside = (u >= 0.3) & (u <= 0.8)
    assert np.var(bridge[:, inside].mean(axis=1)) == pytest.approx(bridge_factor(0.3, 0.8),
                                                                   rel=0.08)


def test_welch_satterthwaite_and_student_t():
    # GUM G.4.1: u = sqrt(1 + 4) , nu = 25 / (1/4 + 16/inf) = 100
    u, dof, k = combine([Term(1.0, 4.0), Term(2.0)])
    assert u == pytest.approx(math.sqrt(5)) and dof == pytest.approx(100.0)
    assert k == pytest.approx(stats.t.ppf(0.975, 100))
    assert combine([Term(3.0), Term(4.0)]) == pytest.approx((5.0, math.inf, 1.959964))


def test_rectangle_plus_normal_quantile_against_monte_carlo():
    assert rect_normal_quantile(1.0, 0.0) == pytest.approx(0.95)          # a rectangle alone
    assert rect_normal_quantile(0.0, 2.0) == pytest.approx(2 * 1.959964, rel=1e-5)
    rng = np.random.default_rng(4)
    x = rng.uniform(-1, 1, 2_000_000) + rng.normal(0, 0.4, 2_000_000)
    assert rect_normal_quantile(1.0, 0.4) == pytest.approx(np.quantile(x, 0.975), abs=3e-3)
    # a dominant rectangular clock term: k near its 1.65 (= 0.95 sqrt 3), not 1.96
    budget = QuantityBudget("m/s", 0.0, {"clock": Term(1.0, rectangular=True),
                                         "statistical": Term(0.05, 50.0)})
    assert budget.k == pytest.approx(1.65, abs=0.01)


def test_quantisation_undithered_and_dithered():
    q = 0.02
    assert quantisation(q, 0.0) == pytest.approx(q / math.sqrt(12))   # GUM F.2.2.1
    # input noise of one step: the quantiser's mean error is gone (Widrow): < 1e-8 of q
    assert quantisation(q, q) < 1e-8 * q
    # the mean of readings of a constant inside one step errs by up to q/2
    rng = np.random.default_rng(5)
    true = rng.uniform(0, 1, 20000) * q
    errors = np.round(true / q) * q - true
    assert np.std(errors) == pytest.approx(quantisation(q, 0.0), rel=0.02)


def test_resolution_of_quantised_readings():
    rng = np.random.default_rng(6)
    x = np.round(rng.normal(50.0, 0.5, 5000) / 0.02) * 0.02
    assert resolution(x) == pytest.approx(0.02, rel=1e-6)
    assert resolution(rng.normal(0, 1, 1000)) < 1e-3


def batch_means_se(y, batches: int = 20):
    """``run_results.stats.batch_se`` of a series' batch means (None under 4 samples a
    batch)."""
    size = y.size // batches
    if size < 4:
        return None
    return batch_se(y[:size * batches].reshape(batches, size).mean(axis=1))


def test_batch_means_see_a_slow_ripple_and_ignore_telescoping_noise():
    rng = np.random.default_rng(7)
    dt, n, tau = 0.02, 2000, 0.7          # 40 s at 50 Hz, AR(1) ripple of 0.7 s
    phi = math.exp(-dt / tau)
    means, ses = [], []
    for _ in range(300):
        ripple = np.zeros(n)
        for i in range(1, n):
            ripple[i] = phi * ripple[i - 1] + rng.normal(0, math.sqrt(1 - phi**2))
        means.append(ripple.mean())
        ses.append(batch_means_se(ripple)[0])
    # true sd of the mean of an AR(1) series: sqrt((1 + phi)/(1 - phi) / n)
    assert np.std(means) == pytest.approx(math.sqrt((1 + phi) / (1 - phi) / n), rel=0.12)
    assert np.median(ses) == pytest.approx(np.std(means), rel=0.25)
    # a rate from positions with white 1 mm noise: its mean telescopes to (x_end - x_0)/T,
    # sd sqrt(2) 1 mm / T = 3.5e-5 m/s; plain batch means say sqrt(B) = 4.5 times that
    # (measured 1.65e-4), the lag-1 term brings it to about twice (measured 7e-5; 40 % of
    # the estimates not positive: se 0, the budget keeps the ends' noise then)
    rates = [np.diff(0.01 * np.arange(n) * dt + 1e-3 * rng.normal(size=n)) / dt
             for _ in range(100)]
    plain = [np.std(r[:1980].reshape(20, 99).mean(axis=1), ddof=1) / math.sqrt(20)
             for r in rates]
    found = [f[0] for f in map(batch_means_se, rates) if f is not None]
    assert np.median(plain) == pytest.approx(math.sqrt(20) * math.sqrt(2) * 1e-3 / (n * dt),
                                             rel=0.1)
    assert np.median(found) < 0.6 * np.median(plain) and len(found) > 40

def _run(t, angle, dp, fz, load_n):
    frames = {"/wheel/encoder": pd.DataFrame({"t_s": t, "wheel_angle_rad": angle}),
              "/tether/force": pd.DataFrame({"t_s": t, "dp_n": dp}),
              "/hub/wrench": pd.DataFrame({"t_s": t, "fz_n": fz})}
    return SimpleNamespace(streams=frames, metadata=SimpleNamespace(
        run=SimpleNamespace(load_n=load_n)))


def test_rest_readings_recover_a_linear_zero_drift():
    """At rest 3 s before and after a 44 s drive the DP cell reads its drift 0.2 + 0.01 t N;
    the zero at a window of 20-40 s is 0.2 + 0.01 * 30 = 0.5 N."""
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 50.0, 0.01)
    moving = (t > 3.0) & (t < 47.0)
    angle = np.floor(np.cumsum(np.where(moving, 0.08, 0.0)) * 0.01 / 1e-3) * 1e-3
    drift = 0.2 + 0.01 * t
    dp = drift + rng.normal(0, 0.05, t.size) + np.where(moving, 40.0, 0.0)
    # fz: the wheel carries 180.5 N against a set 180 N, its zero drifting by 0.004 N/s
    fz = 180.5 + 0.004 * t + rng.normal(0, 0.05, t.size)
    rests = rest_readings(_run(t, angle, dp, fz, 180.0))
    assert rests.drive_s[0] == pytest.approx(3.0, abs=0.1)
    assert rests.drive_s[1] == pytest.approx(47.0, abs=0.1)
    z = zero_at_window(rests, "dp_n", (20.0, 40.0), 0.0)
    assert z.zero == pytest.approx(0.5, abs=0.01)
    assert z.part.change == pytest.approx(0.01 * (48.5 - 1.35), abs=0.01)
    # only fz's change since the first rest is drift: 0.004 * (30 - 1.35) = 0.115 N, not
    # the 0.5 N by which the actual load exceeds the set load (that is what fz measures)
    fz_zero = zero_at_window(rests, "fz_n", (20.0, 40.0), None).zero
    assert fz_zero == pytest.approx(0.004 * (30.0 - 1.35), abs=0.01)
    assert zero_at_window(None, "dp_n", (20.0, 40.0), 0.0).part is None


def test_the_rests_noise_enters_the_zero_with_the_weights_of_its_line():
    """No drift, rests of SE 0.1 N (before, 1 s) and 0.02 N (after, 41 s), a window whose
    middle is a quarter of the way (w = 0.25). The DP cell's zero, ``(1 - w) d0 + w d1``,
    spreads over 20,000 drawn rest means by ``hypot(0.75 * 0.1, 0.25 * 0.02)`` = 0.0752 N;
    fz's, ``w (d1 - d0)`` (its line starts at the first rest), by ``0.25 * hypot(0.1, 0.02)``
    = 0.0255 N: the rests' term of each must be that spread."""
    from run_results.rest_readings import Rest, RestReadings
    from run_results.stats import QuantityStats

    rng = np.random.default_rng(31)
    se_before, se_after, load_n = 0.1, 0.02, 150.0

    def rests(before: float, after: float) -> RestReadings:
        rest = {c: (Rest(1.0, QuantityStats(before + v, 0.0, se_before, 100, 100.0, "N")),
                    Rest(41.0, QuantityStats(after + v, 0.0, se_after, 100, 100.0, "N")))
                for c, v in (("dp_n", 0.0), ("fz_n", load_n))}
        return RestReadings((2.0, 40.0), {c: b for c, (b, _) in rest.items()},
                            {c: a for c, (_, a) in rest.items()})

    window_s = (8.0, 14.0)                           # middle 11 s: w = (11 - 1) / 40
    draws = [rests(*rng.normal(0.0, (se_before, se_after))) for _ in range(20_000)]
    for column, rest_value, expected in (("dp_n", 0.0, math.hypot(0.75 * 0.1, 0.25 * 0.02)),
                                         ("fz_n", None, 0.25 * math.hypot(0.1, 0.02))):
        zeros = [zero_at_window(r, column, window_s, rest_value).zero for r in draws]
        term = zero_at_window(draws[0], column, window_s, rest_value).part.means
        assert term.u == pytest.approx(expected)
        assert np.std(zeros) == pytest.approx(term.u, rel=0.03)


def test_pooled_diffusion_of_random_walk_drifts():
    """Cells drifting as random walks of 0.05 N^2/s: the pooled D^2/T comes back."""
    rng = np.random.default_rng(9)
    records = []
    for _ in range(400):
        d = rng.normal(0, math.sqrt(0.05 * 45.0))
        records.append({"before": {"dp_n": {"t_s": 1.5, "mean": 0.0, "se": 0.01}},
                        "after": {"dp_n": {"t_s": 46.5, "mean": d, "se": 0.01}}})
    pooled = pooled_diffusion([*records, None])
    assert pooled["dp_n"].u == pytest.approx(0.05, rel=0.15) and pooled["dp_n"].dof == 400


def test_an_unstated_clock_is_said_to_be_assumed():
    from run_results.uncertainty_budget import DEFAULT_CLOCK_PPM

    assert BudgetParams().clock_ppm == DEFAULT_CLOCK_PPM and BudgetParams().clock_missing
    assert BudgetParams(150.0).clock_ppm == 150.0 and BudgetParams(150.0).clock_missing == ()
    with pytest.raises(ValueError, match="must be >= 0"):
        BudgetParams(-1.0)


def test_phase_sampling_bounds_the_mean_of_a_sharp_wave_seen_m_times_a_period():
    """A sawtooth (rise 0 -> 1, drop 1) sampled m = 40 times a period: the sample mean errs
    by up to 1/(2m) (by hand: mean of frac(phi + k/m) = (m-1)/(2m) + phi'); the term is
    drop/(2m)/sqrt(3) with the drop read from the phase-averaged waveform (20 bins: 0.95)."""
    from run_results.uncertainty_budget import phase_sampling

    m, f = 40, 0.5
    t = np.arange(0, 40.0, 1 / (m * f))
    errors = [np.mod(f * t + phi, 1.0).mean() - 0.5 for phi in np.linspace(0, 1, 97)]
    assert max(map(abs, errors)) == pytest.approx(1 / (2 * m), rel=0.02)
    term = phase_sampling(t, np.mod(f * t + 0.3, 1.0), f)
    assert term.rectangular and term.u == pytest.approx(0.95 / (2 * m) / math.sqrt(3), rel=0.02)
    assert phase_sampling(t, np.mod(f * t, 1.0), None) is None


def test_rectangle_plus_a_vanishing_normal_is_the_rectangle():
    """A flat channel (found by the fuzzer): sigma 1e-14 of a, the quantile is a(2p - 1)."""
    from run_results.uncertainty_budget import rect_normal_quantile

    assert rect_normal_quantile(1.0, 1e-14) == pytest.approx(0.95, rel=1e-9)
    assert rect_normal_quantile(1.0, 0.05) == pytest.approx(0.95, abs=0.02)


def test_the_fz_zero_drifts_unseen_from_the_zeroing_to_the_first_rest():
    """fz is zeroed (swt.zero) at most ``zero_age_s`` = 120 s before the run and re-zeroed
    never: a random walk of diffusion 0.002 N^2/s over an age rectangular on [0, 120] s and
    the 1.35 s to the first rest's mean time. Its variance, checked against 20,000 simulated
    walks with ages drawn on [0, 120] s, is 0.002 * 60 = 0.12 N^2 above a fresh zero's; the
    DP cell, re-zeroed at the rests, has no unseen age."""
    rng = np.random.default_rng(8)
    t = np.arange(0.0, 50.0, 0.01)
    moving = (t > 3.0) & (t < 47.0)
    angle = np.floor(np.cumsum(np.where(moving, 0.08, 0.0)) * 0.01 / 1e-3) * 1e-3
    dp = rng.normal(0, 0.05, t.size) + np.where(moving, 40.0, 0.0)
    fz = 180.0 + rng.normal(0, 0.05, t.size)
    rests = rest_readings(_run(t, angle, dp, fz, 180.0))
    diffusion = {"fz_n": Term(0.002, 50.0), "dp_n": Term(0.002, 50.0)}
    mean_age_s = BudgetParams(zero_age_s=120.0).zero_age_mean_s
    fresh, aged = (zero_at_window(rests, "fz_n", (20.0, 40.0), None, age).part
                   for age in (0.0, mean_age_s))
    assert (fresh.age_s, aged.age_s) == (pytest.approx(1.35, abs=0.05),
                                         pytest.approx(61.35, abs=0.05))
    ages = np.random.default_rng(9).uniform(0.0, 120.0, 20_000)
    walks = np.random.default_rng(10).normal(0.0, np.sqrt(0.002 * ages))
    added = aged.term(diffusion).u ** 2 - fresh.term(diffusion).u ** 2
    assert added == pytest.approx(np.var(walks), rel=0.03)
    assert added == pytest.approx(0.12)
    dp_part = zero_at_window(rests, "dp_n", (20.0, 40.0), 0.0, mean_age_s).part
    assert dp_part.age_s == 0.0


def test_a_stated_shortest_zero_age_moves_the_mean_age_to_the_bounds_midpoint():
    """Bounds 30-180 s, rectangular (GUM 4.3.7): mean age 105 s, which 20,000 ages drawn
    uniformly between the bounds average to."""
    ages = np.random.default_rng(11).uniform(30.0, 180.0, 20_000)
    params = BudgetParams(zero_age_s=180.0, zero_age_min_s=30.0)
    assert params.zero_age_mean_s == pytest.approx(ages.mean(), rel=0.01)
    assert params.zero_age_mean_s == 105.0
    assert BudgetParams().zero_age_mean_s == 0.0
    with pytest.raises(ValueError, match="zero_age_min_s 200.0 needs zero_age_s"):
        BudgetParams(zero_age_s=180.0, zero_age_min_s=200.0)


def test_the_zero_age_is_read_from_the_campaign_settings(tmp_path):
    from swtlab.pipeline.process import budget_params

    (tmp_path / "swtlab.toml").write_text("[uncertainty]\nzero_age_s = 180\n")
    assert budget_params(tmp_path) == BudgetParams(None, 180.0)
    (tmp_path / "swtlab.toml").write_text("[uncertainty]\nzero_age_s = 180\n"
                                          "zero_age_min_s = 30\n")
    assert budget_params(tmp_path) == BudgetParams(None, 180.0, 30.0)
    with pytest.raises(ValueError, match="zero_age_s -5"):
        BudgetParams(zero_age_s=-5.0)


def test_batch_means_of_a_drive_ripple_cover_at_their_stated_degrees_of_freedom():
    """An AR(1) drive ripple of correlation time 0.7 s sampled at 36 Hz over 30 s (43
    correlation times: the second rig's drives): the window means are covered by
    ``+- t(0.975, dof) se`` about 95 % of the time, dof Satterthwaite's (B-1)(B-2)^2/(3B^2)
    = 5.13 for 20 batches (by hand); with B - 2 = 18 they were covered about 91 %. The
    mean of ``se^2`` is the variance of the mean less about 7 % (exact expectation: the
    ripple's correlation reaching past one batch of 1.5 s; measured 11 % here)."""
    from scipy.signal import lfilter

    rng = np.random.default_rng(12)
    n, phi = 1080, math.exp(-1 / 36 / 0.7)
    series = [lfilter([1.0], [1.0, -phi], np.r_[rng.normal(), rng.normal(
        0, math.sqrt(1 - phi**2), n - 1)]) for _ in range(1500)]
    found = [batch_means_se(y) for y in series]
    assert all(f[1] == pytest.approx(19 * 18**2 / 1200) for f in found if f)
    kept = [(y.mean(), f[0]) for y, f in zip(series, found) if f]
    means, ses = np.array(kept).T
    truth_var = np.var([y.mean() for y in series])
    assert 0.8 * truth_var <= np.mean(ses**2) <= truth_var
    k = stats.t.ppf(0.975, 19 * 18**2 / 1200)
    assert 0.93 <= np.mean(np.abs(means) <= k * ses) <= 0.97


def _wandering_wave(rng, pitches: int, per_pitch: int, noise_sd: float) -> np.ndarray:
    """A sawtooth of unit height that falls to zero mean over each of its pitches, whose
    boundaries wander (shifted by 5 % of a pitch, random per passage), plus white noise: the
    partial sums of the wave stay bounded, so it reaches the window mean only at the ends."""
    t = np.arange(pitches * per_pitch) / per_pitch + rng.uniform(0, 1)
    bounds = np.arange(-1, pitches + 3) + rng.normal(0, 0.05, pitches + 4)
    k = np.searchsorted(bounds, t, side="right") - 1
    u = (t - bounds[k]) / (bounds[k + 1] - bounds[k])
    return u - 0.5 + rng.normal(0, noise_sd, t.size)


@pytest.mark.parametrize(("noise_sd", "pitches"), [(0.02, 5), (0.02, 8), (0.3, 5)])
def test_pitch_batch_means_see_a_wandering_wave_mostly_at_the_window_ends(noise_sd, pitches):
    """Windows of 5 or 8 pitches of 80 samples, the wave phase-averaged out at the nominal
    frequency as the pipeline does; over 600 windows, printed: mean ``se^2`` over the
    variance of the window means, for this estimator and for twenty batches with their lag-1
    term, and the coverage of ``+- t(0.975, dof) se``. The wave dominant (noise 0.02), the
    twenty batches count it at every batch end (4.3 / 2.0 times the variance at 5 / 8
    pitches; measured 4.57 / 2.06), this one 1.90 / 1.15 (covered 98.0 / 94.2 %). With
    noise 0.3 it is low, 0.87 (twenty batches 1.41; covered 89.0 %): the non-negative fit
    drops ``a`` where the noisy long batches make it negative."""
    from run_results.phase_average import phase_average
    from run_results.stats import pitch_batch_means_se

    rng = np.random.default_rng(21 + pitches + int(10 * noise_sd))
    per_pitch = 80
    means, ses, dofs, old = [], [], [], []
    for _ in range(600):
        y = _wandering_wave(rng, pitches, per_pitch, noise_sd)
        average = phase_average(np.arange(y.size) / per_pitch, y, 1.0)
        se, dof = pitch_batch_means_se(y, per_pitch, average["periodic"])
        means.append(average["mean"])      # truth 0: the wave's mean over a pitch is 0
        ses.append(se)
        dofs.append(dof)
        old.append(batch_means_se(y - average["periodic"])[0])
    means, ses, old = np.array(means), np.array(ses), np.array(old)
    truth_var = np.var(means)
    ratio, old_ratio = np.mean(ses**2) / truth_var, np.mean(old**2) / truth_var
    covered = np.mean(np.abs(means) <= stats.t.ppf(0.975, dofs[0]) * ses)
    print(f"noise {noise_sd}, {pitches} pitches: se^2/var {ratio:.2f} (twenty batches "
          f"{old_ratio:.2f}), covered {covered:.3f}")
    assert dofs[0] == pytest.approx(1.5 * (pitches - 1))
    if noise_sd < 0.1:
        assert old_ratio >= 1.8 and ratio <= 0.6 * old_ratio
        assert 0.85 <= ratio <= 2.0 and covered >= 0.93
    else:
        assert 0.65 <= ratio <= 1.1 and 0.88 <= covered <= 0.97


def test_pitch_batch_means_of_white_noise_give_its_standard_error_a_little_low():
    """Ten pitches of white noise: mean ``se^2`` 0.90 of ``sigma^2/n`` (measured; the
    non-negative fit's truncation, see above)."""
    from run_results.stats import pitch_batch_means_se

    rng = np.random.default_rng(23)
    found = [pitch_batch_means_se(rng.normal(0, 2.0, 600), 60) for _ in range(400)]
    assert 0.8 <= np.mean([f[0] ** 2 for f in found]) / (4.0 / 600) <= 1.05
    assert pitch_batch_means_se(np.zeros(100), 60) is None      # under two pitches


def test_pitch_batch_means_leave_out_a_known_random_walk():
    """A Brownian walk of diffusion 0.002 per s plus white noise of sd 0.3, 40 samples a
    second (pitch 40, 8 pitches, n = 320): the walk alone triples the batch-means SE^2, as
    the load cells' drift did the virtual testbed's wheel load (3.1 times on seed 101). Over
    3,000 windows the mean ``var_L`` of the walk alone is ``s^2 L (n - L) / (6 n)`` (``s^2 =
    0.002 / 40`` per sample). With the walk's diffusion given, the SE^2 of walk plus noise
    falls back towards the noise's own (``0.3^2 / 320``; the same noise alone gives 0.82 of
    it, the fit's truncation on white noise): measured 1.63 of it against 2.66 with the walk
    counted, i.e. 56 % of the walk's excess left out. The rest is the walk's realised
    wander, which varies about its expectation by about as much: where what is left is
    negative (40 % of the windows) the non-negative fit resolves nothing and the independent
    samples' SE less the walk's share, here the noise's own, is taken; elsewhere the
    truncation keeps part of the wander."""
    from run_results.stats import pitch_batches

    rng = np.random.default_rng(41)
    n, pitch, dt_s, diffusion, noise_sd = 320, 40, 1 / 40, 0.002, 0.3
    walks = np.cumsum(rng.normal(0, math.sqrt(diffusion * dt_s), (3000, n)), axis=1)
    noise = rng.normal(0, noise_sd, (3000, n))
    var_l = np.mean([pitch_batches(w, pitch, dt_s=dt_s).var for w in walks], axis=0)
    sizes = pitch * np.arange(1, n // pitch)
    assert var_l == pytest.approx(diffusion * dt_s * sizes * (n - sizes) / (6 * n), rel=0.05)
    white = noise_sd**2 / n
    both = [pitch_batches(w + e, pitch, dt_s=dt_s) for w, e in zip(walks, noise)]
    left_out = np.mean([b.se(diffusion)[0] ** 2 for b in both]) / white
    counted = np.mean([b.se()[0] ** 2 for b in both]) / white
    alone = np.mean([pitch_batches(e, pitch, dt_s=dt_s).se()[0] ** 2 for e in noise]) / white
    print(f"se^2 / (sigma^2/n): walk left out {left_out:.3f}, counted {counted:.3f}, noise "
          f"alone {alone:.3f}")
    assert 0.8 <= alone <= 1.0 and counted >= 2.5
    assert alone <= left_out <= alone + 0.5 * (counted - alone)
    # the independent samples' SE less the walk's share is the white noise's SE
    floor = np.mean([b.var_sample - diffusion * dt_s * (n - 1) / (6 * n) for b in both])
    assert floor == pytest.approx(white, rel=0.02)
