"""The Python API's words in the command line's: an error raised through the API names its
keyword arguments (``multipass=0``, ``allow_run_id_reuse=True``); the command prints them as
its flags (``--multipass 0``, ``--allow-run-id-reuse``)."""

from __future__ import annotations

import argparse
import re
import shlex

#: ``name=value``: a keyword argument as the API's errors write it (text values quoted)
_KEYWORD = re.compile(r"(?<![\w./-])([a-z][a-z0-9_]*)=('[^']*'|\"[^\"]*\"|[^\s,;:)\]]+)")


def options(parser: argparse.ArgumentParser) -> dict[str, argparse.Action]:
    """Every optional argument of ``parser`` and of its sub-commands, by keyword (dest)."""
    found: dict[str, argparse.Action] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                for dest, inner in options(sub).items():
                    found.setdefault(dest, inner)
        elif action.option_strings:
            found.setdefault(action.dest, action)
    return found


def as_flags(text: str, args: argparse.Namespace) -> str:
    """``text`` with each keyword argument of the command's parser (``args.cli_parser``, set
    by the command's ``register``) written as its flag; other text unchanged."""
    parser = getattr(args, "cli_parser", None)
    known = options(parser) if parser is not None else {}

    def flag(match: re.Match) -> str:
        action = known.get(match.group(1))
        if action is None:
            return match.group(0)
        option = max(action.option_strings, key=len)
        value = match.group(2)
        if action.nargs == 0:  # a switch: only its "on" is a flag
            return option if value == "True" else match.group(0)
        if value[:1] in "'\"":
            value = value[1:-1]
        return f"{option} {shlex.quote(value)}"

    flags = _KEYWORD.sub(flag, text)
    return flags if flags == text else re.sub(r"(?<=\S), (?=--[a-z])", " ", flags)
