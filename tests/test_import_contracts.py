"""The package boundaries of docs/architecture (pyproject.toml [tool.importlinter]): no estimator
imports the virtual testbed or the blind benches, no installed package imports the repository's
test code, no stage imports the CLI or the report, the report does not import the CLI, the
second rig imports neither the virtual testbed nor any estimator, the apart testbed
(testbeds.apart) imports neither the project's physics nor any estimator, the domain model
(swtlab.domain) imports no stage and no stage imports the pipeline (swtlab.pipeline).
import-linter follows indirect imports too. And what `pip install swtlab` installs: the
stages, not the test code."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tomllib
from fnmatch import fnmatch
from pathlib import Path


ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
TEST_CODE = ("virtual_testbed", "validation", "testbeds", "bench", "tests")


def test_import_contracts_kept():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert exe, "lint-imports (import-linter) is not installed in this environment"
    done = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    outcome = re.search(r"Contracts: (\d+) kept, (\d+) broken\.", done.stdout)
    assert outcome, done.stdout[-2000:]
    contracts = PYPROJECT["tool"]["importlinter"]["contracts"]
    assert (int(outcome[1]), int(outcome[2])) == (len(contracts), 0), done.stdout[-2000:]


def test_the_installed_package_holds_no_test_code():
    include = PYPROJECT["tool"]["setuptools"]["packages"]["find"]["include"]
    installed = {p.name for p in ROOT.iterdir()
                 if p.is_dir() and any(fnmatch(p.name, pattern) for pattern in include)}
    assert {"swtlab", "swtlab_cli", "ingest", "run_results", "sim_gap"} <= installed
    assert not installed & set(TEST_CODE)
    # the calibration's hold-out harness is a bench's, kept in validation/
    assert not (ROOT / "sim_gap" / "holdout.py").exists()
