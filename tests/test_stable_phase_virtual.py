"""Stable-phase detection scored against the virtual testbed's ground truth (>= 50 varied runs).

Acceptance (issue): window start within 2 s of the truth for >= 95 % of the runs; every run
without a stable phase (dig-in) flagged with its reason; none invented where there is one.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import ingest
from stable_phase import DETECTORS, StablePhaseParams, detect_stable_phase
from virtual_testbed.varied_campaign import varied_conditions

START_TOLERANCE_S = 2.0


@pytest.fixture(scope="module")
def detected(varied_campaign):
    """(truth, window) per run of a 56-run campaign in both forms (every third run CSV;
    conftest's, shared with tests/test_run_results_virtual.py)."""
    pairs = []
    for c in varied_conditions():
        truth = json.loads((varied_campaign / "truth" / f"{c.run_id}.json").read_text())
        run = ingest.read_run(varied_campaign / truth["raw_file"])
        pairs.append((truth, run, detect_stable_phase(run)))
    return pairs


def test_campaign_is_varied_enough(detected):
    truths = [t for t, _, _ in detected]
    loads = [t["condition"]["load_n"] for t in truths]
    slips = [t["condition"]["slip_setpoint"] for t in truths if t["condition"]["slip_setpoint"]]
    assert len(truths) >= 50 and min(loads) <= 70 and max(loads) >= 310
    assert min(slips) < -0.15 and max(slips) > 0.75
    assert {t["condition"]["multipass"] for t in truths} == {0, 1, 2}
    assert {t["condition"]["mode"] for t in truths} == {"speed_control", "free_sled", "towed"}
    assert {t["form"] for t in truths} == {"mcap", "csv"}


def test_window_start_within_2_s_of_truth_for_95_percent(detected):
    errors = np.array([w.start_s - t["stable_window"]["start_s"] if w.found else np.inf
                       for t, _, w in detected if t["stable_window"] is not None])
    assert errors.size >= 50
    # measured: 51/52 within 2 s, median -0.37 s, 5-95 % range -1.5..+0.4 s, worst -2.4 s
    assert np.mean(np.abs(errors) <= START_TOLERANCE_S) >= 0.95
    assert abs(np.median(errors)) < 0.6 and np.all(np.isfinite(errors))


def test_window_lies_in_the_stable_phase_and_holds_whole_grouser_periods(detected):
    for truth, _, w in detected:
        if truth["stable_window"] is None:
            continue
        assert w.end_s <= truth["stable_window"]["end_s"] + 0.5
        assert w.end_s - w.start_s >= 15.0, truth["run_id"]
        periods = w.diagnostics["grouser_periods"]
        assert periods >= 2 and abs(periods - round(periods)) < 0.02, truth["run_id"]
        assert w.parameters == StablePhaseParams().to_dict()


def test_every_dig_in_run_is_flagged_with_its_reason(detected):
    dig_in = [(t, w) for t, _, w in detected if t["stable_window"] is None]
    assert len(dig_in) == 4
    for truth, w in dig_in:
        assert not w.found and w.start_s is None
        assert "drawbar pull rises" in w.reason and "collapses" in w.reason
        assert "digs in" in w.reason and "sinkage grows" in w.reason
        peak_n = float(w.reason.split("rises to ")[1].split(" N")[0])
        assert peak_n == pytest.approx(truth["dig_in"]["dp_trend_peak_n"], rel=0.1)


def test_mser_detector_is_registered_and_finds_most_stable_phases(detected):
    """The alternative detector (two-sided MSER alone): weaker than the default here
    (measured: 49/52 found, 67 % within 2 s, median error -1.1 s), but usable."""
    assert set(DETECTORS) >= {"settling", "mser"}
    params = StablePhaseParams(detector="mser")
    errors = []
    for truth, run, _ in detected:
        if truth["stable_window"] is None:
            continue
        w = detect_stable_phase(run, params)
        assert "MSER" in w.method
        errors.append(w.start_s - truth["stable_window"]["start_s"] if w.found else np.inf)
    errors = np.array(errors)
    assert np.isfinite(errors).mean() >= 0.9 and np.median(np.abs(errors)) < 2.0


def test_unknown_detector_is_refused(detected):
    with pytest.raises(KeyError, match="unknown stable-phase detector"):
        detect_stable_phase(detected[0][1], StablePhaseParams(detector="nope"))
