"""Files written whole or not at all: the one way swtlab writes an output file.

The content goes to a temporary file in the target's folder, is flushed and fsynced, then
renamed over the target (``os.replace``, atomic on POSIX and Windows) and the folder is
fsynced: a process killed at any moment leaves the old file or the new one, never a part,
and a crash of the machine after the return keeps the new one. Imports nothing of swtlab,
so every stage may use it.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO


def _fsync_folder(folder: Path) -> None:
    """Make a rename in ``folder`` durable (where the platform allows opening a folder)."""
    try:
        handle = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(handle)
    except OSError:
        pass
    finally:
        os.close(handle)


@contextmanager
def atomic_file(path: str | Path, mode: str = "w", *, encoding: str | None = "utf-8",
                newline: str | None = None) -> Iterator[IO]:
    """A stream (``mode`` ``"w"`` text or ``"wb"`` bytes) whose content replaces ``path`` when
    the block ends without an exception; on an exception ``path`` is untouched and the
    temporary file removed. Missing parent folders are created. The file gets the ordinary
    permissions of a new file (0666 less the umask), not the temporary file's 0600."""
    if mode not in ("w", "wb"):
        raise ValueError(f"mode {mode!r}: 'w' or 'wb'")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.fchmod(handle, 0o666 & ~umask)
        stream: IO = (os.fdopen(handle, "w", encoding=encoding, newline=newline) if mode == "w"
                      else os.fdopen(handle, "wb"))
        with stream:
            yield stream
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    _fsync_folder(path.parent)


def write_atomically(path: str | Path, data: str | bytes, *, encoding: str = "utf-8") -> Path:
    """Write ``data`` (text in ``encoding``, or bytes) to ``path`` through :func:`atomic_file`;
    return the path."""
    with atomic_file(path, "wb") as stream:
        stream.write(data.encode(encoding) if isinstance(data, str) else data)
    return Path(path)
