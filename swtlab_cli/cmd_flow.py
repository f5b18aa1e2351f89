"""``swtlab flow RUN_OR_FRAMES``: soil velocity field under the wheel, side camera (SOFT)."""

from __future__ import annotations

import argparse
import json
import sys

from swtlab_cli import exit_codes
from swtlab_cli.flags import as_flags
from swtlab_base.atomic import write_atomically

ENGINE_CHOICES = ("deform-lk", "farneback", "dis")  # softflow.flow_engine.ENGINES, kept light


def _frames(text: str) -> tuple[int | None, int | None]:
    try:
        a, b = text.split(":")
        return (int(a) if a else None, int(b) if b else None)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected A:B (frame indices, B excluded)") from None


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "flow", help="soil velocity under the wheel, decay rates per angle (docs/softflow.md)",
        description="Soil Optical Flow Technique: dense soil flow between the side-camera frames "
                    "of the stable phase, averaged; velocities about the axle in the bin frame; "
                    "exponential decay rates k(beta) (radial) and alpha3(beta) (tangential) with "
                    "95 %% confidence intervals; for a grousered wheel the best effective-radius "
                    "model.")
    p.add_argument("source", help="MCAP run, CSV run folder, folder of images or video file")
    p.add_argument("--frames", type=_frames, metavar="A:B",
                   help="frame range (indices, B excluded), e.g. that of the stable phase")
    p.add_argument("--json", metavar="OUT", help="write the result as JSON to OUT ('-': stdout)")
    p.add_argument("--plots", metavar="DIR", help="write the PNG plots into DIR")
    p.add_argument("--px-per-m", type=float, help="scale, when swt.camera does not give it")
    p.add_argument("--fps", type=float, help="frame rate, when the frames carry no times")
    p.add_argument("--engine", choices=ENGINE_CHOICES, default=ENGINE_CHOICES[0],
                   help="optical-flow engine (default deform-lk, see docs/softflow.md)")
    p.add_argument("--dask", metavar="SCHEDULER_ADDRESS",
                   help="compute the frame pairs' flows on this dask.distributed scheduler's "
                        "workers (e.g. tcp://10.0.0.5:8786; docs/scale-out.md)")
    p.set_defaults(func=run, cli_parser=p)


def run(args: argparse.Namespace) -> int:
    from softflow.field_analysis import analyse_frames
    from softflow.flow_checks import FlowMeasurementError
    from softflow.frames import FrameSourceError, load_frames
    from softflow.wheel_detect import WheelNotFoundError
    from swtlab_base.cluster import connect

    try:
        client = connect(args.dask) if args.dask else None
    except ValueError as exc:
        print(f"swtlab flow: {as_flags(str(exc), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    try:
        fs = load_frames(args.source, args.frames, args.px_per_m, args.fps)
        result = analyse_frames(fs.frames, fs.t_s, fs.px_per_m, fs.direction, fs.wheel_center_px,
                                fs.wheel_radius_px, fs.grouser_count, fs.grouser_height_px,
                                args.engine, frame_range=fs.frame_range, source=fs.source,
                                client=client)
    except (FrameSourceError, WheelNotFoundError, OSError) as exc:
        print(f"swtlab flow: {as_flags(str(exc), args)}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except FlowMeasurementError as exc:
        print(f"swtlab flow: {fs.source}: soil flow not measured: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    finally:
        if client is not None:
            client.close()
    data = result.to_dict()
    if args.json == "-":
        print(json.dumps(data, indent=2))
    elif args.json:
        write_atomically(args.json, json.dumps(data, indent=2))
    if args.plots:
        from softflow.flow_plots import write_plots

        write_plots(result, fs.frames[0], args.plots)
    if args.json != "-":
        _summary(data)
    return exit_codes.OK


def _summary(data: dict) -> None:
    print(f"{data['source']}  frames {data['frame_range'][0]}:{data['frame_range'][1]}  "
          f"pairs {data['pairs']}  outliers {100 * data['outlier_fraction']:.2f} %")
    print(" beta_deg   k_per_m [95% CI]            alpha3_per_m [95% CI]")
    for row in data["per_beta"]:
        k, a = row["k"], row["alpha3"]
        fmt = lambda f: (f"{f['rate_per_m']:7.1f} [{f['ci95_per_m'][0]:6.1f},"  # noqa: E731
                         f"{f['ci95_per_m'][1]:6.1f}] R2 {f['r2']:.2f}") if f else "      -"
        print(f" {row['beta_deg']:7.1f}   {fmt(k):30s}  {fmt(a)}")
    unfit = [f"{row['beta_deg']:.0f} deg {name}: {row[name + '_reason']}"
             for row in data["per_beta"] for name in ("k", "alpha3")
             if row.get(name + "_reason") and -160 < row["beta_deg"] < -20]
    if unfit:
        print("contact-region angles without a rate: " + "; ".join(unfit))
    g = data["grouser_model"]
    if g:
        scores = ", ".join(f"{m} {1000 * s:.3f}" for m, s in g["scores_mps"].items())
        print(f"grouser model: {g['chosen']} (by {g['margin_percent']:.1f} %; RMS mm/s: {scores}; "
              f"gear gamma {g['gamma']})")
