"""``swtlab track-slip IMAGE``: driving slip from a photo of the wheel track (grouser marks)."""

from __future__ import annotations

import argparse
import json
import sys

from swtlab_cli import exit_codes


def _points(text: str) -> tuple[tuple[float, float], tuple[float, float]]:
    try:
        x1, y1, x2, y2 = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected x1,y1,x2,y2 in pixels") from None
    return (x1, y1), (x2, y2)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "track-slip", help="slip from a photo of the wheel track (docs/track-slip.md)",
        description="Find the track and its grouser marks in a top view, measure their mean "
                    "spacing over the whole visible track and give the driving slip "
                    "s = 1 - spacing*n/(2*pi*r), r the wheel radius WITHOUT grousers.")
    p.add_argument("image", help="top view of the track (PNG, JPEG, ...)")
    p.add_argument("--radius-m", type=float, required=True,
                   help="wheel radius without grousers (m), as in swt.wheel radius_m")
    p.add_argument("--grousers", type=int, required=True, help="number of grousers")
    scale = p.add_mutually_exclusive_group(required=True)
    scale.add_argument("--px-per-m", type=float, help="ground scale at the image centre")
    scale.add_argument("--scale-points", type=_points, metavar="X1,Y1,X2,Y2",
                       help="two image points a known distance apart (with --scale-distance-m)")
    p.add_argument("--scale-distance-m", type=float, help="distance between the scale points (m)")
    p.add_argument("--json", action="store_true", help="machine-readable JSON on stdout")
    p.set_defaults(func=run, parser=p)


def run(args: argparse.Namespace) -> int:
    from softflow.track_slip import NoPeriodicMarksError, measure_track_slip

    if (args.scale_points is None) != (args.scale_distance_m is None):
        args.parser.error("--scale-points and --scale-distance-m go together")
    try:
        result = measure_track_slip(
            args.image, args.radius_m, args.grousers, px_per_m=args.px_per_m,
            scale_points=args.scale_points, scale_distance_m=args.scale_distance_m)
    except NoPeriodicMarksError as exc:
        print(f"swtlab track-slip: {args.image}: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    except (OSError, ValueError) as exc:
        print(f"swtlab track-slip: {exc}", file=sys.stderr)
        return exit_codes.BAD_INPUT
    if args.json:
        print(json.dumps(result.to_dict(), indent=2))
        return exit_codes.OK
    r = result
    print(f"slip             {100 * r.slip:.2f} % +- {100 * r.slip_std:.2f} % (1 sigma)\n"
          f"mark spacing     {1000 * r.spacing_m:.2f} mm +- {1000 * r.spacing_std_m:.2f} mm "
          f"(theoretical 2*pi*r/n = {1000 * r.theoretical_spacing_m:.2f} mm)\n"
          f"marks used       {r.marks_used} of {r.marks_expected} over "
          f"{1000 * r.length_m:.0f} mm of track\n"
          f"track direction  {r.track_angle_deg:.1f} deg in the image (x right, y down)\n"
          f"scale            {r.px_per_m:.1f} px/m")
    return exit_codes.OK
