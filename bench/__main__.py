"""Run every benchmark: ``python -m bench [name ...]``.

Each ``bench/bench_<name>.py`` has ``main(quick: bool) -> dict`` that prints
its own table and returns its numbers; the numbers of a run are written to
``bench/results/<name>.json`` for comparison between commits.
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
from pathlib import Path

import bench


def main() -> None:
    names = sorted(m.name[len("bench_"):] for m in pkgutil.iter_modules(bench.__path__)
                   if m.name.startswith("bench_"))
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("names", nargs="*", help=f"benchmarks to run (default: all of {names})")
    parser.add_argument("--quick", action="store_true", help="smaller inputs, for a smoke run")
    args = parser.parse_args()
    unknown = sorted(set(args.names) - set(names))
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; known: {names}")
    out = Path(__file__).parent / "results"
    out.mkdir(exist_ok=True)
    for name in args.names or names:
        print(f"== bench {name}")
        numbers = importlib.import_module(f"bench.bench_{name}").main(quick=args.quick)
        (out / f"{name}.json").write_text(json.dumps(numbers, indent=2, default=float))


if __name__ == "__main__":
    main()
