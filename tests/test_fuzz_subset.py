"""A seeded subset of the reliability bench's fuzzing (``python -m bench reliability``): 500
mutated real runs through the pipeline, none an unhandled exception, a hang, or a
physically impossible value marked ok."""

from __future__ import annotations

import pytest

from collections import Counter

from bench.bench_reliability import fuzz
from bench.fuzz_outcome import nonsense

SEED = 1  # the bench itself runs seed 17
INPUTS = 500


@pytest.mark.slow  # 500 mutated runs, each read and processed
@pytest.mark.slow_campaign
def test_five_hundred_mutated_runs_fail_cleanly_or_give_sound_results():
    counts, faults = fuzz(INPUTS, SEED)
    total = sum(counts.values(), Counter())
    assert sum(total.values()) == INPUTS
    assert faults == []
    # every kind of input was tried, and the mutations both break runs and leave some usable
    assert set(counts) == {"mcap_bytes", "json_block", "channel", "metadata", "csv_cell",
                           "run_json", "channel_map", "cmu_file", "format_file"}
    assert total["refused"] > 0.5 * INPUTS and total["ok"] + total["flagged"] > 0.1 * INPUTS


def test_the_nonsense_judge_catches_an_impossible_result():
    """The judge itself, on a result with a negative wheel load and one with an SE of 0."""
    from types import SimpleNamespace

    from run_results.stats import QuantityStats

    def result(**quantities):
        return SimpleNamespace(wheel=SimpleNamespace(radius_m=0.125),
                               condition=SimpleNamespace(load_set_n=180.0),
                               quantities={k: QuantityStats(*v, n=100, n_eff=50.0, unit="")
                                           for k, v in quantities.items()})

    assert nonsense(result(wheel_load_n=(180.0, 2.0, 0.1), slip=(0.2, 0.01, 0.001))) is None
    assert "wheel_load_n" in nonsense(result(wheel_load_n=(-5.0, 2.0, 0.1)))
    assert "SE of 0" in nonsense(result(dp_n=(40.0, 0.0, 0.0)))
    assert "slip" in nonsense(result(slip=(-9.8e4, 1.0, 0.1)))
