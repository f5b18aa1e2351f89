"""Plausibility and sensor-health flags (issue 17), each on a run written here: a real
virtual-testbed run with one channel or metadata value changed in its MCAP bytes."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import ingest
from bench.mcap_content import read_content, write_content
from run_results import process_run
from run_results.plausibility import plausibility_flags
from stable_phase import StablePhaseParams

SAMPLE = Path(__file__).resolve().parents[1] / "sample_data" / "campaign"
GOOD = SAMPLE / "L180_MP0_SC_s+020.mcap"   # speed control, 180 N, no DP calibration record


def _process(tmp_path: Path, change=None, metadata: dict | None = None):
    content = read_content(GOOD)
    for (record, key), value in (metadata or {}).items():
        content.metadata[f"swt.{record}"][key] = value
    if change is not None:
        change(content)
    run = ingest.read_run(write_content(tmp_path / "changed.mcap", content))
    return run, process_run(run)


def _map_field(content, topic: str, fields: tuple[str, ...], f) -> None:
    """``field = f(t_s, field values)`` over every block of ``topic``."""
    blocks = content.blocks(topic)
    for name in fields:
        t = np.concatenate([np.asarray(b["t_ns"], float) for b in blocks]) * 1e-9
        y = np.concatenate([np.asarray(b[name], float) for b in blocks])
        new, start = f(t, y), 0
        for b in blocks:
            b[name] = new[start:start + len(b[name])].tolist()
            start += len(b[name])
    content.set_blocks(topic, blocks)


def _flags(result, start: str) -> list[str]:
    return [f for f in result.flags if f.startswith(start)]


def test_the_unchanged_run_is_ok(tmp_path):
    _, result = _process(tmp_path)
    assert result.status == "ok" and result.flags == ()


def test_a_load_cell_saturating_30_n_below_the_load_is_flagged(tmp_path):
    """fz clipped at 150 N while it reads 180 N (raw units: zero included): every sample sits
    at the rail, a constant channel whose SE is 0."""
    run, plain = _process(tmp_path)
    rail = 150.0 + run.metadata.zero["fz"]
    _, result = _process(tmp_path, lambda c: _map_field(c, "/hub/wrench", ("fz",),
                                                        lambda t, y: np.minimum(y, rail)))
    assert plain.quantities["wheel_load_n"].mean == pytest.approx(180.0, abs=5.0)
    assert result.quantities["wheel_load_n"].mean == pytest.approx(150.0)
    assert _flags(result, "fz_n is constant (150)") and _flags(result, "wheel_load_n: SE of 0")
    assert result.status == "flagged"


def test_a_load_cell_clipping_its_peaks_is_flagged(tmp_path):
    """fz clipped at its own 70th percentile: 30 % of the samples pile up at the rail."""
    def clip(t, y):
        return np.minimum(y, np.percentile(y, 70))

    _, result = _process(tmp_path, lambda c: _map_field(c, "/hub/wrench", ("fz",), clip))
    (flag,) = _flags(result, "fz_n saturated")
    share = float(flag.split(": ")[1].split(" %")[0])
    assert 20.0 < share < 40.0 and "at its maximum" in flag and result.status == "flagged"


def test_torque_saturating_is_flagged(tmp_path):
    def clip(t, y):
        return np.minimum(y, np.percentile(y, 80))

    _, result = _process(tmp_path, lambda c: _map_field(c, "/hub/wrench", ("ty",), clip))
    assert _flags(result, "ty_nm saturated") and result.status == "flagged"


def test_all_wrench_channels_zero_is_dead_channels_negative_load_and_se_zero(tmp_path):
    fields = ("fx", "fy", "fz", "tx", "ty", "tz")
    run, result = _process(tmp_path, lambda c: _map_field(c, "/hub/wrench", fields,
                                                          lambda t, y: 0.0 * y))
    assert len(_flags(result, "f")) >= 3 and _flags(result, "fz_n is constant")
    load = -run.metadata.zero["fz"]
    assert result.quantities["wheel_load_n"].mean == pytest.approx(load)
    if load < 0:
        assert _flags(result, "negative wheel load")
    else:
        assert _flags(result, "measured wheel load")
    assert _flags(result, "wheel_load_n: SE of 0") and _flags(result, "torque_nm: SE of 0")


def test_a_constant_suspension_angle_is_a_dead_sensor_and_negative_sinkage(tmp_path):
    """The arm reads its zero angle: hub height 0, so the flexible wheel's sinkage is
    -fz/(1000 k) = -180/(1000*30) = -6 mm (spec), beyond the noise."""
    run, result = _process(tmp_path, lambda c: _map_field(
        c, "/suspension/angle", ("angle",), lambda t, y: 0.0 * y + 0.05))
    assert run.metadata.suspension.angle_zero_rad == 0.05
    assert run.metadata.wheel.stiffness_n_per_mm == 30.0
    assert result.quantities["sinkage_m"].mean == pytest.approx(-0.006, abs=0.0005)
    assert _flags(result, "suspension_angle_rad is constant")
    assert _flags(result, "negative sinkage -6")


def test_set_load_far_from_the_measured_load_is_flagged(tmp_path):
    _, result = _process(tmp_path, metadata={("run", "load_N"): "1800"})
    (flag,) = _flags(result, "measured wheel load")
    assert "set 1800 N" in flag


@pytest.mark.parametrize("key, value, words", [
    ("radius_m", "3.0", "wheel.radius_m 3 m outside the plausible"),
    ("width_m", "0.005", "wheel.width_m 0.005 m outside the plausible"),
    ("stiffness_N_per_mm", "0.01", "wheel.stiffness_N_per_mm 0.01 N/mm"),
    ("grouser_count", "500", "wheel.grouser_count 500  outside"),
    ("grouser_height_m", "0.2", "wheel.grouser_height_m 0.2 m outside"),
])
def test_metadata_outside_the_plausible_range_is_flagged(tmp_path, key, value, words):
    _, result = _process(tmp_path, metadata={("wheel", key): value})
    assert any(words in f for f in _flags(result, "metadata")), result.flags


def test_a_wheel_that_never_turns_is_flagged(tmp_path):
    _, result = _process(tmp_path, lambda c: _map_field(c, "/wheel/encoder", ("angle",),
                                                        lambda t, y: 0.0 * y))
    assert _flags(result, "wheel_angle_rad is constant")
    assert _flags(result, "wheel_surface_speed_mps held 0 m/s instead of its set point")


def test_a_dig_in_with_a_flat_tail_is_flagged(tmp_path):
    """DP rises by a bump 100 exp(-((t - 15)/4)^2) N and falls back to its level well before
    the stable window (29-57 s in truth), clear of the rest readings (before 3 s): the tail
    is flat, the run dug in. Seen through a moving mean over one grouser period T, the
    bump's peak is 100 sqrt(pi) 4 erf(T/8) / T N above the level."""
    from math import erf, pi, sqrt

    _, plain = _process(tmp_path)
    bump = lambda t, y: y + 100.0 * np.exp(-(((t - 15.0) / 4.0) ** 2))  # noqa: E731
    _, result = _process(tmp_path, lambda c: _map_field(c, "/tether/force", ("dp",), bump))
    assert result.window.found and result.window.start_s > 25.0
    (flag,) = _flags(result, "dig-in: drawbar pull rose")
    level = plain.quantities["dp_n"].mean
    assert result.quantities["dp_n"].mean == pytest.approx(level, abs=1.0)
    period = result.window.diagnostics["grouser_period_s"]
    expected = level + 100.0 * sqrt(pi) * 4.0 * erf(period / 8.0) / period
    peak = float(flag.split("rose to ")[1].split(" N")[0])
    assert peak == pytest.approx(expected, abs=3.0)
    assert plain.flags == () and result.status == "flagged"


