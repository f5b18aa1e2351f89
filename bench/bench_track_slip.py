"""Track-photo slip: accuracy over random renders (issue goal: |error| <= 0.5 pp for 95 %),
refusals on mark-free images, and which radius the mark spacing follows."""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from softflow.track_slip import NoPeriodicMarksError, measure_track_slip
from virtual_testbed.second_track_render import random_second_track, render_second_track
from virtual_testbed.track_render import mark_spacing_m, random_nuisance, render_track

RADIUS_M, GROUSERS, HEIGHT_M = 0.125, 12, 0.0092  # BB2-like wheel
SIZE_PX = (800, 600)


#: seeds looked at while tuning the period and mark fits (issue 21): first renderer 50 000-50 199
#: with 60 000 on (this bench's old draw), second renderer 80 000-80 039, 200-229, 300, 700-703;
#: the figures come from the fresh draws below
FRESH_FIRST, FRESH_SECOND = 150_000, 1000


def _accuracy(count: int, base: int = FRESH_FIRST) -> dict:
    """First renderer: slip evenly over 0-0.8, scale ``rng(base + i)``, nuisances ``base + 10 000
    + i``, render seed ``base + i``."""
    errors_pp, refused, seconds = [], 0, []
    slips = np.linspace(0.0, 0.8, count)
    for i, slip in enumerate(slips):
        rng = np.random.default_rng(base + i)
        px_per_m = float(rng.uniform(600, 900))
        image, truth = render_track(float(slip), RADIUS_M, GROUSERS, HEIGHT_M, px_per_m,
                                    seed=base + i,
                                    nuisance=random_nuisance(base + 10_000 + i, SIZE_PX))
        start = time.perf_counter()
        try:
            result = measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=px_per_m)
            errors_pp.append(100 * abs(result.slip - truth["slip"]))
        except NoPeriodicMarksError:
            refused += 1
            errors_pp.append(np.inf)
        seconds.append(time.perf_counter() - start)
    err = np.array(errors_pp)
    measured = err[np.isfinite(err)]
    out = {"renders": count, "refused": refused,
           "within_0p5pp": float(np.mean(err <= 0.5)),
           "median_abs_error_pp": float(np.median(err)),
           "p95_abs_error_pp": float(np.percentile(err, 95)),
           "max_abs_error_pp_measured": float(measured.max()),
           "median_seconds": float(np.median(seconds))}
    print(f"{'renders':>8}{'refused':>9}{'<=0.5pp':>9}{'median pp':>11}{'p95 pp':>8}"
          f"{'max pp':>8}{'s/image':>9}")
    print(f"{count:>8}{refused:>9}{out['within_0p5pp']:>9.1%}{out['median_abs_error_pp']:>11.3f}"
          f"{out['p95_abs_error_pp']:>8.3f}{out['max_abs_error_pp_measured']:>8.3f}"
          f"{out['median_seconds']:>9.2f}")
    return out


def _refusals(count: int) -> dict:
    refused = 0
    for i in range(count):
        nuisance = random_nuisance(70_000 + i, SIZE_PX)
        if i % 2:
            nuisance = replace(nuisance, track_width_m=0.0, sinkage_m=0.0)
        image, _ = render_track(0.3, seed=i, nuisance=replace(nuisance, marks=False))
        try:
            measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=900.0)
        except NoPeriodicMarksError:
            refused += 1
    print(f"mark-free images (sand, tracks without marks): {refused} of {count} refused")
    return {"mark_free_images": count, "mark_free_refused": refused}


