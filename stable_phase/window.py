"""``StableWindow``: the result of stable-phase detection for one run."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class StableWindow:
    """Where a run's stable phase lies, how it was found, and why not when it was not."""

    found: bool
    start_s: float | None
    end_s: float | None
    method: str
    parameters: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)
    reason: str | None = None

    @property
    def duration_s(self) -> float | None:
        return None if not self.found else self.end_s - self.start_s

    def to_dict(self) -> dict:
        return {"found": self.found, "start_s": self.start_s, "end_s": self.end_s,
                "method": self.method, "parameters": dict(self.parameters),
                "diagnostics": dict(self.diagnostics), "reason": self.reason}
