"""User text as every database backend holds it alike: names checked, messages cut."""

from __future__ import annotations

from traceability.models import MESSAGE_CHARS, NAME_CHARS
from swtlab_base.errors import InputError

#: UTF-8 bytes of a name: the bound that keeps a unique index on it within PostgreSQL's
#: B-tree row limit (2,704 bytes) with the other key columns
NAME_BYTES = 2000


class TextRefused(InputError, ValueError):
    """A name the database cannot hold as written (too long, a NUL, not encodable)."""


def checked_name(what: str, value: str) -> str:
    """``value`` unchanged, or :class:`TextRefused` saying why it cannot be stored."""
    shown = f"{what} {value[:40]!r}{'...' if len(value) > 40 else ''}"
    if "\x00" in value:
        raise TextRefused(f"{shown} contains a NUL character; remove it")
    try:
        size = len(value.encode("utf-8"))
    except UnicodeEncodeError:
        raise TextRefused(f"{shown} is not valid Unicode text (a lone surrogate)") from None
    if len(value) > NAME_CHARS or size > NAME_BYTES:
        raise TextRefused(f"{shown} is {len(value)} characters ({size} bytes UTF-8); at most "
                          f"{NAME_CHARS} characters and {NAME_BYTES} bytes are stored")
    return value


def message(value: str) -> str:
    """An error message as stored: NUL characters and lone surrogates replaced, at most
    :data:`MESSAGE_CHARS` characters (a longer one ends with ``...``)."""
    value = value.replace("\x00", "\\x00").encode("utf-8", "backslashreplace").decode("utf-8")
    return value if len(value) <= MESSAGE_CHARS else value[:MESSAGE_CHARS - 3] + "..."
