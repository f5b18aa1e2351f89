"""Entry point of the ``swtlab`` console command.

Each subcommand lives in its own module ``swtlab_cli/cmd_<name>.py`` exposing
``register(subparsers)``; the parser it adds carries ``func(args) -> int``. Only the module of
the command being run is imported (``swtlab --help`` lists the commands from
:data:`COMMANDS` and imports none of them: no NumPy, pandas or database layer at start-up).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from swtlab_base.errors import InputError
from swtlab_cli import exit_codes

#: command -> its one-line help (the same as the module's ``add_parser(help=...)``; a test
#: keeps them equal), in the order ``swtlab --help`` lists them
COMMANDS = {
    "inspect": "show a run as ingest sees it",
    "process": "ingest and process every run of a campaign into the database",
    "results": "list the results of every run in the database",
    "export": "fit the performance curves and write the WPM CSV",
    "wpm": "Wheel Performance Module queries on a WPM CSV (docs/wpm-csv.md)",
    "report": "write the campaign report: one self-contained HTML page per campaign",
    "sim": "terramechanics curves of a model file (docs/model-file.md)",
    "track-slip": "slip from a photo of the wheel track (docs/track-slip.md)",
    "flow": "soil velocity under the wheel, decay rates per angle (docs/softflow.md)",
    "gap": "diagnose the sim-to-real gap: where, which missing effect, how far",
    "gap-bench": "blind check of `swtlab gap` on virtual campaigns with hidden effects",
    "migrate": "create the database or upgrade its schema to this swtlab's",
}


def command_module(command: str):
    """The module of ``command`` (``swtlab_cli.cmd_<name>``), imported now."""
    return importlib.import_module(f"swtlab_cli.cmd_{command.replace('-', '_')}")


class _Version(argparse.Action):
    """``--version``: the installed version, looked up only when asked."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        from traceability.provenance import swtlab_version

        parser.exit(message=f"swtlab {swtlab_version()}\n")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``swtlab`` parser with ``command``'s own parser registered (its module imported);
    every other command is listed by name and help only."""
    parser = argparse.ArgumentParser(
        prog="swtlab",
        description="Single-wheel testbed data: raw runs to wheel characterisation.",
        epilog=exit_codes.EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action=_Version, help="show the version and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, help_text in COMMANDS.items():
        if name == command:
            command_module(name).register(sub)
        else:
            sub.add_parser(name, help=help_text, add_help=False)
    return parser


def _command(argv: list[str]) -> str | None:
    """The command named in ``argv`` (its first word that is no option), if it is one."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in COMMANDS else None


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(_command(argv))
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return exit_codes.USAGE
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        print("swtlab: interrupted", file=sys.stderr)
        return 130
    except InputError as exc:  # the user's file, value or database: one line naming it
        print(f"swtlab {args.command}: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except Exception as exc:  # last line of defence, one line for the user
        print(f"swtlab: internal error: {type(exc).__name__}: {exc} "
              "(rerun with SWTLAB_DEBUG=1 for the traceback)", file=sys.stderr)
        import os

        if os.environ.get("SWTLAB_DEBUG"):
            raise
        return exit_codes.INTERNAL


if __name__ == "__main__":
    sys.exit(main())
