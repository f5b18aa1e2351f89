"""``RunResult``: one run's stable-phase results, flags, oscillation and corrections."""

from __future__ import annotations

from dataclasses import dataclass, field

from run_results.stats import QuantityStats
from run_results.traces import Trace
from stable_phase import StableWindow
from swtlab_base.plain_json import jsonable
from swtlab_base.domain.results import STATUSES


@dataclass(frozen=True)
class RunResult:
    """Per-run results (see docs/run-results.md). ``condition``: wheel, soil, multipass,
    set load, set slip, steering angle and velocity, for grouping runs across a campaign.
    ``traces``: channel -> decimated :class:`run_results.traces.Trace` for plots (arrays,
    left out of :meth:`to_dict`)."""

    run_id: str
    mode: str
    status: str
    flags: tuple[str, ...]
    window: StableWindow
    quantities: dict[str, QuantityStats]
    oscillation: dict
    dp_trace: dict | None
    corrections: dict
    condition: dict = field(default_factory=dict)
    traces: dict[str, Trace] = field(default_factory=dict)
    #: quantity -> ``run_results.uncertainty_budget.QuantityBudget``
    uncertainty: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r} not in {STATUSES}")

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN as null)."""
        return jsonable({
            "run_id": self.run_id, "mode": self.mode, "status": self.status,
            "flags": list(self.flags), "window": self.window.to_dict(),
            "quantities": {k: v.to_dict() for k, v in self.quantities.items()},
            "oscillation": dict(self.oscillation), "dp_trace": self.dp_trace,
            "corrections": dict(self.corrections), "condition": dict(self.condition),
            "uncertainty": {k: b.to_dict() for k, b in self.uncertainty.items()}})
