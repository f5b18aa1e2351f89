"""``RunResult``: one run's stable-phase results, flags, oscillation and corrections."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from run_results.stats import QuantityStats
from run_results.traces import Trace
from stable_phase import StableWindow
from swtlab_base.plain_json import jsonable
from swtlab_base.domain import TestCondition, Wheel
from swtlab_base.domain.results import STATUSES, wheel_columns


@dataclass(frozen=True)
class RunResult:
    """Per-run results (see docs/run-results.md) of a run of ``campaign`` with ``wheel`` on
    ``soil`` at the set point ``condition`` (mode, set load, soil pass, set slip, velocity,
    gravity, steering angle), for grouping runs across a campaign. ``traces``: channel ->
    decimated :class:`run_results.traces.Trace` for plots (arrays, left out of
    :meth:`to_dict`)."""

    run_id: str
    status: str
    flags: tuple[str, ...]
    window: StableWindow
    quantities: dict[str, QuantityStats]
    oscillation: dict
    dp_trace: dict | None
    corrections: dict
    campaign: str
    wheel: Wheel
    soil: str
    condition: TestCondition
    traces: dict[str, Trace] = field(default_factory=dict)
    #: quantity -> ``run_results.uncertainty_budget.QuantityBudget``
    uncertainty: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.status not in STATUSES:
            raise ValueError(f"status {self.status!r} not in {STATUSES}")

    @property
    def mode(self) -> str:
        """The test mode (``condition.mode``)."""
        return self.condition.mode

    def to_dict(self) -> dict:
        """JSON-ready dict (NaN as null)."""
        return jsonable({
            "run_id": self.run_id, "mode": self.mode, "status": self.status,
            "flags": list(self.flags), "window": self.window.to_dict(),
            "quantities": {k: v.to_dict() for k, v in self.quantities.items()},
            "oscillation": dict(self.oscillation), "dp_trace": self.dp_trace,
            "corrections": dict(self.corrections), "condition": {
                "campaign": self.campaign, **wheel_columns(self.wheel), "soil": self.soil,
                **asdict(self.condition)},
            "uncertainty": {k: b.to_dict() for k, b in self.uncertainty.items()}})
