"""Virtual single-wheel testbed: raw runs (MCAP and CSV, per the raw-run spec)
from a known ground truth, with the truth written apart. Never imported by estimators."""

from virtual_testbed.campaign import Testbed, generate_campaign, make_run, write_run
from virtual_testbed.conditions import VELOCITY_40_M_PER_H_MPS, RunCondition
from virtual_testbed.law import PerformanceLaw, bb2_sand_law, self_propelled_slip, towed_slip
from virtual_testbed.rig import BB2_WHEEL, Suspension, Timeline, Wheel
from virtual_testbed.sensors import Rates, SensorModel
from virtual_testbed.simulate import Dynamics, simulate_true_run

__all__ = [
    "BB2_WHEEL", "Dynamics", "PerformanceLaw", "Rates", "RunCondition", "bb2_sand_law",
    "SensorModel", "Suspension", "Testbed", "Timeline", "VELOCITY_40_M_PER_H_MPS", "Wheel",
    "generate_campaign", "make_run", "self_propelled_slip", "simulate_true_run", "towed_slip",
    "write_run",
]
