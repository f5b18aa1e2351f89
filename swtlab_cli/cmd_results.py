"""``swtlab results --db URL [--csv FILE | --parquet FILE | --json]``: one row per run
(docs/results.md)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from swtlab_cli import exit_codes
from swtlab_base.atomic import atomic_file
from swtlab_base.domain.results import not_measured_heads

SUMMARY_COLUMNS = ["run_id", "mode", "load_set_n", "multipass", "slip_setpoint", "status",
                   "window_start_s", "window_end_s", "slip_mean", "slip_u95", "dp_n_mean",
                   "dp_n_se", "dp_n_u95", "torque_nm_mean", "torque_nm_u95", "sinkage_m_mean",
                   "sinkage_m_u95", "resistance_n_mean", "resistance_n_u95", "image_slip_mean",
                   "not_measured"]

REPLICATE_COLUMNS = ["wheel", "mode", "multipass", "load_set_n", "slip_setpoint", "quantity",
                     "runs", "mean", "replicate_sd", "within_u", "ratio", "larger"]

TOWED_COLUMNS = ["wheel", "soil", "multipass", "load_n", "towed_resistance_n",
                 "towed_resistance_se_n", "powered_resistance_at_zero_slip_n",
                 "powered_resistance_se_n", "powered_method", "difference_n"]


def register(sub: argparse._SubParsersAction) -> None:
    parser = sub.add_parser(
        "results", help="list the results of every run in the database",
        description="One row per run: identifiers and conditions, status and flags, the stable "
                    "window, and each quantity's mean, standard deviation, standard error and "
                    "uncertainty budget (u, u95 = k u, terms) in SI units (columns: "
                    "docs/results.md); runs that failed (status failed) with the stage, "
                    "exception type and reason. Without --csv/--parquet/--json, a summary "
                    "table.")
    parser.add_argument("--db", required=True,
                        help="database URL or SQLite file path (read, never created or upgraded)")
    out = parser.add_mutually_exclusive_group()
    out.add_argument("--csv", type=Path, help="write every column to this CSV file")
    out.add_argument("--parquet", type=Path,
                     help="write every column to this Parquet file (pyarrow; keeps the dtypes)")
    out.add_argument("--json", action="store_true", help="every column as JSON records on stdout")
    instead = parser.add_mutually_exclusive_group()
    instead.add_argument("--towed", action="store_true",
                         help="instead: motion resistance of the towed runs against powered runs "
                              "at zero slip, per wheel, soil, multipass and load")
    instead.add_argument("--replicates", action="store_true",
                         help="instead: the spread of replicate runs (same condition) beside "
                              "their within-run uncertainty, per condition and quantity")
    parser.set_defaults(func=run)


def failed_rows(failures) -> pd.DataFrame:
    """One row per failed run (``traceability.store_failures.current_failures``): status
    ``failed``, the reason in ``flags`` and ``failure_reason``, the stage and exception type."""
    return pd.DataFrame.from_records([{
        "run_id": f.run_id or Path(f.path).stem, "status": "failed",
        "flags": f"{f.stage} failed: {f.error}", "raw_file_path": f.path,
        "raw_file_sha256": f.sha256, "failure_stage": f.stage,
        "failure_type": f.failure_type, "failure_reason": f.error}
        for f in failures], columns=["run_id", "status", "flags", "raw_file_path",
                                     "raw_file_sha256", "failure_stage", "failure_type",
                                     "failure_reason"])


#: the uncertainty each shown value is rounded by (GUM 7.2.6), per table; uncertainties
#: themselves show two significant digits
SUMMARY_U = {f"{q}_mean": f"{q}_u95" for q in ("slip", "dp_n", "torque_nm", "sinkage_m",
                                               "resistance_n")}
SUMMARY_U.update({"image_slip_mean": "image_slip_u95", "dp_n_se": "dp_n_se"})
TOWED_U = {"towed_resistance_n": "towed_resistance_se_n",
           "powered_resistance_at_zero_slip_n": "powered_resistance_se_n"}
REPLICATE_U = {"mean": "within_u", "replicate_sd": "replicate_sd", "within_u": "within_u"}


def shown(frame: pd.DataFrame, uncertainty: dict[str, str]) -> pd.DataFrame:
    """``frame`` as text for a person: each value of ``uncertainty``'s keys to the decimal of
    its row's uncertainty column (two significant digits; ``swtlab_base.rounding``), the
    uncertainty columns to two significant digits, other numbers to four, NaN empty."""
    from swtlab_base.rounding import plain, value_and_u

    us = set(uncertainty.values())
    out = {}
    for column in frame.columns:
        values = frame[column]
        if column in uncertainty and uncertainty[column] in frame:
            out[column] = [value_and_u(_float(v), _float(u))[0]
                           for v, u in zip(values, frame[uncertainty[column]])]
        elif column in us:
            out[column] = [value_and_u(None, _float(u))[1] for u in values]
        elif pd.api.types.is_float_dtype(values):
            out[column] = [plain(_float(v)) for v in values]
        else:
            out[column] = ["" if pd.isna(v) else str(v) for v in values]
    return pd.DataFrame(out, columns=frame.columns)


def _float(value) -> float | None:
    return None if value is None or pd.isna(value) else float(value)


def write_parquet(frame: pd.DataFrame, path: Path) -> None:
    """``frame`` to a Parquet file (pyarrow), atomically; ``pd.read_parquet`` gives it back
    with its dtypes (pandas metadata in the file)."""
    with atomic_file(path, "wb") as stream:
        frame.to_parquet(stream, engine="pyarrow", index=False)


def run(args: argparse.Namespace) -> int:
    from traceability import open_database
    from traceability.queries import latest_results
    from traceability.store_failures import current_failures

    with open_database(args.db, read_only=True)() as session:
        table = latest_results(session)
        failed = failed_rows(current_failures(session))
    if table.empty and failed.empty:
        print(f"swtlab results: {args.db}: no processed runs (run swtlab process first)",
              file=sys.stderr)
        return exit_codes.BAD_INPUT
    missing = table.loc[table["raw_file_missing"], "raw_file_path"] if len(table) else []
    if len(missing):
        print(f"swtlab results: notice: the raw files of {len(missing)} runs are missing "
              f"(marked by swtlab process): {'; '.join(missing)}", file=sys.stderr)
    if args.towed:
        from run_results import towed_vs_powered

        table = pd.DataFrame(towed_vs_powered(table)) if len(table) else table
        if table.empty:
            print(f"swtlab results: {args.db}: no towed runs", file=sys.stderr)
            return exit_codes.BAD_INPUT
        failed = failed.iloc[0:0]
    if args.replicates:
        from swtlab_base.domain.replicates import NO_REPLICATES, replicate_spread

        table = replicate_spread(table) if len(table) else table
        if table.empty:
            print(f"swtlab results: {args.db}: {NO_REPLICATES}")
            return exit_codes.OK
        table = table.assign(run_ids=table["run_ids"].map(" ".join))
        failed = failed.iloc[0:0]
    every = pd.concat([t for t in (table, failed) if len(t)], ignore_index=True)
    if args.csv or args.parquet:
        if args.csv:
            with atomic_file(args.csv, newline="") as stream:
                every.to_csv(stream, index=False)
        else:
            write_parquet(every, args.parquet)
        print(f"{len(every)} runs written to {args.csv or args.parquet}"
              + (f" ({len(failed)} failed)" if len(failed) else ""))
    elif args.json:
        print(every.to_json(orient="records", indent=1))
    elif args.towed:
        print(shown(table[TOWED_COLUMNS], TOWED_U).to_string(index=False))
    elif args.replicates:
        columns = [c for c in REPLICATE_COLUMNS if c in table.columns]
        print(shown(table[columns], REPLICATE_U).to_string(index=False))
    else:
        columns = [c for c in SUMMARY_COLUMNS if c in every.columns]
        if "not_measured" in every:  # the items' heads here; the full text in --csv/--json
            every = every.assign(not_measured=every["not_measured"].map(
                lambda v: "; ".join(not_measured_heads(v))))
        print(shown(every[columns], SUMMARY_U).to_string(index=False))
        for row in failed.itertuples():
            print(f"failed: {row.run_id}: {row.flags} [{row.failure_type}]")
    return exit_codes.OK
