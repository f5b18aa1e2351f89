"""Stored results of two swtlab SQLite databases, table by table: ``python -m
bench.compare_results OLD.sqlite NEW.sqlite`` (exit 1 if any table differs).

For a speed change that must not move a number: process the same campaign folder (the
same absolute path: soil-flow JSON names its source) with the old and the new code, then
compare. Every column but when a row was made, rows in sorted order (``--jobs`` may store
runs in another order)."""

from __future__ import annotations

import sqlite3
import sys

#: columns that say when a row was made, not what was computed
WHEN = {"created_at"}


def table_rows(path: str) -> dict[str, list[tuple]]:
    """Every table's rows (without :data:`WHEN`), sorted."""
    with sqlite3.connect(path) as con:
        tables = [t for (t,) in con.execute("SELECT name FROM sqlite_master WHERE type = "
                                            "'table' AND name NOT LIKE 'sqlite_%' ORDER BY name")]
        out = {}
        for table in tables:
            kept = [f'"{c[1]}"' for c in con.execute(f"PRAGMA table_info({table})")
                    if c[1] not in WHEN]
            rows = con.execute(f"SELECT {', '.join(kept)} FROM {table}").fetchall()
            out[table] = sorted(rows, key=repr)
    return out


def main(old: str, new: str) -> int:
    a, b = table_rows(old), table_rows(new)
    differ = 0
    for table in sorted(a.keys() | b.keys()):
        same = a.get(table) == b.get(table)
        differ += not same
        print(f"{table:24} {len(a.get(table, [])):6d} / {len(b.get(table, [])):6d} rows "
              f"{'same' if same else 'DIFFERENT'}")
    cells = sum(len(row) for rows in a.values() for row in rows)
    print(f"{len(a)} tables, {cells} cells: {differ} differ")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
