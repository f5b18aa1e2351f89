"""The second signal model of the blind gap-bench (``validation.gap_bench``,
``signal_model="second"``): one campaign's raw runs written by the second rig
(validation/second_rig: underdamped transients, shark-fin grouser load, coloured noise, drift
since zeroing, gain errors, spikes, other rates; docs/second-rig.md) instead of the virtual
testbed. The truths, layout, diagnosis and scoring are gap_bench's own.

Each run's steady values are the hidden-truth model's curves at the set point
(validation.model_truth); the wheel metadata are the virtual testbed's (BB2-like, 30 N/mm),
so a campaign differs from a testbed one only in its signals.
"""

from __future__ import annotations

from pathlib import Path

import terramechanics as tm
from validation.model_truth import ModelTruth
from validation.second_rig import Rig, RunCondition, Timeline, WheelGeometry, write_campaign


def rig_conditions(conds, campaign: str, w) -> list[RunCondition]:
    """Speed-control conditions of the virtual testbed (gap_bench's ``conditions``) as
    second-rig conditions, on the virtual testbed's wheel ``w`` (a ``swtlab_base.domain.Wheel``
    with its stiffness)."""
    wheel = WheelGeometry(name=w.name, radius_m=w.radius_m, width_m=w.width_m,
                          grouser_count=w.grouser_count, grouser_height_m=w.grouser_height_m,
                          stiffness_n_per_mm=w.stiffness_n_per_mm)
    return [RunCondition(c.run_id, c.mode, c.load_set_n, c.slip_setpoint, multipass=c.multipass,
                         gravity_mps2=c.gravity_mps2, velocity_mps=c.velocity_set_mps, soil="sand",
                         campaign=campaign, wheel=wheel)
            for c in conds]


def write_second_campaign(out: Path, conds, truth: tm.WheelModel, seed: int, name: str,
                          duration_s: float, wheel) -> None:
    """One campaign's raw runs of ``wheel`` from the second rig under ``out/campaign``, the
    truth of ``truth``'s curves under ``out/truth`` (as the testbed's ``generate_campaign``)."""
    rig = Rig(timeline=Timeline(duration_s=duration_s))
    write_campaign(out, rig_conditions(conds, name, wheel), ModelTruth(truth), seed, rig=rig)
