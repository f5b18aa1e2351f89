"""Content hashes of raw files and CSV run folders."""

from __future__ import annotations

import hashlib
from pathlib import Path

CHUNK_BYTES = 1 << 20


def _update_with_file(digest: "hashlib._Hash", path: Path) -> int:
    size = 0
    with path.open("rb") as handle:
        while chunk := handle.read(CHUNK_BYTES):
            digest.update(chunk)
            size += len(chunk)
    return size


def content_sha256(path: Path) -> tuple[str, int]:
    """sha256 and size in bytes of a file, or of a folder (relative names and contents, sorted)."""
    digest = hashlib.sha256()
    if path.is_file():
        size = _update_with_file(digest, path)
        return digest.hexdigest(), size
    size = 0
    for member in sorted(p for p in path.rglob("*") if p.is_file()):
        digest.update(member.relative_to(path).as_posix().encode() + b"\0")
        size += _update_with_file(digest, member)
    return digest.hexdigest(), size
