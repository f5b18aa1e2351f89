"""Coverage of the 95 % intervals (``mean +- u95``) against known truths, on 60 short CSV
runs of varied conditions from each generator (validation/coverage.py; the >= 200-run figures
are in ``python -m bench coverage``). Seeds used while tuning the budget: virtual 101, 102;
second rig 201. These seeds are other ones.

- virtual testbed (in-family: the estimators were built beside it);
- second rig (independent signal model: underdamped transients, shark-fin grouser load,
  drift since a zeroing minutes before the run, gain errors, drive speed ripple);
- the second rig's low-speed coarse-encoder mode (a 14-bit wheel encoder and the sled at
  500 Hz, 5-20 mm/s: slip, speeds from displacements of a count or none a sample).

With 60 runs a true 95 % coverage reads 90-100 % (2 binomial sd); the bounds below allow
that, and the printout gives the coverage and the spread of ``(mean - truth)/u``.
"""

from __future__ import annotations

import pytest

from validation.coverage import coverage, run_coverage

pytestmark = [pytest.mark.slow,  # three 60-run campaigns generated and processed, one per rig
              pytest.mark.slow_campaign]

RUNS = 60
#: the issue's quantities: DP, torque, wheel load, slip, sinkage, resistance, velocity
REQUIRED = ("dp_n", "torque_nm", "wheel_load_n", "slip", "sinkage_m", "resistance_n",
            "travel_velocity_mps")


@pytest.fixture(scope="module", params=[("virtual", 131), ("second", 231), ("low_speed", 331)],
                ids=["virtual", "second_rig", "low_speed"])
def table(request, tmp_path_factory):
    generator, seed = request.param
    scores = run_coverage(tmp_path_factory.mktemp(generator), generator, RUNS, seed)
    table = coverage(scores)
    print(f"\n{generator} seed {seed}:\n{table.round(3).to_string()}")
    return generator, table


def test_every_quantity_is_scored_on_most_runs(table):
    _, t = table
    assert set(REQUIRED) <= set(t.index)
    assert (t.loc[list(REQUIRED), "runs"] >= 0.75 * RUNS).all()


def test_the_95_percent_intervals_cover_the_truth(table):
    """Measured (seeds 131 / 231 / 331), coverage virtual | second rig | low-speed mode: DP 94 | 90
    | 96 %, torque 98 | 98 | 97 %, wheel load 98 | 100 | 98 %, slip 97 | 97 | 100 %, sinkage 90 |
    100 | 95 %, resistance 96 | 98 | 98 %, travel velocity 100 | 95 | 98 % (slip and velocity
    with the mean of per-sample ratios and rates, before the rates from displacements: virtual
    97, 100 %, second rig 92, 95 %; before the whole-pitch batch means of the statistical term:
    virtual sinkage 92, torque 97 %; second rig DP 98, torque 100, resistance 100 %; with
    ``fz``'s zero age between the rig's stated bounds, 30-180 s, instead of the longest: the
    same coverage, second rig load and sinkage z spread 0.88 and 0.85; with the drift's walk
    left out of the statistical term: second rig DP 92 -> 90 %, the rest the same). The Wilson
    intervals of 60 runs span about 10 points."""
    _, t = table
    low = 0.85
    for q in REQUIRED:
        assert low <= t.loc[q, "coverage"] <= 1.0, (q, t.loc[q, "coverage"])


def test_the_spread_of_z_is_near_one(table):
    """``(mean - truth)/u`` spreads by about 1 where the budget is right: not six times too
    small (the sinkage SE of the issue) nor several times too large."""
    generator, t = table
    for q in REQUIRED:
        assert 0.4 < t.loc[q, "z_std"] < 1.6, (q, t.loc[q, "z_std"])
