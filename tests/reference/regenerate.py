"""The stored reference of the sample campaign's outputs (issue 39, item 7): what ``make demo``
gives for ``sample_data/campaign``, normalised, under ``tests/reference/sample_campaign/``.

- ``results.csv``: ``swtlab results --csv``, raw-file paths relative to the repository;
- ``wpm.csv``: ``swtlab export``, without its ``# swtlab_version`` line;
- ``gap.json``: ``swtlab gap --sim terramechanics/models/bb2_sand.toml`` (the demo's
  settings), the measured database's URL as ``<measured database>``, paths relative to the
  repository, any ``swtlab_version``/``version``/``created``/``created_at`` key left out.

A commit that means to change a number regenerates them, in the repository root, with::

    python -m tests.reference.regenerate            # all three (about 40 s)
    python -m tests.reference.regenerate gap.json   # one of them

and commits the changed files with the change (``git diff`` shows what moved).
``tests/test_reference_sample.py`` checks the code against them.

Both compute in a child process on one pinned instruction set
(:mod:`bench.pinned_isa`): the last bits of NumPy, OpenBLAS, Numba and OpenCV otherwise differ
from machine to machine, and a stable window can move by one sample.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import io
import json
import math
import sqlite3
import subprocess
import sys
import tempfile
from pathlib import Path

from bench.pinned_isa import pinned_env

ROOT = Path(__file__).resolve().parents[2]
CAMPAIGN = ROOT / "sample_data" / "campaign"
MODEL = ROOT / "terramechanics" / "models" / "bb2_sand.toml"
REFERENCE = Path(__file__).resolve().parent / "sample_campaign"
NAMES = ("results.csv", "wpm.csv", "gap.json")
#: keys of the gap JSON that say when and by which version, not what was found
UNSTABLE_KEYS = {"swtlab_version", "version", "created", "created_at"}
#: numbers agree to this relative tolerance: the same code on another CPU or BLAS may sum in
#: another order (last bits); a change a commit means is many orders larger
REL_TOL = 1e-9


def _cli(*argv: str) -> None:
    from swtlab_cli.main import main

    with contextlib.redirect_stdout(io.StringIO()):
        code = main(list(argv))
    if code != 0:
        raise RuntimeError(f"swtlab {' '.join(argv)}: exit {code}")


def _relative(text: str) -> str:
    return text.replace(str(ROOT) + "/", "")


def _clean(value, db_url: str):
    if isinstance(value, dict):
        return {k: _clean(v, db_url) for k, v in value.items() if k not in UNSTABLE_KEYS}
    if isinstance(value, list):
        return [_clean(v, db_url) for v in value]
    if isinstance(value, str):
        return _relative(value.replace(db_url, "<measured database>"))
    return value


def outputs(db_url: str, workdir: Path, names: tuple[str, ...] = NAMES) -> dict[str, str]:
    """The normalised ``names`` of the sample campaign processed into ``db_url`` (by
    ``swtlab process``), made with the demo's commands in ``workdir``."""
    out: dict[str, str] = {}
    if "results.csv" in names:
        _cli("results", "--db", db_url, "--csv", str(workdir / "results.csv"))
        out["results.csv"] = _relative((workdir / "results.csv").read_text())
    if "wpm.csv" in names:
        _cli("export", "--db", db_url, "-o", str(workdir / "wpm.csv"))
        out["wpm.csv"] = "".join(line for line in (workdir / "wpm.csv").read_text()
                                 .splitlines(keepends=True)
                                 if not line.startswith("# swtlab_version:"))
    if "gap.json" in names:
        _cli("gap", "--measured", db_url, "--sim", str(MODEL), "--json",
             str(workdir / "gap.json"))
        report = _clean(json.loads((workdir / "gap.json").read_text()), db_url)
        out["gap.json"] = json.dumps(report, indent=1, sort_keys=True) + "\n"
    return out


