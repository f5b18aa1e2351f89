"""``swtlab migrate --db URL``: create the database or upgrade its schema to this swtlab's.

Only this command and ``swtlab process`` change a schema; the read commands refuse a
database at an older schema and name this command.
"""

from __future__ import annotations

import argparse

from swtlab_cli import exit_codes


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "migrate", help="create the database or upgrade its schema to this swtlab's",
        description=" ".join(line.strip() for line in __doc__.splitlines()[2:]))
    parser.add_argument("--db", required=True,
                        help="database URL or SQLite file path (created when missing)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from traceability import open_database
    from traceability.database import head_revision

    open_database(args.db)
    print(f"database: {args.db} at schema revision {head_revision()}")
    return exit_codes.OK
