"""Stable-phase detection of single-wheel-testbed runs (docs/stable-phase.md).

Pluggable transient detectors (one per file) behind a small registry; the pipeline
(``detect_stable_phase``) gates on the speeds, cuts the transient, trims to whole grouser
periods and checks the window. Never reads ground truth.
"""

from stable_phase.autocorr import standard_error, statistical_inefficiency
from stable_phase.detect import detect_stable_phase
from stable_phase.params import StablePhaseParams
from stable_phase.registry import DETECTORS, Cut, Detector, get_detector, register
from stable_phase.window import StableWindow

__all__ = ["Cut", "DETECTORS", "Detector", "StablePhaseParams", "StableWindow",
           "detect_stable_phase", "get_detector", "register", "standard_error",
           "statistical_inefficiency"]
