"""What the pipeline carries: a processed run, a failure, a campaign."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

import pandas as pd

from swtlab_base.domain import Wheel, check_results, wheels_of
from swtlab_base.errors import InputError


class FailureKind(Enum):
    """Whose a failure is, decided where it was caught from the exception's type."""

    #: ingest refused the file (an ``ingest.IngestError``): the reason is its own line
    #: ``<file>: <channel>: <problem>``
    REFUSED = "refused"
    #: another :class:`~swtlab_base.errors.InputError`: the user's input, refused at a later stage
    INPUT = "input"
    #: any other exception: a fault of swtlab inside that run, please report it
    INTERNAL = "internal"


@dataclass(frozen=True)
class Failure:
    """A run (or part of one) that could not be processed: the ``file``, the ``stage``
    (``ingest``, ``results``, ``soil_flow``, ``store``), the one-line ``reason``, the
    ``error_type``, the exception's class name, kept as a record for the user, and its
    ``kind`` (:class:`FailureKind`; None for a failure loaded from a database, which keeps
    the class name only)."""

    file: str
    stage: str
    reason: str
    error_type: str
    kind: FailureKind | None

    @classmethod
    def of(cls, file: str | Path, stage: str, error: BaseException) -> Failure:
        """The failure of ``stage`` on ``file`` from the exception it raised: its own message
        for an :class:`~swtlab_base.errors.InputError` (the user's input), else
        ``internal error (<type>: <message>)``, on one line."""
        from ingest.errors import IngestError

        name = type(error).__name__
        kind = (FailureKind.REFUSED if isinstance(error, IngestError)
                else FailureKind.INPUT if isinstance(error, InputError) else FailureKind.INTERNAL)
        internal = kind is FailureKind.INTERNAL
        text = f"internal error ({name}: {error})" if internal else str(error)
        return cls(str(file), stage, one_line(text), name, kind)

    @property
    def line(self) -> str:
        """The failure on one line naming the file: an ingest refusal's own reason, else
        ``<file>: <stage>: <reason>``."""
        if self.kind is FailureKind.REFUSED:
            return self.reason
        return f"{self.file}: {self.stage}: {self.reason}"


#: longest failure reason kept (a message quoting a huge value is cut, never the file name)
MAX_REASON_CHARS = 500


def one_line(text: str) -> str:
    """``text`` on one line (runs of blanks and line breaks become one space), at most
    :data:`MAX_REASON_CHARS` characters."""
    text = " ".join(str(text).split())
    return text if len(text) <= MAX_REASON_CHARS else text[:MAX_REASON_CHARS - 3] + "..."


@dataclass
class ProcessedRun:
    """One raw file through the pipeline: ``path``, its content's ``sha256`` and
    ``size_bytes``; ``run``: the ``ingest.Run`` (None when it could not
    be read, or when the campaign was loaded from a database); ``result``: its
    ``run_results.RunResult``; ``flow``: its soil flow (``softflow.flow_run.RunFlow``) with
    ``flow_npz``, the packed arrays the database keeps; ``failures`` of any stage."""

    path: Path
    sha256: str
    run: Any = None
    streams: list | None = None
    result: Any = None
    flow: Any = None
    flow_npz: bytes | None = None
    failures: list[Failure] = field(default_factory=list)
    size_bytes: int | None = None

    @property
    def run_id(self) -> str | None:
        return None if self.result is None else self.result.run_id


@dataclass
class Campaign:
    """A processed campaign: ``runs`` (:class:`ProcessedRun`), ``results`` (one row per run in
    the schema of :mod:`swtlab_base.domain.results`, docs/results.md), ``failures`` (every run or
    part of one that failed, with file, stage and reason), the processing ``parameters`` and
    the ``source`` database URL of a campaign loaded from one."""

    runs: list[ProcessedRun]
    results: pd.DataFrame
    failures: list[Failure]
    parameters: dict = field(default_factory=dict)
    source: str | None = None

    def __post_init__(self) -> None:
        check_results(self.results)

    @property
    def wheels(self) -> dict[str, Wheel]:
        """Wheel name -> geometry, from the results."""
        return wheels_of(self.results) if len(self.results) else {}

    @property
    def replicates(self) -> pd.DataFrame:
        """Spread of the replicate runs beside their within-run uncertainty, per condition and
        quantity (``swtlab_base.domain.replicates.replicate_spread``); empty without replicates."""
        from swtlab_base.domain.replicates import replicate_spread

        return replicate_spread(self.results)

    @property
    def repeatability(self) -> str:
        """One line: how many conditions have replicates, or that the campaign has none."""
        from swtlab_base.domain.replicates import NO_REPLICATES, REPLICATE_KEY

        spread = self.replicates
        if spread.empty:
            return NO_REPLICATES
        conditions = spread[[c for c in REPLICATE_KEY if c in spread]].drop_duplicates()
        larger = spread.groupby("quantity", sort=False)["larger"].apply(
            lambda x: (x == "replicates").mean())
        return (f"{len(conditions)} condition(s) with replicate runs; the replicate spread "
                "exceeds the within-run uncertainty in "
                + ", ".join(f"{q} {100 * v:.0f} %" for q, v in larger.items()) + " of them")

    @property
    def names(self) -> list[str]:
        """The campaign names (``swt.run.campaign``) the results hold."""
        return sorted(set(self.results["campaign"])) if len(self.results) else []
