"""Noise-free run dynamics: transient, dig-in, grouser oscillation, modes, suspension geometry."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from virtual_testbed.conditions import RunCondition
from virtual_testbed.grousers import grousers_in_contact, oscillation_shape, passing_frequency_hz
from virtual_testbed.law import bb2_sand_law, towed_slip
from virtual_testbed.measure import suspension_angle_rad
from virtual_testbed.rig import BB2_WHEEL, Suspension, Timeline, Wheel
from virtual_testbed.simulate import (Dynamics, simulate_true_run, surface_speed_mps,
                                      travel_speed_mps)

LAW, TL, DYN = bb2_sand_law(), Timeline(), Dynamics()


def _run(mode="speed_control", load=180.0, slip=0.3, multipass=0):
    cond = RunCondition.of("x", mode, load, multipass, slip if mode == "speed_control" else None)
    return simulate_true_run(cond, LAW, BB2_WHEEL, TL, DYN)


def _at(run, key, t_s):
    return np.interp(t_s, run.signals["t_s"], run.signals[key])


def test_slip_forms_of_the_spec():
    v = 0.0111
    for slip in (-0.1, 0.0, 0.2, 0.9):
        r_omega = float(surface_speed_mps(v, slip))
        expected = (r_omega - v) / r_omega if r_omega >= v else (r_omega - v) / v
        assert expected == pytest.approx(slip)
        assert float(travel_speed_mps(r_omega, slip)) == pytest.approx(v)


def test_transient_settles_in_about_25_s():
    run = _run()
    z_ss = run.steady["sinkage_m"]
    trend = run.signals["dp_trend_n"]
    t = run.signals["t_s"]
    assert TL.window_start_s == pytest.approx(29.0)
    assert _at(run, "sinkage_m", 3.0) < 0.8 * z_ss
    # The DP transient is the resistance following sinkage from the static sinkage
    # (0.6 x the zero-slip sinkage) to the steady one: amplitude R (1 - z_start / z_ss), decaying
    # with the time constant settle_time_s / 5 = 5 s (module docstring). Hand-calculated from
    # the law's steady values, not from the run: 15.9 N at 180 N and 30 % slip, 3.2 N left
    # at 10 s. (The old check, "more than 5 % of the steady DP at 10 s", measured the law's
    # R/DP ratio rather than the settling: the published grouser law's 8 % higher steady DP
    # put it at 4.7 %.)
    z_start = DYN.static_sinkage_ratio * float(LAW.evaluate(180.0, 0.0, 0, 9.81)["sinkage_m"])
    amplitude = run.steady["resistance_n"] * (1.0 - z_start / z_ss)
    left = amplitude * np.exp(-(10.0 - TL.motion_start_s) / (TL.settle_time_s / 5.0))
    # within 15 %: thrust still builds (shear, 1.5 s) by 0.3 N; a 4 s or 6 s constant is 30 % off
    assert np.interp(10.0, t, trend) - run.steady["dp_n"] == pytest.approx(left, rel=0.15)
    assert left > 0.01 * run.steady["dp_n"]  # not settled at 10 s by the 1 % rule below
    assert np.interp(TL.window_start_s, t, trend) == pytest.approx(run.steady["dp_n"], rel=0.01)
    assert _at(run, "omega_radps", 20.0) == pytest.approx(0.0111111 / 0.7 / 0.125, rel=1e-4)


def test_dig_in_dp_rises_then_collapses_and_sinkage_keeps_growing():
    run = _run(load=300.0, slip=0.9)
    assert run.digs_in and not _run(load=70.0, slip=0.9).digs_in
    trend, t = run.signals["dp_trend_n"], run.signals["t_s"]
    # DP rises above 0.4 W, then collapses below 0.15 W as the wheel digs in
    assert np.interp(7.0, t, trend) > 0.4 * 300.0 > 0.15 * 300.0 > np.interp(TL.decel_start_s, t,
                                                                            trend)
    sinkage = [np.interp(x, t, run.signals["sinkage_m"]) for x in (20.0, 40.0, 55.0)]
    assert sinkage[0] < sinkage[1] < sinkage[2]


def test_free_sled_and_towed_modes():
    free, towed = _run("free_sled"), _run("towed")
    assert np.all(free.signals["dp_n"] == 0.0)
    assert _at(free, "slip", 40.0) == pytest.approx(free.steady["slip"], abs=1e-4)
    assert _at(free, "velocity_mps", 40.0) == pytest.approx(0.0111111, rel=1e-3)
    assert towed.steady["slip"] == pytest.approx(towed_slip(LAW, 180.0, 0), abs=1e-6)
    assert abs(towed.steady["torque_nm"]) < 1e-6
    resistance = float(LAW.evaluate(180.0, towed.steady["slip"], 0)["resistance_n"])
    assert towed.steady["dp_n"] == pytest.approx(-resistance, abs=1e-3)


def test_grousers_two_to_three_in_contact_and_waveform_has_harmonics():
    assert grousers_in_contact(0.010, 0.125, 0.0092, 12) == pytest.approx(2.07, abs=0.01)
    assert grousers_in_contact(0.040, 0.125, 0.0092, 12) == 3.0
    angle = np.linspace(0.0, 2 * np.pi, 12000, endpoint=False)
    shape = oscillation_shape(angle, 12, 2.5)
    assert shape.mean() == pytest.approx(0.0, abs=1e-3)
    assert shape.std() == pytest.approx(1.0, rel=0.01)
    amplitude = np.abs(np.fft.rfft(shape)) / shape.size * 2
    assert amplitude[12] > 0.8 and amplitude[24] > 0.3 and amplitude[6] < 1e-3
    assert float(passing_frequency_hz(12, 2 * np.pi)) == 12.0


def test_oscillation_in_forces_at_the_grouser_frequency():
    run = _run(slip=0.6)
    t, fx = run.signals["t_s"], run.signals["fx_n"]
    keep = (t >= TL.window_start_s) & (t <= TL.decel_start_s)
    x = fx[keep] - fx[keep].mean()
    freq = np.fft.rfftfreq(8 * x.size, 1.0 / DYN.grid_hz)
    peak = freq[np.argmax(np.abs(np.fft.rfft(x * np.hanning(x.size), 8 * x.size)))]
    assert peak == pytest.approx(12 * 0.0111111 / 0.4 / 0.125 / (2 * np.pi), rel=0.02)


def test_suspension_angle_gives_the_sinkage():
    sus = Suspension(arm_length_m=0.6, angle_zero_rad=0.05)
    rigid = suspension_angle_rad(0.02, 180.0, replace(BB2_WHEEL, stiffness_n_per_mm=None), sus)
    assert -0.6 * (np.sin(rigid) - np.sin(0.05)) == pytest.approx(0.02)
    flexible = Wheel(0.125, 0.112, 12, 0.0092, stiffness_n_per_mm=60.0, name="flex")
    angle = suspension_angle_rad(0.02, 180.0, flexible, sus)
    hub_height = 0.6 * (np.sin(angle) - np.sin(0.05))
    assert -hub_height - 180.0 / (1000.0 * 60.0) == pytest.approx(0.02)


def test_smooth_wheel_has_no_grouser_oscillation():
    """A smooth rim (no grousers): the run simulates, DP and torque follow the steady law
    without the passing oscillation, no grousers in contact."""
    smooth = replace(BB2_WHEEL, grouser_count=0, grouser_height_m=0.0)
    cond = RunCondition.of("x", "speed_control", 180.0, 0, 0.3)
    run = simulate_true_run(cond, LAW, smooth, TL, DYN)
    t = run.signals["t_s"]
    window = (t > TL.window_start_s) & (t < TL.decel_start_s)
    dp = run.signals["dp_n"][window]
    assert run.grousers_in_contact == 0.0
    np.testing.assert_allclose(dp, run.signals["dp_trend_n"][window], rtol=0, atol=1e-12)
    assert np.std(dp) < 1e-3 * abs(run.steady["dp_n"])
