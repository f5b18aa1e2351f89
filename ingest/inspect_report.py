"""A run as ingest sees it, as plain data (for ``swtlab inspect --json``) or as text tables."""

from __future__ import annotations

import numpy as np

from ingest.canonical import STABLE_PHASE_NEEDS
from ingest.run import Run
from swtlab_base.plain_json import jsonable

_DERIVED_UNITS = {"slip": "1"}


def _column_unit(column: str) -> str:
    for suffix, unit in (("_radps", "rad/s"), ("_mps", "m/s"), ("_nm", "N·m"), ("_rad", "rad"),
                         ("_n", "N"), ("_m", "m"), ("_s", "s")):
        if column.endswith(suffix):
            return unit
    return _DERIVED_UNITS.get(column, "1")


def stream_report(run: Run) -> list[dict]:
    """Each stream's channels with rate/span/gaps/units, as plain data (what a processed run
    stores; the rest of :func:`report` it does not need)."""
    return jsonable([{"topic": topic, **run.timing[topic].to_dict(),
                      "channels": [{"column": c, "unit": _column_unit(c),
                                    "source_unit": run.units.get(c)} for c in frame.columns[1:]]}
                     for topic, frame in run.streams.items()])


def stable_phase_missing(run: Run) -> list[str]:
    """``"<column>: ..."`` for each channel the stable phase needs that the run lacks
    (no finite sample)."""
    return [f"{column}: the stable phase needs it (from {' or '.join(sources)}); not in this "
            f"source (channel map {run.channel_map})"
            for column, sources in STABLE_PHASE_NEEDS.items()
            if not np.isfinite(run.channels[column].to_numpy()).any()]


def report(run: Run) -> dict:
    """Metadata, each stream's channels with rate/span/gaps/units, the time base and problems."""
    table = run.channels
    columns = []
    for column in table.columns[1:]:
        values = table[column].to_numpy()
        finite = np.isfinite(values)
        columns.append({"column": column, "unit": _column_unit(column),
                        "valid_fraction": float(finite.mean()) if len(values) else 0.0,
                        "mean": float(values[finite].mean()) if finite.any() else None})
    return jsonable({"source": str(run.source), "channel_map": run.channel_map,
                   "metadata": run.metadata.to_dict(), "streams": stream_report(run),
                   "time_base": run.derivation.get("time_base"), "channels": columns,
                   "frames": [f.to_dict() for f in run.frames.values()],
                   "derivation": run.derivation,
                   "problems": [p.to_dict() for p in run.problems],
                   "stable_phase_missing": stable_phase_missing(run)})


def _fmt(value) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def _table(header: list[str], rows: list[list]) -> list[str]:
    cells = [header] + [[_fmt(v) for v in row] for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    return ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in cells]


def render_text(data: dict) -> str:
    """Human-readable tables of a ``report``."""
    lines = [f"run {data['metadata']['run']['run_id']}  ({data['source']}, "
             f"channel map {data['channel_map']})", "", "metadata:"]
    for record, values in data["metadata"].items():
        if values:
            items = ", ".join(f"{k}={_fmt(v)}" for k, v in values.items() if v is not None)
            lines.append(f"  {record}: {items}")
    lines += ["", "streams (native time stamps):"]
    rows = []
    for s in data["streams"]:
        gaps = sum(b - a for a, b in s["gaps"])
        for ch in s["channels"]:
            rows.append([s["topic"], ch["column"], ch["unit"], ch["source_unit"], s["samples"],
                         round(s["rate_hz"], 2), f"{s['t0_s']:.3f}-{s['t1_s']:.3f}",
                         f"{len(s['gaps'])} ({gaps:.3f} s)", s["dropped_samples"]])
    lines += ["  " + r for r in _table(["topic", "column", "unit", "source unit", "samples",
                                        "rate Hz", "span s", "gaps", "dropped"], rows)]
    tb = data["time_base"]
    lines += ["", f"common time base: {tb['samples']} samples at {tb['rate_hz']:.6g} Hz from "
                  f"{tb['t0_s']:.3f} s"]
    rows = [[c["column"], c["unit"], f"{100 * c['valid_fraction']:.1f}%", c["mean"]]
            for c in data["channels"]]
    lines += ["  " + r for r in _table(["column", "unit", "valid", "mean"], rows)]
    if data["frames"]:
        lines += ["", "camera frames:"]
        lines += ["  " + r for r in _table(["topic", "count", "first s", "last s"],
                                           [[f["topic"], f["count"], f["first_s"], f["last_s"]]
                                            for f in data["frames"]])]
    lines += ["", f"problems ({len(data['problems'])}):"]
    lines += [f"  {p['severity']}: {p['channel'] or '-'}: {p['message']}" for p in data["problems"]]
    if not data["problems"]:
        lines.append("  none")
    return "\n".join(lines)
