"""Run results scored against the virtual testbed's ground truth.

Means are compared with the truth's ``stable_means`` (noise-free means over the true
window) and, where the law gives the quantity, with ``law_steady`` (the steady value
without the grouser oscillation): the truth window is not a whole number of grouser periods,
so ``stable_means`` carries part of the oscillation (up to ~40 um of sinkage), while our
window holds whole periods. "1 %" is of the quantity's scale: the wheel load for forces
(DP/W to 0.01), load x radius for torque, 1 (i.e. 0.01) for slip, |truth| otherwise.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import ingest
from run_results import RigCompliance, process_run, results_table, towed_vs_powered
from virtual_testbed import RunCondition, SensorModel, generate_campaign
from virtual_testbed.sample_campaign import SAMPLE_RATES
from virtual_testbed.varied_campaign import varied_conditions, varied_forms
from virtual_testbed import Testbed as VirtualTestbed
from virtual_testbed.grousers import oscillation_shape

pytestmark = [pytest.mark.slow,  # the 56-run varied campaign and campaigns with drifting
              # load cells generated and processed
              pytest.mark.slow_campaign]

RATES = SAMPLE_RATES
TRUTH_KEY = {"resistance_n": "motion_resistance_n"}
LAW_KEY = {"slip": "slip", "dp_n": "dp_n", "torque_nm": "torque_nm", "thrust_n": "thrust_n",
           "resistance_n": "resistance_n", "sinkage_m": "sinkage_m"}
FORCES = ("wheel_load_n", "dp_n", "thrust_n", "resistance_n")


def _processed(out):
    """(truth, run, result) per run of a ``varied_conditions`` campaign written to ``out``."""
    pairs = []
    for c in varied_conditions():
        truth = json.loads((out / "truth" / f"{c.run_id}.json").read_text())
        run = ingest.read_run(out / truth["raw_file"])
        pairs.append((truth, run, process_run(run)))
    return pairs


@pytest.fixture(scope="module")
def processed(varied_campaign):
    """The default testbed: its load cells drift (random walk, ~0.5 N) after zeroing
    (conftest's campaign, shared with tests/test_stable_phase_virtual.py)."""
    return _processed(varied_campaign)


@pytest.fixture(scope="module")
def processed_no_drift(tmp_path_factory):
    """Same design, load cells without drift: what the window statistics can see."""
    sensors = SensorModel(force_drift_n=0.0, torque_drift_nm=0.0)
    out = tmp_path_factory.mktemp("results_no_drift")
    conditions = varied_conditions()
    generate_campaign(out, conditions, seed=12, rates=RATES, form=varied_forms(conditions),
                      testbed=VirtualTestbed(sensors=sensors))
    return _processed(out)


def _scale(key: str, truth: dict, value: float) -> float:
    load = truth["condition"]["load_n"]
    if key in FORCES:
        return load
    if key == "torque_nm":
        return load * truth["law"].get("radius_m", 0.125)
    return 1.0 if key == "slip" else abs(value)


def _misses(pairs) -> tuple[list, int, dict]:
    """Means outside 1 % of scale and 2 u of both truths; how many checked; z-scores
    against the oscillation-free truth (law_steady where the law gives it). ``u``: the
    combined standard uncertainty of the budget (the means are re-zeroed on the rest
    readings, so the rests' noise is in them, and in ``u``, not in the SE)."""
    misses, checked, z = [], 0, {}
    for truth, _, result in pairs:
        if truth["stable_means"] is None:
            continue
        for key, q in result.quantities.items():
            tkey = TRUTH_KEY.get(key, key)
            if tkey not in truth["stable_means"] or (
                    key in ("dp_n", "resistance_n") and result.mode == "free_sled"):
                continue
            targets = [truth["stable_means"][tkey]]
            if key in LAW_KEY:
                targets.append(truth["law_steady"][LAW_KEY[key]])
            elif key == "wheel_load_n":
                targets.append(truth["condition"]["load_n"])   # fz = load + oscillation
            error = min((q.mean - x for x in targets), key=abs)
            u = result.uncertainty[key].u
            tol = max(0.01 * _scale(key, truth, targets[0]), 2.0 * u)
            checked += 1
            z.setdefault(key, []).append((q.mean - targets[-1]) / u)
            if abs(error) > tol:
                misses.append((truth["run_id"], key, error, error / _scale(key, truth,
                                                                            targets[0])))
    return misses, checked, z


def test_every_mean_within_1_percent_or_2_se_without_load_cell_drift(processed_no_drift):
    misses, checked, _ = _misses(processed_no_drift)
    assert checked >= 50 * 8 and misses == []


def test_means_with_drifting_load_cells(processed):
    """Means re-zeroed on the rest readings, within 1 % of scale or 2 u of the truth.
    Measured: 460/460 (before the budget, 459/460 within 1 % or 2 SE)."""
    misses, checked, _ = _misses(processed)
    assert checked >= 50 * 8 and len(misses) <= 0.01 * checked
    assert all(abs(rel) < 0.02 for *_, rel in misses)


def test_uncertainties_are_honest(processed_no_drift):
    """z = (mean - truth)/u over the runs, truth without the grouser oscillation, u the
    budget's combined standard uncertainty (clock bound at its default 100 ppm).

    Measured std of z (each run alone: no pooled drift): wheel load 0.77, DP 0.82,
    resistance 0.71, torque 0.71, sinkage 0.61 (was 2.45 on the SE alone: the 10 Hz arm
    encoder sees few phases of the sharp-edged grouser wave, now the budget's phase-sampling
    term, and its quantisation); slip 1.71, omega 1.68, travel velocity 1.81: the clock
    dominates them and the testbed's clocks err by up to 200 ppm, twice the default bound,
    so at most 2 (slip and omega read 1.1-1.2 while the batch means' fallback, the
    autocorrelation SE, overstated their noise). On the SE alone: wheel load 1.11, DP 1.21,
    torque 1.63."""
    _, _, z = _misses(processed_no_drift)
    spread = {k: float(np.std(v)) for k, v in z.items()}
    print({k: round(v, 2) for k, v in spread.items()})
    for key in ("wheel_load_n", "dp_n", "resistance_n"):
        assert 0.6 < spread[key] < 1.4, (key, spread[key])
    for key in ("slip", "wheel_omega_radps", "travel_velocity_mps"):
        assert 0.6 < spread[key] < 2.1, (key, spread[key])
    assert spread["torque_nm"] < 2.0 and spread["sinkage_m"] < 3.0


def test_grouser_frequency_and_waveform(processed):
    for truth, _, result in processed:
        if truth["stable_means"] is None:
            continue
        osc = result.oscillation
        assert osc["grouser_measured_hz"] == pytest.approx(
            truth["grouser_passing_frequency_hz"], rel=0.03)
        assert osc["grouser_expected_hz"] == pytest.approx(
            truth["grouser_passing_frequency_hz"], rel=0.01)
        shape = oscillation_shape(np.linspace(0, 2 * np.pi / 12, 2000), 12,
                                  truth["grousers_in_contact"])
        amplitude = truth["dynamics"]["dp_oscillation_ratio"] * truth["condition"]["load_n"]
        if result.mode != "free_sled":
            expected = amplitude * (shape.max() - shape.min())
            assert osc["dp_peak_to_peak_n"] == pytest.approx(expected, rel=0.15)
            assert osc["dp_peak_n"] == pytest.approx(
                truth["stable_means"]["dp_n"] + amplitude * shape.max(), abs=0.15 * expected)
        assert osc["torque_peak_to_peak_nm"] > 0


def test_no_stable_phase_runs_keep_their_dp_trace(processed):
    dig_in = [(t, r) for t, _, r in processed if t["stable_means"] is None]
    assert len(dig_in) == 4
    for truth, result in dig_in:
        assert result.status == "no_stable_phase" and result.quantities == {}
        assert "digs in" in result.flags[0]
        trace = result.dp_trace
        assert 100 < len(trace["t_s"]) <= 500 and len(trace["dp_n"]) == len(trace["t_s"])
        assert max(v for v in trace["dp_n"] if v is not None) == pytest.approx(
            truth["dig_in"]["dp_trend_peak_n"], rel=0.1)
        json.dumps(result.to_dict(), allow_nan=False)


def test_status_flags_tare_and_json(processed):
    for truth, _run, result in processed:
        assert result.corrections["tare"]["zero_offsets_subtracted"] == truth["measurement"]["zero"]
        assert result.corrections["rig_compliance"] is None
        assert result.condition.load_set_n == truth["condition"]["load_n"]
        json.dumps(result.to_dict(), allow_nan=False)
        if result.status != "no_stable_phase":
            assert result.status == ("flagged" if result.flags else "ok")
            assert set(result.quantities) >= {"slip", "travel_velocity_mps", "wheel_omega_radps",
                                              "wheel_load_n", "dp_n", "torque_nm", "thrust_n",
                                              "resistance_n", "sinkage_m"}
    assert sum(r.status == "ok" for _, _, r in processed) >= 40


def test_rig_compliance_shifts_hub_height_and_sinkage(processed):
    truth, run, plain = next(p for p in processed if p[0]["run_id"] == "sc00")
    rig = RigCompliance(kind="linear", m_per_n=2e-6, reference_load_n=0.0, source="test")
    result = process_run(run, rig=rig)
    load = plain.quantities["wheel_load_n"].mean
    shift = 2e-6 * load
    assert result.quantities["hub_height_m"].mean == pytest.approx(
        plain.quantities["hub_height_m"].mean + shift, abs=2e-6)
    assert result.quantities["sinkage_m"].mean == pytest.approx(
        plain.quantities["sinkage_m"].mean - shift, abs=2e-6)
    assert result.corrections["rig_compliance"] == rig.to_dict()
    assert result.corrections["hub_height_correction_mean_m"] == pytest.approx(shift, rel=0.01)
    table = RigCompliance.from_dict({"kind": "table", "load_n": [0, 400],
                                     "correction_m": [0.0, 8e-4]})
    assert RigCompliance.from_dict(table.to_dict()) == table
    assert table.correction(200.0) == pytest.approx(4e-4)
    with pytest.raises(ValueError):
        RigCompliance(kind="table", load_n=(1.0,), correction_m=(0.0,))


def test_towed_resistance_against_powered_runs_near_zero_slip(tmp_path):
    """BB2 testbed law at 180 N: R about 18 N at multipass 0, less on compacted soil."""
    conditions = [RunCondition.of(f"L180_MP{mp}_SC{i}", "speed_control", 180.0, mp, s)
                  for mp in (0, 1, 2) for i, s in enumerate((-0.1, -0.05, 0.0, 0.05, 0.1))]
    conditions += [RunCondition.of(f"L180_MP{mp}_TW", "towed", 180.0, mp) for mp in (0, 1, 2)]
    generate_campaign(tmp_path, conditions, seed=5, rates=RATES)
    results, truths = [], {}
    for c in conditions:
        truth = json.loads((tmp_path / "truth" / f"{c.run_id}.json").read_text())
        truths[c.run_id] = truth
        results.append(process_run(ingest.read_run(tmp_path / truth["raw_file"])))
    rows = {row["multipass"]: row for row in towed_vs_powered(results_table(results))}
    assert sorted(rows) == [0, 1, 2]
    for mp, row in rows.items():
        assert len(row["powered_runs"]) == 5 and row["towed_runs"] == [f"L180_MP{mp}_TW"]
        law_r0 = truths[f"L180_MP{mp}_SC2"]["law_steady"]["resistance_n"]
        law_towed = truths[f"L180_MP{mp}_TW"]["law_steady"]["resistance_n"]
        assert row["powered_resistance_at_zero_slip_n"] == pytest.approx(law_r0, abs=1.0)
        assert row["powered_method"] == "interpolated"
        assert row["towed_resistance_n"] == pytest.approx(law_towed, abs=1.0)
        assert row["difference_n"] == pytest.approx(law_towed - law_r0, abs=1.4)
    assert rows[0]["powered_resistance_at_zero_slip_n"] == pytest.approx(18.0, abs=1.5)
    r0 = {mp: row["powered_resistance_at_zero_slip_n"] for mp, row in rows.items()}
    assert r0[2] < r0[0]


def test_steered_run_reports_side_force_and_slip_angle(tmp_path):
    """A steered testbed run (10 deg slip angle): side force and slip angle against the truth."""
    condition = RunCondition.of("ST10", "steered", 180.0, 0, 0.2, steer_deg=10.0)
    generate_campaign(tmp_path, [condition], seed=3, rates=RATES)
    truth = json.loads((tmp_path / "truth" / "ST10.json").read_text())
    result = process_run(ingest.read_run(tmp_path / truth["raw_file"]))
    assert result.mode == "steered" and result.window.found
    side, means = result.quantities["side_force_n"], truth["stable_means"]
    assert means["side_force_n"] > 0.2 * 180.0  # the testbed's saturating side-force law
    assert side.mean == pytest.approx(means["side_force_n"], abs=max(3 * side.se, 0.01 * 180.0))
    assert result.quantities["slip_angle_deg"].mean == means["slip_angle_deg"] == 10.0
    assert result.quantities["slip"].mean == pytest.approx(0.2, abs=0.005)
    assert result.condition.steer_deg == 10.0
