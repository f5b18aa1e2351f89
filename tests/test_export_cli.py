"""swtlab export on the processed sample campaign: the literature's 120 N check, the WPM CSV,
and the trace from every coefficient back to raw files."""

from __future__ import annotations

import pytest

import hashlib
import warnings

from sqlalchemy import func, select

from fitting import from_run_results, validate_load_interpolation
from swtlab_cli.main import main
from traceability import open_database
from traceability.models import CurveFit, RawFile, RunResult, WpmExport
from traceability.queries import latest_results
from wpm_export import WheelPerformanceModule

pytestmark = pytest.mark.slow  # the whole sample campaign (60 runs) processed once for both tests


def test_load_interpolation_predicts_the_120_n_runs(processed_sample_db):
    """RUAG WPAT validation: curves at 70/180/300 N interpolated to 120 N against the 120 N runs."""
    with open_database(processed_sample_db)() as session:
        table = from_run_results(latest_results(session))
    table = table[table["multipass"] == 0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        checks = {v.quantity: v for v in validate_load_interpolation(table, 120.0)}
    dp = checks["dp_n"]
    assert dp.tested_loads_n == (70.0, 180.0, 300.0) and dp.n_points >= 4
    assert dp.rmse_pct_of_range < 3.0
    # the force-like quantities against the measured DP range too (torque as T/r, r = 0.125 m)
    assert checks["resistance_n"].rmse < 0.03 * dp.measured_range
    assert checks["torque_nm"].rmse / 0.125 < 0.03 * dp.measured_range


def test_export_writes_the_wpm_csv_and_records_its_trace(processed_sample_db, tmp_path, capsys):
    out = tmp_path / "wpm.csv"
    assert main(["export", "--db", processed_sample_db, "-o", str(out)]) == 0
    assert "not fitted" in capsys.readouterr().out  # the 5-run 120 N series is validation only
    file_hash = hashlib.sha256(out.read_bytes()).hexdigest()
    factory = open_database(processed_sample_db)
    with factory() as session:
        export = session.scalars(select(WpmExport).order_by(WpmExport.id.desc())).first()
        assert export.file_sha256 == file_hash
        assert len(export.fits) == 2 * 3 * 5  # multipass x tested loads x quantities
        fit = next(f for f in export.fits if f.quantity == "dp_n" and f.load_n == 180.0
                   and f.multipass == 0)
        raw_files = {r.raw_file.path for r in fit.inputs}
        assert len(raw_files) == fit.n_points
        assert all("L180_MP0" in path for path in raw_files)
        n_fits = session.scalar(select(func.count()).select_from(CurveFit))
    # the same inputs again: fits reused, one more export
    assert main(["export", "--db", processed_sample_db, "-o", str(tmp_path / "again.csv")]) == 0
    with factory() as session:
        assert session.scalar(select(func.count()).select_from(CurveFit)) == n_fits
        assert session.scalar(select(func.count()).select_from(WpmExport)) >= 2
        assert session.scalar(select(func.count()).select_from(RawFile)) == session.scalar(
            select(func.count()).select_from(RunResult))
    assert (tmp_path / "again.csv").read_bytes() == out.read_bytes()
    wpm = WheelPerformanceModule.load(out)
    answer = wpm.slip_for("dp_n", 500.0, 180.0, multipass=0)
    assert float(answer.slip) == 1.0 and answer.status == "above_max"