def test_an_overshoot_settling_from_the_start_is_no_dig_in(tmp_path):
    """The run settling to its slip-sinkage (gap bench seed 30 c013): the DP is 60 N above
    its level when the speeds are up (gate at 3.9 s) and decays as exp(-(t - 5)/4 s) into
    the window. It collapses by more than the dig-in check's share, but it never rose after
    the gate: no flag, and the window's DP is the plain run's (4 s constant: 0.05 N left at
    the window's start)."""
    overshoot = lambda t, y: y + 60.0 * np.exp(-np.clip(t - 5.0, 0.0, None) / 4.0) \
        * (t > 3.0)  # noqa: E731
    _, plain = _process(tmp_path)
    _, settling = _process(tmp_path, lambda c: _map_field(c, "/tether/force", ("dp",),
                                                          overshoot))
    assert settling.window.diagnostics["gate_start_s"] < 5.0
    assert settling.window.found and not _flags(settling, "dig-in")
    assert settling.status == "ok"
    assert settling.quantities["dp_n"].mean == pytest.approx(plain.quantities["dp_n"].mean,
                                                              abs=0.5)


def test_sinkage_growing_through_the_first_window_is_a_dig_in(tmp_path):
    """The hub sinks 4 mm more, at a steady 0.2 mm/s from 20 to 40 s, then holds: the window
    kept is the flat second half, and the growth through the first candidate window (at most
    the 4 mm of the ramp) is flagged."""
    arm_m = 0.6

    def sink(t, angle):
        drop_m = np.clip((t - 20.0) / 20.0, 0.0, 1.0) * 0.004
        return np.arcsin(np.sin(angle) - drop_m / arm_m)  # h = L (sin a - sin a0), spec

    run, result = _process(tmp_path, lambda c: _map_field(c, "/suspension/angle", ("angle",),
                                                          sink))
    assert run.metadata.suspension.arm_length_m == arm_m
    assert result.window.diagnostics["shrunk_to_second_half"]
    (flag,) = _flags(result, "dig-in: sinkage grew by")
    grown_mm = float(flag.split("grew by ")[1].split(" mm")[0])
    assert 0.5 < grown_mm <= 4.0 and result.status == "flagged"