def _radius() -> list[dict]:
    """Measured spacing against 2*pi*r*(1-s)/n with the rim radius and the tip radius."""
    rows = []
    print(f"{'h mm':>6}{'slip':>6}{'measured mm':>13}{'rim r mm':>10}{'tip r+h mm':>12}"
          f"{'slip(r) %':>11}{'slip(r+h) %':>13}")
    for height_m in (0.0092, 0.02, 0.03):
        for slip in (0.1, 0.4, 0.7):
            image, _ = render_track(slip, RADIUS_M, GROUSERS, height_m, 900.0, seed=1,
                                    size_px=SIZE_PX, track_angle_deg=25.0)
            rim = measure_track_slip(image, RADIUS_M, GROUSERS, px_per_m=900.0)
            tip = measure_track_slip(image, RADIUS_M + height_m, GROUSERS, px_per_m=900.0)
            row = {"grouser_height_m": height_m, "slip": slip, "measured_m": rim.spacing_m,
                   "rim_m": mark_spacing_m(slip, RADIUS_M, GROUSERS),
                   "tip_m": mark_spacing_m(slip, RADIUS_M + height_m, GROUSERS),
                   "slip_with_rim": rim.slip, "slip_with_tip": tip.slip}
            rows.append(row)
            print(f"{1000 * height_m:>6.1f}{slip:>6.2f}{1000 * row['measured_m']:>13.2f}"
                  f"{1000 * row['rim_m']:>10.2f}{1000 * row['tip_m']:>12.2f}"
                  f"{100 * rim.slip:>11.2f}{100 * tip.slip:>13.2f}")
    return rows


def _baseline_s() -> float:
    """Seconds of a fixed workload (ten 1024 x 1024 float FFTs, one thread): photo times are
    also given as a ratio to it, so a busy machine's numbers can be compared."""
    a = np.random.default_rng(0).standard_normal((1024, 1024))
    start = time.perf_counter()
    for _ in range(10):
        np.fft.rfft2(a)
    return time.perf_counter() - start


