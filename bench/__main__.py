"""Run every benchmark: ``python -m bench [name ...]``.

Each ``bench/bench_<name>.py`` has ``main(quick: bool) -> dict`` that prints
its own table and returns its numbers; the numbers of a run are written to
``bench/results/<name>.json`` for comparison between commits. ``--markdown``: a benchmark
with ``markdown(numbers) -> str`` also writes ``docs/validation/<name>.md``.
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
from pathlib import Path

import bench
from swtlab_base.atomic import write_atomically


def main() -> None:
    names = sorted(m.name[len("bench_"):] for m in pkgutil.iter_modules(bench.__path__)
                   if m.name.startswith("bench_"))
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("names", nargs="*", help=f"benchmarks to run (default: all of {names})")
    parser.add_argument("--quick", action="store_true", help="smaller inputs, for a smoke run")
    parser.add_argument("--markdown", action="store_true",
                        help="also write docs/validation/<name>.md where the benchmark can")
    args = parser.parse_args()
    unknown = sorted(set(args.names) - set(names))
    if unknown:
        parser.error(f"unknown benchmark(s) {unknown}; known: {names}")
    out = Path(__file__).parent / "results"
    out.mkdir(exist_ok=True)
    for name in args.names or names:
        print(f"== bench {name}")
        module = importlib.import_module(f"bench.bench_{name}")
        numbers = module.main(quick=args.quick)
        (out / f"{name}.json").write_text(json.dumps(numbers, indent=2, default=float))
        if args.markdown and hasattr(module, "markdown"):
            page = Path(__file__).parents[1] / "docs" / "validation" / f"{name}.md"
            page.parent.mkdir(exist_ok=True)
            write_atomically(page, module.markdown(numbers))
            print(f"written {page}")


if __name__ == "__main__":
    main()
