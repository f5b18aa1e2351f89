"""Files cut short: a logger that stopped mid-write leaves a file without its end (an MCAP
without its summary and footer, a text table whose last line has no line break, a ROS 1 bag
without its index). Ingest reads what is there, says where the file ends and why it looks
cut, and the run is flagged; a run read from such a file is never ``ok``."""

from __future__ import annotations

from pathlib import Path

#: bytes read from a text file's end to find its last line
TAIL_BYTES = 1 << 16


def note(end_s: float | None, why: str) -> str:
    """``file ends at t = 41.200 s (cut short?): <why>`` (``end_s``: the last time stamp read,
    s from the run start; None when no sample was read)."""
    where = "before its first sample" if end_s is None else f"at t = {end_s:.3f} s"
    return f"file ends {where} (cut short?): {why}"


def message(path: str | Path, end_s: float | None, why: str) -> str:
    """:func:`note` after the file's name: the flag a run read from such a file carries."""
    return f"{Path(path).name}: {note(end_s, why)}"


def last_line_cut(path: Path) -> bool:
    """True when a text file's last line has no line break after it: every writer of tables
    (loggers, the csv module, pandas, numpy.savetxt, LabVIEW, MATLAB writematrix) ends each
    row with one, so a file without it stopped in the middle of a row (its last number may
    itself be cut: ``12.3`` of ``12.345``)."""
    with open(path, "rb") as stream:
        size = stream.seek(0, 2)
        stream.seek(max(0, size - TAIL_BYTES))
        tail = stream.read()
    return bool(tail) and bool(tail.rpartition(b"\n")[2].strip())


CUT_LINE = "its last line has no line break (the logger stopped mid-row); that line is dropped"
