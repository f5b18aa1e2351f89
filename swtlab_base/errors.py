"""The one error hierarchy of swtlab: every error the project raises on purpose is a
:class:`SwtlabError`; the ones that mean the user's input cannot be used (a file, a channel,
a value, a database) are an :class:`InputError`, on which ``swtlab`` exits with code 3
(:mod:`swtlab_cli.exit_codes`). Anything else reaching the command line is a fault of swtlab
(exit code 4)."""

from __future__ import annotations


class SwtlabError(Exception):
    """An error swtlab raises on purpose; its message is one line for the user."""


class InputError(SwtlabError):
    """Input that cannot be used as given (file, channel or value, and the problem): the
    user's to fix, not a fault of swtlab."""
