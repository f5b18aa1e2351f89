"""Stored results of two swtlab SQLite databases, table by table: ``python -m
bench.compare_results OLD.sqlite NEW.sqlite`` (exit 1 if any table differs);
``--shifts`` says by how much, each number against its own standard uncertainty (below).

For a speed change that must not move a number: process the same campaign folder (the
same absolute path: soil-flow JSON names its source) with the old and the new code, then
compare. Every column but when a row was made, rows in sorted order (``--jobs`` may store
runs in another order)."""

from __future__ import annotations

import json
import math
import re
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


#: each run's quantities and their budgets, by file path and quantity
_QUANTITIES = ("SELECT f.path, q.quantity, q.mean, q.se, q.std, q.n, q.n_eff, u.u, u.dof, "
               "u.correction FROM run_quantity q JOIN run_result r ON q.run_result_id = r.id "
               "JOIN raw_file f ON r.raw_file_id = f.id LEFT JOIN run_uncertainty u ON "
               "u.run_result_id = r.id AND u.quantity = q.quantity")


def _numbers(value, path: str = "") -> dict[str, float]:
    """Numeric leaves of a JSON value by their path (list indices and keys)."""
    if isinstance(value, dict):
        items = [(f"{path}.{key}", item) for key, item in value.items()]
    elif isinstance(value, list):
        items = [(f"{path}[{i}]", item) for i, item in enumerate(value)]
    else:
        number = isinstance(value, (int, float)) and not isinstance(value, bool)
        return {path: float(value)} if number else {}
    return {k: v for where, item in items for k, v in _numbers(item, where).items()}


def shifts(old: str, new: str) -> None:
    """Per quantity, the largest change over the runs of: the mean against its SE and its
    combined standard uncertainty ``u``; the SE and ``u`` against their own standard
    uncertainty (``1/sqrt(2 dof)`` of themselves, GUM G.4.2 / Table E.1; ``n_eff`` for the
    SE); ``n`` in samples. Then every other numeric cell (JSON leaves included) by its
    largest relative change, table.column by table.column."""
    def rows(path: str) -> dict:
        with sqlite3.connect(path) as con:
            return {(r[0], r[1]): r[2:] for r in con.execute(_QUANTITIES)}
    a, b = rows(old), rows(new)
    print(f"{'quantity':24} {'runs':>5} {'|dmean|/se':>11} {'|dmean|/u':>10} {'|dse|/u(se)':>12} "
          f"{'|du|/u(u)':>10} {'|dn|':>5}")
    for quantity in sorted({q for _, q in a}):
        keys = [k for k in a if k[1] == quantity and k in b]
        worst = [0.0] * 5
        for key in keys:
            (m0, se0, _, n0, neff0, u0, dof0, _), (m1, se1, _, n1, _, u1, _, _) = a[key], b[key]
            worst[0] = max(worst[0], abs(m1 - m0) / se0 if se0 else float(m1 != m0))
            worst[1] = max(worst[1], abs(m1 - m0) / u0 if u0 else float(m1 != m0))
            worst[2] = max(worst[2], abs(se1 - se0) / (se0 / math.sqrt(2 * neff0))
                           if se0 and neff0 else float(se1 != se0))
            if u0 is not None and u1 is not None:
                worst[3] = max(worst[3], abs(u1 - u0) / (u0 / math.sqrt(2 * min(dof0, 1e12)))
                               if u0 and dof0 else float(u1 != u0))
            worst[4] = max(worst[4], abs(n1 - n0))
        print(f"{quantity:24} {len(keys):5d} {worst[0]:11.2e} {worst[1]:10.2e} {worst[2]:12.2e} "
              f"{worst[3]:10.2e} {worst[4]:5.0f}")
    missing = (a.keys() ^ b.keys())
    print(f"quantities stored in one database only: {len(missing)}")
    ta, tb = table_rows(old), table_rows(new)
    for table in sorted(ta):
        if table in ("run_quantity", "run_uncertainty") or ta[table] == tb.get(table):
            continue
        with sqlite3.connect(old) as con:
            names = [c[1] for c in con.execute(f"PRAGMA table_info({table})") if c[1] not in WHEN]
        worst: dict[str, float] = {}
        for ra, rb in zip(ta[table], tb.get(table, [])):
            for name, x, y in zip(names, ra, rb):
                if x == y:
                    continue
                if isinstance(x, str) and isinstance(y, str) and x[:1] in "[{":
                    nx, ny = _numbers(json.loads(x)), _numbers(json.loads(y))
                    pairs = [(k, nx[k], ny[k]) for k in nx.keys() & ny.keys() if nx[k] != ny[k]]
                    if nx.keys() != ny.keys():
                        worst[f"{name} (different keys)"] = math.inf
                elif isinstance(x, (int, float)) and isinstance(y, (int, float)):
                    pairs = [("", x, y)]
                else:
                    worst[f"{name} (not numbers)"] = math.inf
                    continue
                for key, u, v in pairs:
                    label = f"{name}{_generic(key)}"
                    change = abs(v - u) / max(abs(u), abs(v))
                    worst[label] = max(worst.get(label, 0.0), change)
        print(f"{table}: rows {len(ta[table])} / {len(tb.get(table, []))}; largest relative "
              "changes:")
        for label, change in sorted(worst.items(), key=lambda item: -item[1])[:12]:
            print(f"  {label:70} {change:.2e}")


def _generic(key: str) -> str:
    """A JSON path without its list indices (one line per kind of leaf)."""
    return re.sub(r"\[\d+\]", "[]", key)


if __name__ == "__main__":
    if "--shifts" in sys.argv:
        shifts(*[a for a in sys.argv[1:] if a != "--shifts"][:2])
        sys.exit(0)
    sys.exit(main(*sys.argv[1:3]))
