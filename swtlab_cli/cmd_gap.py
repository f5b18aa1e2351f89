"""``swtlab gap --measured DB_URL_OR_CSV [--measured ...] --sim MODEL_TOML_OR_WPM [--json F]
[--html F]``: the sim-to-real gap diagnosis (docs/gap-report.md)."""

from __future__ import annotations

import argparse
import sys

from swtlab_cli import exit_codes


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "gap", help="diagnose the sim-to-real gap: where, which missing effect, how far",
        description="Residual map of measured against simulated drawbar pull, torque, sinkage "
                    "and resistance; candidate explanations (soil recalibration, each missing "
                    "effect, pairs) fitted and scored on held-out loads, multipass and gravity "
                    "levels; a verdict (effects, none, or inconclusive with the test that "
                    "would decide); held-out RMSE before and after. docs/gap-report.md. "
                    "With a database as the measured side, the report is also recorded there "
                    "(and shown by swtlab report).")
    p.add_argument("--measured", required=True, action="append",
                   help="database URL or SQLite file (swtlab process), WPM CSV, points CSV "
                        "(docs/points-csv.md) or CMU smooth_runs.csv; repeat for several "
                        "sources on one soil (fitted jointly, each with its own wheel)")
    p.add_argument("--sim", required=True, help="model TOML or a simulator's WPM CSV")
    p.add_argument("--reference-model", help="model TOML computing effect corrections for a "
                                             "WPM-CSV simulation (default: bb2_sand, no effects)")
    p.add_argument("--effects", help="comma-separated candidate effects (default: all the "
                                     "simulation lacks)")
    p.add_argument("--laws", help="laws the candidates may use, comma-separated effect=law "
                                  "(repeat an effect for several), e.g. grousers=ding2011,"
                                  "slip_sinkage=lyasko2010,slip_sinkage=lyasko2010~load (default: "
                                  "every law of each effect, load-varying forms included; "
                                  "docs/gap-report.md)")
    p.add_argument("--json", help="write the report JSON here")
    p.add_argument("--html", help="write the HTML report here")
    p.add_argument("--jobs", type=int, default=1, help="worker processes (default 1)")
    p.add_argument("--boot", type=int, default=200, help="bootstrap replicates (default 200)")
    p.add_argument("--seed", type=int, default=0, help="bootstrap seed")
    p.add_argument("--allow-wheel-mismatch", action="store_true",
                   help="diagnose even when the measured wheel is not the simulated one "
                        "(radius, width, grousers); the differences go into the report")
    p.set_defaults(func=run)


def parse_laws(text: str) -> dict[str, tuple[str, ...]]:
    """``grousers=ding2011,grousers=bekker1956,slip_sinkage=lyasko2010`` -> effect -> laws,
    each checked against terramechanics.LAWS."""
    import terramechanics as tm

    out: dict[str, tuple[str, ...]] = {}
    for item in (t.strip() for t in text.split(",") if t.strip()):
        effect, sep, law = (x.strip() for x in item.partition("="))
        if not sep or not law:
            raise ValueError(f"{item!r} is not effect=law")
        tm.law_class(effect, law)
        out[effect] = out.get(effect, ()) + (law,)
    return out


def run(args: argparse.Namespace) -> int:
    from sim_gap.vocabulary import EFFECT_NAMES
    from swtlab.pipeline.gap import diagnose_gap

    effects = None
    if args.effects:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        unknown = sorted(set(effects) - set(EFFECT_NAMES))
        if unknown:
            print(f"swtlab gap: unknown effect(s) {unknown}; known: {list(EFFECT_NAMES)}",
                  file=sys.stderr)
            return exit_codes.USAGE
    try:
        laws = parse_laws(args.laws) if args.laws else None
    except (KeyError, ValueError) as exc:
        print(f"swtlab gap: --laws: {exc}", file=sys.stderr)
        return exit_codes.USAGE
    from sim_gap.measured import is_database

    measured = args.measured[0] if len(args.measured) == 1 else args.measured
    try:
        gap = diagnose_gap(measured, args.sim, effects=effects,
                           reference_model=args.reference_model, n_boot=args.boot,
                           jobs=args.jobs, seed=args.seed, laws=laws,
                           allow_wheel_mismatch=args.allow_wheel_mismatch,
                           record_in=measured if isinstance(measured, str)
                           and is_database(measured) else None)  # recorded there too
        gap.write(args.json, args.html)
    except (OSError, ValueError, KeyError) as exc:
        print(f"swtlab gap: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    report = gap.typed
    for line in (report.wheel or {}).get("mismatches", []):
        print(f"wheel mismatch allowed: {line}")
    if len(report.sources or ()) > 1:
        for effect in (report.effect_sources or {}).values():
            print(effect["text"])
    verdict = report.verdict
    print("verdict:", verdict if isinstance(verdict, str) else (", ".join(verdict) or "none"))
    print("reason:", report.reason)
    for entry in report.effect_sets[:3]:
        print(f"  P({entry.label}) = {entry.probability:.3f}")
    for test in report.next_tests:
        print(f"next test ({test['gain_bits']:.2f} bits expected): {test['test']}")
    if report.separating_test:
        print("where the gap is largest:", report.separating_test["test"])
    for q, before in report.held_out_rmse_before.items():
        print(f"{q}: held-out RMSE {before:.4g} -> {report.held_out_rmse_after[q]:.4g} "
              f"({report.shrink_pct[q]:.1f} % shrink)")
    return exit_codes.OK
