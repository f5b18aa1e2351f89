"""Run every benchmark: ``python -m bench [name ...]``.

Each ``bench/bench_<name>.py`` has ``main(quick: bool) -> dict`` that prints
its own table and returns its numbers; the numbers of a run are written to
``bench/results/<name>.json`` for comparison between commits. ``--markdown``: a benchmark
with ``markdown(numbers) -> str`` also writes ``docs/validation/<name>.md``, under its title
the line naming the release and the command (:func:`provenance`, which
tests/test_validation_records.py reads).
"""

from __future__ import annotations

import argparse
import importlib
import json
import pkgutil
import tomllib
from pathlib import Path

import bench
from swtlab_base.atomic import write_atomically


ROOT = Path(__file__).resolve().parents[1]


def provenance(name: str) -> str:
    """The line a page written by ``--markdown`` carries: the release of the checkout the
    bench ran on (pyproject.toml's version) and the command that wrote it."""
    release = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    return f"From release {release}: `python -m bench {name} --markdown`"


def page(name: str, markdown: str) -> str:
    """``markdown`` (a benchmark's page) with :func:`provenance` under its title line."""
    title, _, rest = markdown.partition("\n")
    return f"{title}\n\n{provenance(name)}\n{rest}"


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
            path = ROOT / "docs" / "validation" / f"{name}.md"
            path.parent.mkdir(exist_ok=True)
            write_atomically(path, page(name, module.markdown(numbers)))
            print(f"written {path}")


if __name__ == "__main__":
    main()
