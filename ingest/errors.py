"""Errors and problems ingest reports (one line each, file + channel + problem)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

from swtlab_base.errors import InputError

Severity = Literal["warning", "error"]


class IngestError(InputError):
    """A run that cannot be used at all: ``"<path>: <channel>: <problem>"`` on one line."""

    def __init__(self, path: str | Path, channel: str | None, problem: str):
        self.path = Path(path)
        self.channel = channel
        self.problem = " ".join(str(problem).split())  # always one line
        super().__init__(str(self))

    def __str__(self) -> str:
        return f"{self.path}: {self.channel or '-'}: {self.problem}"

    def __reduce__(self):  # picklable for process pools
        return (IngestError, (self.path, self.channel, self.problem))


@dataclass(frozen=True)
class Problem:
    """Something ingest saw in a run that is still usable (a gap, a missing optional channel)."""

    severity: Severity
    channel: str | None
    message: str

    def __str__(self) -> str:
        return f"{self.severity}: {self.channel or '-'}: {self.message}"

    def to_dict(self) -> dict:
        return {"severity": self.severity, "channel": self.channel, "message": self.message}
