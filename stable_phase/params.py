"""Tunables of stable-phase detection (every one is recorded in ``StableWindow.parameters``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass


@dataclass(frozen=True)
class StablePhaseParams:
    """Knobs of the gate, the transient cut and the window checks (units in the names)."""

    detector: str = "settling"            # registry name of the transient detector
    gate_smooth_s: float = 1.0            # moving average of the speeds before gating
    gate_rel_tol: float = 0.05            # speed within 5 % of the travel velocity scale ...
    gate_sigmas: float = 3.0              # ... or within 3 robust sigmas of its own noise
    gate_bridge_s: float = 1.0            # speed dropouts up to 1 s inside the gate are bridged
    ramp_lookback_s: float = 10.0         # how far before the gate to look for the ramp start
    settle_fraction: float = 0.005        # stable once the transient is 0.5 % of its excursion
    batch_s: float = 1.0                  # MSER batch spacing (means over one grouser period)
    mser_max_cut_fraction: float = 0.5    # MSER may cut at most half the gated segment
    end_max_cut_fraction: float = 0.1     # after the settling cut MSER trims <= 10 % off the end
    min_window_s: float = 5.0             # shorter windows are not a stable phase
    min_grouser_periods: int = 2          # ... nor windows holding fewer grouser periods
    slope_alpha: float = 0.01             # slope test significance level
    slope_change_force_ratio: float = 0.02   # practical drift limit over the window: 2 % of load
    slope_change_sinkage_ratio: float = 0.05  # ... 5 % of the mean sinkage
    r_hat_limit: float = 1.1              # split-window R limit (with a level shift over the
    #                                       practical drift limit between the halves)
    dig_in_dp_drop_ratio: float = 0.05    # DP falling 5 % of the load after its peak = collapse

    def to_dict(self) -> dict:
        return asdict(self)
