"""Entry point of the ``swtlab`` console command.

Each subcommand lives in its own module ``swtlab_cli/cmd_<name>.py`` exposing
``register(subparsers)``; the parser it adds carries ``func(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from swtlab_cli import exit_codes

SUBCOMMANDS = ["inspect", "process", "results", "export", "wpm", "report", "sim",
               "track_slip", "flow", "gap", "gap_bench", "migrate"]


def build_parser() -> argparse.ArgumentParser:
    from traceability.provenance import swtlab_version

    parser = argparse.ArgumentParser(
        prog="swtlab",
        description="Single-wheel testbed data: raw runs to wheel characterisation.",
        epilog=exit_codes.EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"swtlab {swtlab_version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in SUBCOMMANDS:
        importlib.import_module(f"swtlab_cli.cmd_{name}").register(sub)
    return parser


def _is_database_error(exc: Exception) -> bool:
    """A database that cannot be used as asked (``traceability.database.UnusableDatabase``): the
    user's input, not swtlab's fault. Checked without importing the database layer."""
    database = sys.modules.get("traceability.database")
    return database is not None and isinstance(exc, database.UnusableDatabase)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return exit_codes.USAGE
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print("swtlab: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - last line of defence, one line for the user
        if _is_database_error(exc):
            print(f"swtlab {args.command}: {exc}", file=sys.stderr)
            return exit_codes.BAD_INPUT
        print(f"swtlab: internal error: {type(exc).__name__}: {exc} "
              "(rerun with SWTLAB_DEBUG=1 for the traceback)", file=sys.stderr)
        import os

        if os.environ.get("SWTLAB_DEBUG"):
            raise
        return exit_codes.INTERNAL


if __name__ == "__main__":
    sys.exit(main())
