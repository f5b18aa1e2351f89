"""The package boundaries (pyproject.toml [tool.importlinter], README "Layout"): the layers
of the installed package, each importing only the ones below it (swtlab_base at the bottom,
the API and the command line on top), no import cycle inside a package nor between the
top-level packages, no installed package imports the repository's test code, the second rig
imports neither the virtual testbed nor any estimator, the apart testbed (testbeds.apart)
imports neither the project's physics nor any estimator. import-linter follows indirect
imports too. And what `pip install swtlab` installs: the stages, not the test code."""

from __future__ import annotations

import itertools
import re
import shutil
import subprocess
import sys
import tomllib
from fnmatch import fnmatch
from pathlib import Path

import pytest


ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
TEST_CODE = ("virtual_testbed", "validation", "testbeds", "bench", "tests")
CONTRACTS = PYPROJECT["tool"]["importlinter"]["contracts"]


def _installed() -> set[str]:
    """The top-level packages `pip install swtlab` installs (folders of this checkout)."""
    include = PYPROJECT["tool"]["setuptools"]["packages"]["find"]["include"]
    return {p.name for p in ROOT.iterdir()
            if (p / "__init__.py").is_file() and any(fnmatch(p.name, pattern)
                                                     for pattern in include)}


def test_import_contracts_kept():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert exe, "lint-imports (import-linter) is not installed in this environment"
    done = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    outcome = re.search(r"Contracts: (\d+) kept, (\d+) broken\.", done.stdout)
    assert outcome, done.stdout[-2000:]
    assert (int(outcome[1]), int(outcome[2])) == (len(CONTRACTS), 0), done.stdout[-2000:]
    for contract in CONTRACTS:  # each by name: kept
        assert re.search(re.escape(contract["name"]).replace(r"\ ", r"\s+") + r"\s+KEPT",
                         done.stdout), contract["name"]


def test_every_installed_package_has_its_place_in_the_layers():
    """One layers contract orders the whole installed package: a new top-level package must
    take a place in it (else nothing keeps it from importing upward)."""
    layers = [c for c in CONTRACTS if c["type"] == "layers"]
    assert len(layers) == 1
    placed = [name.strip() for layer in layers[0]["layers"] for name in layer.split("|")]
    assert sorted(placed) == sorted(_installed())
    assert placed[0] == "swtlab_cli" and placed[-1] == "swtlab_base"


def test_no_import_cycle_between_the_top_level_packages():
    """The layers rule this out for the installed package; here the repository's test code
    (virtual_testbed, validation, testbeds) is included. A package that imports another
    which, directly or through others, imports it back is a cycle."""
    grimp = pytest.importorskip("grimp")
    roots = PYPROJECT["tool"]["importlinter"]["root_packages"]
    graph = grimp.build_graph(*roots, cache_dir=None)
    cycles = [(a, b) for a, b in itertools.permutations(roots, 2)
              if graph.chain_exists(importer=a, imported=b, as_packages=True)
              and graph.chain_exists(importer=b, imported=a, as_packages=True)]
    assert cycles == []


def test_the_installed_package_holds_no_test_code():
    installed = _installed()
    assert {"swtlab", "swtlab_base", "swtlab_cli", "ingest", "run_results",
            "sim_gap"} <= installed
    assert not installed & set(TEST_CODE)
    # the calibration's hold-out harness is a bench's, kept in validation/
    assert not (ROOT / "sim_gap" / "holdout.py").exists()
