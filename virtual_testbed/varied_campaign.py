"""A campaign of varied conditions for checking estimators against the truth.

56 runs: 44 speed-control runs at random loads (60-320 N), slips (-0.2..0.8) and soil
passes (0-2), a free-sled and a towed run at four loads, and four runs above the dig-in
slip (no stable phase). Used by the stable-phase and run-result tests.
"""

from __future__ import annotations

import numpy as np

from virtual_testbed.conditions import RunCondition


def varied_conditions(seed: int = 7) -> list[RunCondition]:
    """The 56 conditions, the same for the same ``seed``."""
    rng = np.random.default_rng(seed)
    out = [RunCondition.of(f"sc{i:02d}", "speed_control", float(np.round(rng.uniform(60, 320))),
                           int(rng.integers(0, 3)), float(np.round(rng.uniform(-0.2, 0.8), 3)))
           for i in range(44)]
    for i, (load, mp) in enumerate([(80, 0), (180, 1), (250, 2), (320, 0)]):
        out += [RunCondition.of(f"fs{i}", "free_sled", float(load), mp),
                RunCondition.of(f"tw{i}", "towed", float(load), mp)]
    out += [RunCondition.of(f"dig{i}", "speed_control", float(load), mp, slip)
            for i, (load, mp, slip) in enumerate([(180, 0, 0.92), (300, 0, 0.9), (250, 1, 0.93),
                                                   (120, 0, 0.96)])]
    return out


def varied_forms(conditions: list[RunCondition]) -> dict[str, str]:
    """Each run's file form: every third run a CSV folder, the others MCAP, so that one
    campaign goes through both readers."""
    return {c.run_id: ("csv" if i % 3 == 0 else "mcap") for i, c in enumerate(conditions)}
