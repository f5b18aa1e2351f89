"""A second raw-run generator, written from the raw-run spec apart from ``virtual_testbed``
(it imports neither it nor any estimator; import contract in pyproject.toml).

The caller's truth (a callable or a table) gives the true steady values of each condition;
the rig adds its own signal model (underdamped and ramp-and-overshoot transients, shark-fin
grouser load with phase jitter, coloured noise, drift since zeroing with rest readings, gain
errors, quantisation, clocks, spikes) and writes MCAP or CSV runs, with the truth apart.
docs/second-rig.md.
"""

from validation.second_rig.campaign import Rig, low_speed_rig, make_run, write_campaign
from validation.second_rig.condition import (MODES, TRUTH_KEYS, RunCondition, SecondRigError,
                                             WheelGeometry, steady_truth, wheel_omega_radps)
from validation.second_rig.sensors import Rates, SensorModel
from validation.second_rig.signals import SignalModel, Timeline

__all__ = ["MODES", "TRUTH_KEYS", "Rates", "Rig", "RunCondition", "SecondRigError",
           "SensorModel", "SignalModel", "Timeline", "WheelGeometry", "low_speed_rig", "make_run",
           "steady_truth", "wheel_omega_radps", "write_campaign"]
