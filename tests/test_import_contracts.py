"""The package boundaries of docs/architecture (pyproject.toml [tool.importlinter]): no estimator
imports the virtual testbed or the blind benches, no stage imports the CLI or the report, the
report does not import the CLI, the second rig imports neither the virtual testbed nor any
estimator, the apart testbed (testbeds.apart) imports neither the project's physics nor any
estimator, the domain model (swtlab.domain) imports no stage and no stage imports the pipeline
(swtlab.pipeline). import-linter follows indirect imports too."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_import_contracts_kept():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert exe, "lint-imports (import-linter) is not installed in this environment"
    done = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-2000:]
    assert "Contracts: 9 kept, 0 broken." in done.stdout, done.stdout[-2000:]
