"""``swtlab wpm query WPM.csv --load N (--dp X | --torque X | --sinkage X | --resistance X |
--slip S)``: answers of the Wheel Performance Module from a WPM CSV (docs/wpm-csv.md)."""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
import warnings

from swtlab_cli import exit_codes
from swtlab_cli.flags import as_flags

#: option -> quantity of the inverse query
TARGETS = {"dp": "dp_n", "torque": "torque_nm", "sinkage": "sinkage_m",
           "resistance": "resistance_n"}


def finite(text: str) -> float:
    """A finite number from the command line."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "wpm", help="Wheel Performance Module queries on a WPM CSV (docs/wpm-csv.md)",
        description="Answers from a WPM CSV, after RUAG's Wheel Performance Module.")
    sub = p.add_subparsers(dest="wpm_command", metavar="WPM_COMMAND", required=True)
    q = sub.add_parser(
        "query", help="slip for a required DP/torque/sinkage/resistance, or values at a slip",
        description="With --dp/--torque/--sinkage/--resistance: the smallest slip at which the "
                    "wheel gives that value at the load (slip 1.0 and the maximum when it "
                    "cannot). With --slip: every quantity at that slip. Loads between the "
                    "tested ones are interpolated across load on curve values.")
    q._negative_number_matcher = re.compile(r"^-\d*\.?\d")
    q.add_argument("wpm_csv", help="WPM CSV file")
    q.add_argument("--load", dest="load_n", type=finite, required=True, help="wheel load in N")
    ask = q.add_mutually_exclusive_group(required=True)
    ask.add_argument("--dp", type=finite, help="required drawbar pull in N")
    ask.add_argument("--torque", type=finite, help="required torque in N*m")
    ask.add_argument("--sinkage", type=finite, help="required sinkage in m")
    ask.add_argument("--resistance", type=finite, help="required motion resistance in N")
    ask.add_argument("--slip", type=finite, help="slip (fraction, driving (r*w - v)/(r*w))")
    q.add_argument("--soil", help="soil of the curves (needed when the file has several)")
    q.add_argument("--wheel", help="wheel of the curves (needed when the file has several)")
    q.add_argument("--multipass", type=int, help="multipass index of the curves")
    q.add_argument("--allow-extrapolation", action="store_true",
                   help="answer for a load outside the tested loads (linear, with a warning)")
    q.add_argument("--json", action="store_true", help="one JSON object on standard output")
    q.set_defaults(func=run_query, cli_parser=q)
    f = sub.add_parser(
        "fmu", help="the wheel as an FMI 2.0 co-simulation FMU (docs/wpm-csv.md)",
        description="Write an FMU of one curve set: inputs wheel load and slip, outputs DP, "
                    "torque, sinkage, resistance and their 95 %% half-widths, answered by the "
                    "C library from the embedded WPM CSV (no Python at run time).")
    f.add_argument("wpm_csv", help="WPM CSV file")
    f.add_argument("-o", "--output", required=True, help="FMU file to write (e.g. wheel.fmu)")
    f.add_argument("--soil", help="soil of the curves (needed when the file has several)")
    f.add_argument("--wheel", help="wheel of the curves (needed when the file has several)")
    f.add_argument("--multipass", type=int, help="multipass index of the curves")
    f.set_defaults(func=run_fmu, cli_parser=f)


def run_fmu(args: argparse.Namespace) -> int:
    from wpm_export import WpmFormatError, WpmSelectionError
    from wpm_export.fmu import build_fmu

    try:
        made = build_fmu(args.wpm_csv, args.output, soil=args.soil, wheel=args.wheel,
                         multipass=args.multipass)
    except (OSError, WpmFormatError, WpmSelectionError) as exc:
        print(f"swtlab wpm: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    print(f"{made['fmu']}: FMI 2.0 co-simulation FMU of {made['wheel']} on {made['soil']}, "
          f"multipass {made['multipass']}")
    return exit_codes.OK


def _print_text(answer: dict) -> None:
    head = (f"{answer['soil']} / {answer['wheel']} / multipass {answer['multipass']} at "
            f"{answer['load_n']:g} N ({answer['method']} across {answer['tested_loads_n']} N"
            + (", EXTRAPOLATED in load" if answer["extrapolated_load"] else "") + ")")
    print(head)
    if "quantity" in answer:
        q, u = answer["quantity"], answer["unit"]
        if answer["status"] == "ok":
            print(f"{q} = {answer['target']:g} {u} at slip {answer['slip']:.6g}")
            print(_slip_uncertainty(answer))
        elif answer["status"] == "at_step":
            print(f"{q} = {answer['target']:g} {u} at slip 0: inside the curve's jump at zero "
                  "slip (braked side to driven side)")
        elif answer["status"] == "above_max":
            print(f"{q} = {answer['target']:g} {u} is beyond the wheel: slip 1.0 (100 %), "
                  f"maximum achievable {answer['value']:.6g} {u}"
                  + (f" +- {answer['value_conf_half95']:.3g} {u} (95 % confidence), the "
                     "maximum over the fitted slip range" if answer["value_conf_half95"]
                     is not None else ", the maximum over the fitted slip range"))
        else:
            print(f"{q} = {answer['target']:g} {u} is below the curve over slips "
                  f"[{answer['slip_min']:g}, {answer['slip_max']:g}]: no slip; minimum "
                  f"{answer['value']:.6g} {u}")
        return
    for q, v in answer["values"].items():
        flag = "  (outside the fitted slip range: extrapolated)" \
            if answer["outside_slip_range"][q] else ""
        conf, pred = answer["conf_half95"][q], answer["pred_half95"][q]
        bands = f"  +- {conf:.3g} (95 % conf.), +- {pred:.3g} (one run, 95 % pred.)" \
            if conf is not None else "  (uncertainty unknown: no uncertainty columns)"
        print(f"{q:13s} {v:.6g} {answer['units'][q]}{bands}{flag}")


def _slip_uncertainty(answer: dict) -> str:
    """The slip's 95 % half-widths, or why there are none."""
    if not answer["uncertainty_known"]:
        return ("slip uncertainty unknown: the WPM CSV carries no uncertainty columns "
                "(written before swtlab 0.4.0, or by another tool)")
    conf, pred = answer["slip_conf_half95"], answer["slip_pred_half95"]
    if conf is None:
        return "slip uncertainty undetermined: the curve is flat there (slope 0)"
    u = answer["unit"]
    return (f"slip +- {conf:.3g} (95 % confidence of the curve), +- {pred:.3g} (95 % "
            f"prediction for one run); from the {answer['quantity']} band +- "
            f"{answer['value_conf_half95']:.3g} / {answer['value_pred_half95']:.3g} {u} "
            f"through u_slip ~ u / |d {answer['quantity']} / d slip| (linearised)")


def run_query(args: argparse.Namespace) -> int:
    from fitting.errors import FittingError
    from swtlab.pipeline.curves import query_wpm
    from wpm_export import WpmFormatError, WpmSelectionError

    option = next((o for o in TARGETS if getattr(args, o) is not None), None)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            answer = query_wpm(args.wpm_csv, args.load_n,
                               quantity=TARGETS[option] if option else None,
                               target=getattr(args, option) if option else None,
                               slip=args.slip, soil=args.soil, wheel=args.wheel,
                               multipass=args.multipass,
                               allow_extrapolation=args.allow_extrapolation)
    except (OSError, WpmFormatError, WpmSelectionError, FittingError) as exc:
        print(f"swtlab wpm: {as_flags(str(exc), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    for w in {str(w.message) for w in caught}:
        print(f"swtlab wpm: warning: {w}", file=sys.stderr)
    if args.json:
        print(json.dumps(answer))
    else:
        _print_text(answer)
    return exit_codes.OK
