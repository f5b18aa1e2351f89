"""Tare and rig compliance, applied before the statistics and recorded with the run.

Tare: ingest already subtracts the ``swt.zero`` offsets (raw-run spec) from the hub
wrench; ``tare_record`` states what was subtracted. Rig compliance: the testbed frame and
suspension deflect under the wheel load, so the hub sits lower than the soil alone makes
it; a per-campaign law gives the correction added to the measured hub height,
``hub_height_corrected = hub_height + correction(fz)``, and sinkage is re-derived from it
(spec: ``z = -h`` rigid, ``z = -h - fz/(1000 k)`` flexible).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RigCompliance:
    """Hub-height correction (m) against wheel load (N): linear or a table interpolated.

    ``linear``: ``correction = m_per_n * (fz - reference_load_n)``;
    ``table``: ``np.interp(fz, load_n, correction_m)`` (held constant outside the table).
    """

    kind: str = "linear"
    m_per_n: float = 0.0
    reference_load_n: float = 0.0
    load_n: tuple[float, ...] = ()
    correction_m: tuple[float, ...] = ()
    source: str = ""

    def __post_init__(self) -> None:
        if self.kind not in ("linear", "table"):
            raise ValueError(f"rig compliance kind {self.kind!r} not in ('linear', 'table')")
        if self.kind == "table" and (len(self.load_n) < 2
                                     or len(self.load_n) != len(self.correction_m)
                                     or np.any(np.diff(self.load_n) <= 0)):
            raise ValueError("a table needs >= 2 increasing load_n values, one correction_m each")

    def correction(self, fz_n) -> np.ndarray:
        """Correction added to the hub height (m) at wheel load ``fz_n``."""
        fz = np.asarray(fz_n, float)
        if self.kind == "linear":
            return self.m_per_n * (fz - self.reference_load_n)
        return np.interp(fz, self.load_n, self.correction_m)

    def to_dict(self) -> dict:
        out = {"kind": self.kind, "source": self.source}
        if self.kind == "linear":
            out.update(m_per_n=self.m_per_n, reference_load_n=self.reference_load_n)
        else:
            out.update(load_n=list(self.load_n), correction_m=list(self.correction_m))
        return out

    @classmethod
    def from_dict(cls, data: dict) -> "RigCompliance":
        kind = data.get("kind", "linear")
        if kind == "table":
            return cls(kind="table", load_n=tuple(map(float, data["load_n"])),
                       correction_m=tuple(map(float, data["correction_m"])),
                       source=data.get("source", ""))
        return cls(kind="linear", m_per_n=float(data.get("m_per_n", 0.0)),
                   reference_load_n=float(data.get("reference_load_n", 0.0)),
                   source=data.get("source", ""))


def corrected_heights(hub_height_m, fz_n, stiffness_n_per_mm: float | None,
                      rig: RigCompliance | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(hub_height_m, sinkage_m, correction_m)`` after the rig correction (spec sinkage)."""
    hub = np.asarray(hub_height_m, float)
    fz = np.asarray(fz_n, float)
    correction = np.zeros_like(hub) if rig is None else rig.correction(fz)
    hub = hub + correction
    sinkage = -hub if stiffness_n_per_mm is None else -hub - fz / (1000.0 * stiffness_n_per_mm)
    return hub, sinkage, correction


def tare_record(run) -> dict:
    """What ingest subtracted as zero offsets (``swt.zero``), for ``RunResult.corrections``."""
    zero = dict(run.metadata.zero)
    return {"zero_offsets_subtracted": zero,
            "applied_by": "ingest (swt.zero subtracted from /hub/wrench)" if zero else
                          "none: the run has no swt.zero record"}
