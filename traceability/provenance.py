"""What made a number: the swtlab version (one place: ``version`` in pyproject.toml, read from
the installed metadata) and the sha256 of the lock file the environment was installed from."""

from __future__ import annotations

import hashlib
from functools import cache
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

#: the lock file of a source checkout (editable install, CI, make demo/test)
LOCK_FILE = Path(__file__).resolve().parents[1] / "requirements.lock"


@cache
def swtlab_version() -> str:
    """The installed swtlab version, ``unknown`` when swtlab is imported without installing."""
    try:
        return version("swtlab")
    except PackageNotFoundError:
        return "unknown"


@cache
def lock_sha256() -> str | None:
    """sha256 of ``requirements.lock`` beside the package, None where there is none (a wheel)."""
    try:
        return hashlib.sha256(LOCK_FILE.read_bytes()).hexdigest()
    except OSError:
        return None