def _computed(names: tuple[str, ...], keep_db: Path | None = None) -> dict[str, str]:
    with tempfile.TemporaryDirectory() as tmp:
        db_url = f"sqlite:///{Path(tmp) / 'swtlab.sqlite'}"
        _cli("process", str(CAMPAIGN), "--db", db_url, "--quiet")
        if keep_db is not None:
            sqlite_copy(Path(tmp) / "swtlab.sqlite", keep_db)
        return outputs(db_url, Path(tmp), names)


def sqlite_copy(source: Path, target: Path) -> None:
    """``source`` copied to ``target`` by SQLite's backup (the same database, page for page)."""
    with contextlib.closing(sqlite3.connect(source)) as a, \
            contextlib.closing(sqlite3.connect(target)) as b:
        a.backup(b)


def pinned_outputs(names: tuple[str, ...] = NAMES,
                   keep_db: Path | None = None) -> dict[str, str]:
    """:func:`outputs` of the sample campaign processed afresh, computed in a child process
    on the pinned instruction set; ``keep_db``: where to keep a copy of the processed
    database as it was before the outputs were made."""
    keep = [] if keep_db is None else ["--keep-db", str(keep_db)]
    done = subprocess.run([sys.executable, "-m", "tests.reference.regenerate", "--print",
                           *keep, *names], cwd=ROOT, env=pinned_env(),
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"the pinned reference run failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout)


def _same(a, b) -> bool:
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=REL_TOL)
    return a == b


def _number(text: str):
    try:
        return float(text)
    except ValueError:
        return text


def _walk(where: str, a, b, found: list[str]) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                found.append(f"{where}/{k}: only in the {'reference' if k in a else 'new output'}")
            else:
                _walk(f"{where}/{k}", a[k], b[k], found)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            found.append(f"{where}: {len(a)} items in the reference, {len(b)} now")
        for i, (x, y) in enumerate(zip(a, b)):
            _walk(f"{where}[{i}]", x, y, found)
    elif not _same(a, b):
        found.append(f"{where}: reference {a!r}, now {b!r}")


def differences(name: str, reference: str, now: str) -> list[str]:
    """Where ``now`` differs from ``reference`` (numbers to :data:`REL_TOL`), for output
    ``name``: a CSV compared cell by cell (comment lines as text), JSON value by value."""
    found: list[str] = []
    if name.endswith(".json"):
        _walk(name, json.loads(reference), json.loads(now), found)
        return found
    rows = [[[_number(cell) for cell in row] if not row or not row[0].startswith("#") else row
             for row in csv.reader(io.StringIO(text))] for text in (reference, now)]
    header = next((row for row in rows[0] if row and not str(row[0]).startswith("#")), [])
    if len(rows[0]) != len(rows[1]):
        found.append(f"{name}: {len(rows[0])} lines in the reference, {len(rows[1])} now")
    for i, (x, y) in enumerate(zip(*rows)):
        if len(x) != len(y):
            found.append(f"{name} line {i + 1}: {len(x)} cells in the reference, {len(y)} now")
        for j, (a, b) in enumerate(zip(x, y)):
            if not _same(a, b):
                column = header[j] if j < len(header) else j
                found.append(f"{name} line {i + 1}, {column}: reference {a!r}, now {b!r}")
    return found


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.reference.regenerate")
    parser.add_argument("names", nargs="*", help=f"some of {', '.join(NAMES)} (default: all)")
    parser.add_argument("--print", action="store_true",
                        help="compute here and print the outputs as JSON (the pinned child)")
    parser.add_argument("--keep-db", type=Path, help="with --print: keep the processed database")
    args = parser.parse_args(argv)
    names = tuple(args.names) or NAMES
    unknown = sorted(set(names) - set(NAMES))
    if unknown:
        parser.error(f"unknown output(s) {unknown}; known: {list(NAMES)}")
    if args.print:
        print(json.dumps(_computed(names, args.keep_db)))
        return 0
    REFERENCE.mkdir(parents=True, exist_ok=True)
    for name, text in pinned_outputs(names).items():
        before = (REFERENCE / name).read_text() if (REFERENCE / name).is_file() else None
        (REFERENCE / name).write_text(text)
        moved = ("new" if before is None else
                 f"{len(differences(name, before, text))} value(s) moved")
        print(f"{REFERENCE / name}: {moved}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
