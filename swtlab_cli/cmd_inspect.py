"""``swtlab inspect RUN``: a run as ingest sees it (metadata, channels, rates, gaps, problems)."""

from __future__ import annotations

import argparse
import json
import os
import sys

from swtlab_cli import exit_codes
from swtlab_cli.flags import as_flags


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "inspect", help="show a run as ingest sees it",
        description="Show a run as ingest sees it: metadata, each channel's rate, span, gaps "
                    "and units, the common time base, and every problem found. Exits 3 when "
                    "the run lacks a channel the stable phase needs (the wheel's or the "
                    "sled's speed), naming it.")
    parser.add_argument("run", help="a .mcap file, a CSV run folder (run.json), or a file a "
                                    "channel map describes")
    parser.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    parser.add_argument("--channel-map", metavar="MAP", default=None,
                        help="channel map: a .toml path or a shipped name (e.g. "
                             "cmu_3d_terramechanics); default: the spec form")
    parser.set_defaults(func=run, cli_parser=parser)


def run(args: argparse.Namespace) -> int:
    from ingest import IngestError, read_run
    from ingest.inspect_report import render_text, report

    try:
        data = report(read_run(args.run, args.channel_map))
    except IngestError as exc:
        print(as_flags(str(exc), args), file=sys.stderr)
        return exit_codes.BAD_INPUT
    text = json.dumps(data, indent=2, allow_nan=False) if args.json else render_text(data)
    try:
        print(text)
        sys.stdout.flush()
    except BrokenPipeError:  # `swtlab inspect run | head`: the reader left, not an error
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    for line in data["stable_phase_missing"]:
        print(f"{args.run}: {line}", file=sys.stderr)
    return exit_codes.BAD_INPUT if data["stable_phase_missing"] else exit_codes.OK