def test_a_torque_zero_far_off_is_repaired_by_the_rests_and_flagged_without_them(tmp_path):
    """swt.zero.ty = 500 N*m instead of its own zero z0 (found by the fuzzer, stored as ok
    before): the rest readings re-measure the torque's zero, so the thrust is the plain
    run's and the correction the shift; the thrust the bad zero gives without rests, about
    -3900 N against a 180 N load, is flagged."""
    plain_run, plain = _process(tmp_path)
    run, result = _process(tmp_path, metadata={("zero", "ty"): "500"})
    shift_nm = 500.0 - plain_run.metadata.zero["ty"]
    assert result.quantities["thrust_n"].mean == pytest.approx(
        plain.quantities["thrust_n"].mean, abs=0.5)
    assert result.uncertainty["torque_nm"].correction == pytest.approx(shift_nm, rel=1e-3)
    thrust = (plain.quantities["torque_nm"].mean - shift_nm) / run.metadata.wheel.radius_m
    unrepaired = {**result.quantities,
                  "thrust_n": replace(result.quantities["thrust_n"], mean=thrust)}
    flags = plausibility_flags(run, result.window, unrepaired, StablePhaseParams())
    assert any(f.startswith("thrust T/r") and "over 1.5 times the wheel load" in f
               for f in flags)


def test_electrical_spikes_are_flagged(tmp_path):
    """Three fz samples at 35, 40 and 45 s read 1000 N more (found by the fuzzer: the spikes
    inflate the SE until a negative sinkage looked like noise, stored as ok)."""
    def spikes(t, y):
        y = y.copy()
        y[[int(np.argmin(np.abs(t - s))) for s in (35.0, 40.0, 45.0)]] += 1000.0
        return y

    _, result = _process(tmp_path, lambda c: _map_field(c, "/hub/wrench", ("fz",), spikes))
    (flag,) = _flags(result, "fz_n: 3 samples jump more than 360")
    assert "2 x the set load" in flag and result.status == "flagged"


def test_arm_encoder_spikes_are_flagged(tmp_path):
    """Three arm-angle samples 0.5 rad off: the hub height jumps by
    0.6 (sin(a + 0.5) - sin(a)) = about 0.27 m, more than the 0.125 m radius (found by the
    fuzzer: a negative sinkage hidden in the spikes' SE, stored as ok)."""
    def spikes(t, angle):
        angle = angle.copy()
        angle[[int(np.argmin(np.abs(t - s))) for s in (35.0, 40.0, 45.0)]] += 0.5
        return angle

    _, result = _process(tmp_path, lambda c: _map_field(c, "/suspension/angle", ("angle",),
                                                        spikes))
    (flag,) = _flags(result, "hub_height_m: 3 samples jump more than the wheel radius 0.125 m")
    assert result.status == "flagged" and flag.endswith("arm encoder spikes?")
