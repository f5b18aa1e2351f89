"""A seeded subset of the reliability bench's fuzzing (``python -m bench reliability``: 10,500
inputs of seed 17): every mutation the generator (``bench.fuzz_inputs``) has, three times, through
the pipeline; none an unhandled exception, a hang, or a physically impossible value marked ok.

The subset: among cases 0-499 of seed 1 (this test's former 500 inputs), the first three of
each (kind, how) pair, the 40 mutations of the 9 input kinds listed in ``MUTATIONS``; 120
inputs, each kind 9 to 24 times. Finding rare faults by volume is the bench's job."""

from __future__ import annotations

from collections import Counter

import pytest

from bench.bench_reliability import fuzz
from bench.fuzz_inputs import case
from bench.fuzz_outcome import nonsense

SEED = 1  # the bench itself runs seed 17
POOL = 500  # cases 0-499 of SEED, from which the subset is taken
PER_MUTATION = 3
#: the mutations of each kind of input (the ``how`` of bench.fuzz_inputs' case functions)
MUTATIONS = {
    "mcap_bytes": {"flip", "cut", "insert", "zero"},
    "json_block": {"sample", "t_ns", "drop_key", "add_key", "short", "payload", "scale",
                   "swap_t"},
    "channel": {"scale", "negate", "offset", "flat", "clip", "spikes", "freeze"},
    "metadata": {"set", "drop", "new", "drop_record"},
    "csv_cell": {"cell", "drop_line", "cut", "header", "junk_line"},
    "run_json": {"set", "drop", "text"},
    "channel_map": {"set", "drop", "csv_file"},
    "cmu_file": {"cut", "cell", "junk"},
    "format_file": {"channel", "bytes", "cut"},
}


def _subset() -> tuple[list[int], Counter]:
    """Indices of the first ``PER_MUTATION`` cases of every (kind, how) among cases
    0..POOL-1, and how many of each were taken."""
    taken: Counter = Counter()
    indices = []
    for i in range(POOL):
        item = case(SEED, i)
        if taken[item.kind, item.how] < PER_MUTATION:
            taken[item.kind, item.how] += 1
            indices.append(i)
    return indices, taken


@pytest.mark.slow  # 120 mutated runs, each read and processed
@pytest.mark.slow_campaign
def test_every_mutation_three_times_fails_cleanly_or_gives_sound_results():
    indices, taken = _subset()
    # every mutation of every kind is in the subset, each three times
    assert set(taken) == {(kind, how) for kind, hows in MUTATIONS.items() for how in hows}
    assert set(taken.values()) == {PER_MUTATION}
    counts, faults = fuzz(indices, SEED)
    total = sum(counts.values(), Counter())
    assert sum(total.values()) == len(indices) == PER_MUTATION * len(taken)
    assert faults == []
    assert all(sum(counts[kind].values()) >= PER_MUTATION for kind in MUTATIONS)
    # the mutations both break runs and leave some usable
    assert total["refused"] > 0.5 * len(indices)
    assert total["ok"] + total["flagged"] > 0.1 * len(indices)


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
