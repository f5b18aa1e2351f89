"""Run every benchmark: ``python -m bench [name ...]``.

Each ``bench/bench_<name>.py`` has ``main(quick: bool) -> dict`` that prints
its own table and returns its numbers; the numbers of a run are written to
``bench/results/<name>.json`` for comparison between commits. ``--markdown``: a benchmark
with ``markdown(numbers) -> str`` also writes ``docs/validation/<name>.md``, under its title
the line naming the release and the command (:func:`provenance`, which
tests/test_validation_records.py reads). A benchmark module with ``ON_PINNED_ISA = True``
runs in a child process on one instruction set (:mod:`bench.pinned_isa`): its figures count
verdicts at a threshold, which the last bits of another machine's kernels can turn.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import pkgutil
import subprocess
import sys
import tomllib
from collections.abc import Mapping
from pathlib import Path

import bench
from bench.pinned_isa import is_pinned, pinned_env
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


def pinned_child(name: str, module, options: list[str],
                 environ: Mapping[str, str] = os.environ) -> tuple[list[str], dict] | None:
    """The command and environment that run benchmark ``name`` (with ``options``) on the
    pinned instruction set, when its module asks for it and this process is not on it."""
    if not getattr(module, "ON_PINNED_ISA", False) or is_pinned(environ):
        return None
    return [sys.executable, "-m", "bench", name, *options], pinned_env(environ)


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
        child = pinned_child(name, module, ["--quick"] * args.quick
                             + ["--markdown"] * args.markdown)
        if child is not None:
            print("on the pinned instruction set (bench/pinned_isa.py), in a child process",
                  flush=True)
            subprocess.run(child[0], env=child[1], cwd=ROOT, check=True)
            continue
        numbers = module.main(quick=args.quick)
        (out / f"{name}.json").write_text(json.dumps(numbers, indent=2, default=float))
        if args.markdown and hasattr(module, "markdown"):
            path = ROOT / "docs" / "validation" / f"{name}.md"
            path.parent.mkdir(exist_ok=True)
            write_atomically(path, page(name, module.markdown(numbers)))
            print(f"written {path}")


if __name__ == "__main__":
    main()
