"""``swtlab report`` reads stored results only: its modules load neither the raw-file readers
(ingest, scipy.signal) nor scipy.stats, and softflow (numba, OpenCV) only for a campaign with
soil flow (issue 19 item 5: a second of the report's start-up)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_the_report_modules_load_no_reader_and_no_scipy_stats():
    code = ("import sys, campaign_report, campaign_report.render, swtlab_cli.cmd_report; "
            "print(sorted(m for m in ('ingest', 'scipy.signal', 'scipy.stats', 'softflow', "
            "'numba', 'cv2', 'run_results.process') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                          text=True, env={"PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "[]"