def _second(count: int, base: int = FRESH_SECOND) -> dict:
    """Second renderer (written apart): jittered, erased and smeared marks, uneven light,
    rotation, keystone, JPEG q80; seeds ``base`` on, slip evenly over 0-0.8; mark-free photos;
    seconds per photo with OpenCV on one thread."""
    import cv2

    cv2.setNumThreads(1)
    errors_pp, seconds = [], []
    for i, slip in enumerate(np.linspace(0.0, 0.8, count)):
        scene = random_second_track(base + i, float(slip))
        image, truth = render_second_track(scene)
        start = time.perf_counter()
        try:
            r = measure_track_slip(image, scene.radius_m, scene.grousers, px_per_m=scene.px_per_m)
            errors_pp.append(100 * abs(r.slip - truth["slip"]))
        except NoPeriodicMarksError:
            errors_pp.append(np.inf)
        seconds.append(time.perf_counter() - start)
    refused, mark_free = 0, max(count // 4, 5)
    for i in range(mark_free):  # random rotation, light, keystone; no marks
        image, _ = render_second_track(replace(random_second_track(90_000 + i, 0.3), marks=False))
        try:
            measure_track_slip(image, 0.125, 12, px_per_m=700.0)
        except NoPeriodicMarksError:
            refused += 1
    err = np.array(errors_pp)
    measured = err[np.isfinite(err)]
    baseline_s = _baseline_s()
    out = {"renders": count, "refused": int(np.sum(~np.isfinite(err))),
           "within_0p5pp": float(np.mean(err <= 0.5)),
           "median_abs_error_pp": float(np.median(err)),
           "p95_abs_error_pp": float(np.percentile(err, 95)),
           "max_abs_error_pp_measured": float(measured.max()) if measured.size else None,
           "mark_free": mark_free, "mark_free_refused": refused,
           "median_seconds_one_thread": float(np.median(seconds)),
           "baseline_seconds": baseline_s,
           "photo_over_baseline": float(np.median(seconds) / baseline_s)}
    print("second renderer:", {k: round(v, 4) if isinstance(v, float) else v
                               for k, v in out.items()})
    print(f"seconds per photo (one thread, median): {out['median_seconds_one_thread']:.2f}; "
          f"fixed workload {baseline_s:.3f} s; photo / workload {out['photo_over_baseline']:.2f}")
    return out


def main(quick: bool = False) -> dict:
    return {"second_renderer": _second(10 if quick else 40),
            "accuracy": _accuracy(30 if quick else 40),
            "refusals": _refusals(6 if quick else 40),
            "radius": _radius()}


def _seeds(base: int, count: int) -> str:
    return f"{base}-{base + count - 1}"


def _pp(value: float | None) -> str:
    return "refused" if value is None or not np.isfinite(value) else f"{value:.3f}"


def markdown(numbers: dict) -> str:
    """docs/validation/track_slip.md from :func:`main`'s numbers."""
    first, second = numbers["accuracy"], numbers["second_renderer"]
    refusals = numbers["refusals"]

    def row(name: str, seeds: str, r: dict) -> str:
        return (f"| {name} | {seeds} | {r['renders']} | {r['refused']} | "
                f"{100 * r['within_0p5pp']:.1f} % | {_pp(r['median_abs_error_pp'])} | "
                f"{_pp(r['p95_abs_error_pp'])} | {_pp(r['max_abs_error_pp_measured'])} |")

    lines = [
        "# Track-photo slip: validation record", "",
        "Written by `bench/bench_track_slip.py`; do not edit by hand (how to measure slip from "
        "a photo: [docs/track-slip.md](../track-slip.md)). BB2-like wheel (r = 125 mm, 12 "
        "grousers of 9.2 mm); slip evenly over 0-0.8; truth from the renderer. The first "
        "renderer (`virtual_testbed/track_render.py`: 800 x 600 px, 600-900 px/m, every "
        "nuisance random) is the one the estimator was tuned beside; the second "
        "(`virtual_testbed/second_track_render.py`: painted sand, jittered, erased and smeared "
        "marks, uneven light, rotation, keystone, JPEG q80; 640 x 480 px) was written apart "
        "from it. The seeds below are fresh; the seeds looked at while tuning are named in "
        "the bench's source. A refusal counts as a failure.", "",
        "## Accuracy", "",
        "| renderer | seeds | renders | refused | within 0.5 pp | median error pp | "
        "95th percentile pp | largest measured pp |",
        "|---|---|---:|---:|---:|---:|---:|---:|",
        row("first", _seeds(FRESH_FIRST, first["renders"]), first),
        row("second", _seeds(FRESH_SECOND, second["renders"]), second), "",
        "## Photos without marks", "",
        f"Plain sand and tracks without marks (first renderer): {refusals['mark_free_refused']} "
        f"of {refusals['mark_free_images']} refused; second renderer (random rotation, light, "
        f"keystone): {second['mark_free_refused']} of {second['mark_free']} refused.", "",
        "## Which radius the mark spacing follows", "",
        "Marks are cut by the grouser tips, but their spacing follows the rim radius r "
        "(`2 pi r (1 - s) / n`), not the tip radius r + h:", "",
        "| grouser height mm | slip | measured spacing mm | rim r mm | tip r + h mm | "
        "slip with r | slip with r + h |",
        "|---:|---:|---:|---:|---:|---:|---:|"]
    lines += [f"| {1000 * r['grouser_height_m']:.1f} | {r['slip']:.2f} | "
              f"{1000 * r['measured_m']:.2f} | {1000 * r['rim_m']:.2f} | "
              f"{1000 * r['tip_m']:.2f} | {r['slip_with_rim']:.4f} | "
              f"{r['slip_with_tip']:.4f} |" for r in numbers["radius"]]
    lines += ["", "## Speed", "",
              f"Second renderer's photos, OpenCV on one thread: "
              f"{second['median_seconds_one_thread']:.2f} s per photo (median); a fixed "
              f"workload (ten 1024 x 1024 FFTs, one thread) took {second['baseline_seconds']:.3f}"
              f" s in the same run: a photo costs {second['photo_over_baseline']:.1f} times it "
              "(compare machines by this ratio)."]
    return "\n".join(lines) + "\n"
