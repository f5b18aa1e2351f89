"""The page's figures, one function each, drawn with matplotlib on plain ``Figure`` objects
(no pyplot state). Every axis is labelled with its unit; loads and multipasses look the same
in every figure (:class:`campaign_report.style.Palette`)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.container import ErrorbarContainer
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from campaign_report.data import SetKey
from campaign_report.style import (CURVE_QUANTITIES, LOAD_COLOURS, PER_LOAD_OF, QUANTITIES,
                                   Palette, plain_text)
from fitting import CurveFit, ValidationResult, band, curves_by_load, interpolate_load
from sim_gap.vocabulary import SLIP_BAND_EDGES, slip_band_labels
from wpm_export import WheelPerformanceModule

CURVE_POINTS = 200
MARKER_PT = 5.0  # marker size of the curves' points
NORMAL_K = 1.96  # coverage factor of a 95 % interval without a budget


def expanded_uncertainty(rows: pd.DataFrame, key: str) -> pd.Series | None:
    """Each point's 95 % expanded uncertainty ``k sigma``: sigma the fits' (``<q>_se`` of the
    fitting table: the larger of the run's combined standard uncertainty and its replicate
    spread), k the coverage factor of the run's budget (``<q>_k``; 1.96 without one)."""
    if f"{key}_se" not in rows:
        return None
    k = rows[f"{key}_k"].astype(float).fillna(NORMAL_K) if f"{key}_k" in rows else NORMAL_K
    return rows[f"{key}_se"].astype(float) * k


def _errorbars(ax, rows: pd.DataFrame, key: str, colour: str, marker: str,
               fitted: bool) -> None:
    q = QUANTITIES[key]
    u = expanded_uncertainty(rows, key)
    ax.errorbar(rows["slip"] * 100.0, rows[key] * q.scale,
                yerr=None if u is None else u * q.scale, fmt=marker, ms=MARKER_PT,
                color=colour, mfc=colour if fitted else "white", capsize=2.5, lw=1, zorder=3)


def hidden_errorbars(fig: Figure, keys) -> str | None:
    """After ``fig`` is drawn: the error bars (:func:`_errorbars`) no longer than the marker
    radius, per panel (``keys``: each panel's quantity) with the largest of them in the
    display unit, as one sentence; None when every bar can be seen."""
    radius_px = MARKER_PT * fig.dpi / 72.0 / 2.0 + 1.0  # + a pixel of anti-aliasing
    parts = []
    for ax, key in zip(fig.axes, keys):
        hidden, total = [], 0
        for container in ax.containers:
            if not isinstance(container, ErrorbarContainer) or not container.has_yerr:
                continue
            for collection in container.lines[2]:  # (data line, caps, bar collections)
                for segment in collection.get_segments():
                    total += 1
                    y0_px, y1_px = ax.transData.transform(segment)[:, 1]
                    if abs(y1_px - y0_px) / 2.0 <= radius_px:
                        hidden.append(abs(segment[1][1] - segment[0][1]) / 2.0)
        if hidden:
            q = QUANTITIES[key]
            parts.append(f"U({q.label}) ≤ {max(hidden):.2g} {q.unit}"
                         + ("" if len(hidden) == total else
                            f" ({len(hidden)} of {total} points)"))
    if not parts:
        return None
    return ("Error bars smaller than the markers: " + ", ".join(parts) + " (U: 95 % expanded "
            "uncertainty of the mean, k·σ with σ the larger of the run's combined standard "
            "uncertainty and its replicate spread).")


def _curve(ax, curve, quantity: str, colour: str, ls: str = "-", lw: float = 1.6,
           alpha: float = 1.0) -> None:
    """A polynomial over its own slip range, slip in %, the value in the display unit."""
    slip = np.linspace(curve.slip_min, curve.slip_max, CURVE_POINTS)
    ax.plot(slip * 100.0, curve.evaluate(slip) * QUANTITIES[quantity].scale, color=colour,
            ls=ls, lw=lw, alpha=alpha)


def _bands(ax, curve, quantity: str, colour: str) -> bool:
    """A curve's 95 % confidence band (darker) and prediction band (lighter) shaded over its
    slip range (``fitting.band``, docs/fitting.md "Bands"); False, nothing drawn, where the
    curve carries no uncertainty."""
    slip = np.linspace(curve.slip_min, curve.slip_max, CURVE_POINTS)
    mean, conf, pred = band(curve, slip)
    if not np.isfinite(pred).any():
        return False
    scale = QUANTITIES[quantity].scale
    for half, alpha in ((pred, 0.08), (conf, 0.22)):
        ax.fill_between(slip * 100.0, (mean - half) * scale, (mean + half) * scale,
                        color=colour, alpha=alpha, lw=0, zorder=1)
    return True


def band_text(curves, keys) -> str:
    """The largest 95 % half-widths of the curves' bands per quantity of ``keys``, in words
    (the bands can be narrower than a curve's line); or that the curves carry none."""
    parts = []
    for key in keys:
        widths = [np.nanmax(np.stack(band(c, np.linspace(c.slip_min, c.slip_max,
                                                          CURVE_POINTS))[1:]), axis=1)
                  for c in curves if c.quantity == key and c.covariance is not None]
        if widths:
            q = QUANTITIES[key]
            conf, pred = np.nanmax(widths, axis=0) * q.scale
            parts.append(f"{q.label} ± {conf:.2g} / ± {pred:.2g} {q.unit}")
    if not parts:
        return ("These curves carry no uncertainty (stored without their parameter "
                "covariance): no bands drawn.")
    return ("95 % bands (fitting.band: confidence, where the true curve lies / prediction, "
            "where one new run's mean lies), their largest half-widths: " + ", ".join(parts)
            + ".")


def band_handles() -> list[Patch]:
    """Legend entries of the two bands (:func:`_bands`)."""
    return [Patch(color="0.3", alpha=0.22 + 0.08, label="95 % confidence band"),
            Patch(color="0.3", alpha=0.08, label="95 % prediction band")]


def _slip_axes(fig: Figure, keys) -> list:
    axes = fig.subplots(2, (len(keys) + 1) // 2, squeeze=False).ravel()
    for ax, key in zip(axes, keys):
        ax.set_xlabel(QUANTITIES["slip"].axis_label)
        ax.set_ylabel(QUANTITIES[key].axis_label)
        ax.set_title(QUANTITIES[key].label.capitalize(), fontsize="medium")
        ax.grid(alpha=0.3)
    return list(axes)


def performance_curves(points: pd.DataFrame, fits: list[CurveFit], wheel: str, soil: str,
                       statuses, palette: Palette) -> Figure:
    """DP, torque, sinkage and resistance against slip for one wheel on one soil: every
    load and multipass, means with their 95 % expanded uncertainty as error bars
    (:func:`expanded_uncertainty`; hollow: runs whose status is not in ``statuses``, i.e. not
    fitted) and the fitted polynomials with their 95 % confidence and prediction bands."""
    fig = Figure(figsize=(11.0, 8.2), layout="constrained")
    axes = _slip_axes(fig, CURVE_QUANTITIES)
    mine = points[(points["wheel"] == wheel) & (points["soil"] == soil)]
    banded = False
    for ax, key in zip(axes, CURVE_QUANTITIES):
        for (mp, load), rows in mine.groupby(["multipass", "load_n"]):
            rows = rows[np.isfinite(rows[key].astype(float))]
            for fitted, part in rows.groupby(rows["status"].isin(list(statuses))):
                _errorbars(ax, part, key, palette.colour(load), palette.marker(mp), fitted)
        for f in fits:
            if (f.wheel, f.soil, f.quantity) == (wheel, soil, key):
                _curve(ax, f, key, palette.colour(f.load_n), palette.line(f.multipass))
                banded |= _bands(ax, f, key, palette.colour(f.load_n))
    handles = palette.legend_handles(mine["load_n"], mine["multipass"])
    if banded:
        handles += band_handles()
    if not mine["status"].isin(list(statuses)).all():
        handles.append(Line2D([], [], ls="", marker="o", color="0.3", mfc="white",
                              label="flagged, not fitted"))
    fig.legend(handles=handles, loc="outside right upper", title="load, soil pass")
    fig.suptitle(f"{plain_text(wheel)} on {plain_text(soil)}: means ± U95, fitted "
                 "polynomials with their 95 % bands",
                 fontsize="medium")
    return fig


def load_validation(points: pd.DataFrame, fits: list[CurveFit], key: SetKey, load_n: float,
                    checks: list[ValidationResult], palette: Palette) -> Figure:
    """The curves at the tested loads interpolated to ``load_n`` (thick, with its bands)
    against the runs at ``load_n`` kept aside (points ± 95 % expanded uncertainty), one panel
    per quantity, the RMSE as % of the measured range in each title."""
    fig = Figure(figsize=(11.0, 8.2), layout="constrained")
    axes = _slip_axes(fig, CURVE_QUANTITIES)
    by_quantity = {c.quantity: c for c in checks}
    sets = curves_by_load(f for f in fits if (f.wheel, f.soil, f.multipass) == key)
    rows = points[(points["wheel"] == key[0]) & (points["soil"] == key[1])
                  & (points["multipass"] == key[2]) & np.isclose(points["load_n"], load_n)]
    colour, mp = palette.colour(load_n), key[2]
    banded = False
    for ax, q in zip(axes, CURVE_QUANTITIES):
        tested = sets.get((*key, q), {})
        for load, curve in sorted(tested.items()):
            _curve(ax, curve, q, palette.colour(load), palette.line(mp), lw=1.0)
        if len(tested) >= 2:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                interpolated = interpolate_load(tested, load_n)
            _curve(ax, interpolated, q, colour, palette.line(mp), lw=3.0, alpha=0.85)
            banded |= _bands(ax, interpolated, q, colour)
        ok = rows[np.isfinite(rows[q].astype(float))]
        _errorbars(ax, ok, q, colour, palette.marker(mp), fitted=True)
        check = by_quantity.get(q)
        if check is not None:
            unit = QUANTITIES[q]
            ax.set_title(f"{unit.label.capitalize()}: RMSE {check.rmse * unit.scale:.3g} "
                         f"{unit.unit} = {check.rmse_pct_of_range:.2g} % of range",
                         fontsize="medium")
    handles = palette.legend_handles([*sets.get((*key, "dp_n"), {}), load_n], [mp])
    fig.legend(handles=handles + (band_handles() if banded else []),
               loc="outside right upper", title="load")
    fig.suptitle(f"{plain_text(key[0])} on {plain_text(key[1])}, multipass {mp}: curves "
                 "interpolated to "
                 f"{load_n:g} N against the {load_n:g} N runs (not used in the fits)",
                 fontsize="medium")
    return fig


def wpm_curves(wpm: WheelPerformanceModule, tested: dict[str, list[float]], soil: str,
               wheel: str, multipass: int, palette: Palette) -> Figure:
    """Every quantity of one WPM curve set as exported, evaluated by the WPM runtime: the
    curves at the tested loads (``tested``: quantity -> loads) and, thin grey, at loads
    between them."""
    selection = {"soil": soil, "wheel": wheel, "multipass": multipass}
    quantities = [q for q in wpm.quantities(**selection) if q in tested]
    fig = Figure(figsize=(12.0, 7.6), layout="constrained")
    axes = _slip_axes(fig, quantities)
    for ax, q in zip(axes, quantities):
        loads = sorted(tested[q])
        for load in (np.array(loads[1:]) + np.array(loads[:-1])) / 2.0:
            _curve(ax, wpm.curve(q, float(load), **selection), q, "0.6", ":", lw=1.0)
        for load in loads:
            _curve(ax, wpm.curve(q, load, **selection), q, palette.colour(load),
                   palette.line(multipass), lw=1.8)
    for ax in axes[len(quantities):]:
        ax.set_axis_off()
    handles = palette.legend_handles([x for q in quantities for x in tested[q]], [multipass])
    handles.append(Line2D([], [], color="0.6", ls=":", label="between (WPM runtime)"))
    fig.legend(handles=handles, loc="outside right upper", title="load")
    fig.suptitle(f"WPM curves as exported: {plain_text(wheel)} on {plain_text(soil)}, "
                 f"multipass {multipass}",
                 fontsize="medium")
    return fig


def slip_band_text(label: str) -> str:
    """A residual-map slip band (``sim_gap.vocabulary`` label, slip as a fraction) in %."""
    i = slip_band_labels().index(label)
    return f"{SLIP_BAND_EDGES[i] * 100:g} to {SLIP_BAND_EDGES[i + 1] * 100:g}"


def condition_text(region: Mapping[str, Any], varying: set[str]) -> str:
    """A region's conditions in words, only the factors that vary in the campaign."""
    parts = [f"{region['load_n']:g} N"]
    if "multipass" in varying:
        parts.append(f"multipass {region['multipass']}")
    if "gravity_mps2" in varying:
        parts.append(f"{region['gravity_mps2']:.3g} m/s²")
    return ", ".join(parts)


def varying_factors(regions: Sequence[Mapping[str, Any]]) -> set[str]:
    return {k for k in ("multipass", "gravity_mps2") if len({r[k] for r in regions}) > 1}


def gap_heatmap(regions: Sequence[Mapping[str, Any]], tag: str = "") -> Figure:
    """The residual map of a gap report (``sim_gap.regions.residual_map``): one panel per
    quantity, rows = load (and multipass, gravity where they vary), columns = slip bands,
    colour = mean residual (measured − simulated) in % of the load (torque: of load × wheel
    radius; sinkage: of the radius), ``*`` = significant; ``tag="_soil_recalibrated"`` for
    the map after soil-only recalibration."""
    frame = pd.DataFrame(regions)
    quantities = list(dict.fromkeys(frame["quantity"]))
    bands = [b for b in slip_band_labels() if b in set(frame["slip_band"])]
    varying = varying_factors(regions)
    frame = frame.sort_values(["gravity_mps2", "multipass", "load_n"])
    frame["row"] = [condition_text(r, varying) for r in frame.to_dict("records")]
    rows = list(dict.fromkeys(frame["row"]))
    fig = Figure(figsize=(3.1 * len(quantities) + 1.4, 0.32 * len(rows) + 2.3),
                 layout="constrained")
    axes = fig.subplots(1, len(quantities), squeeze=False)[0]
    for ax, q in zip(axes, quantities):
        grid = np.full((len(rows), len(bands)), np.nan)
        star = np.zeros(grid.shape, bool)
        for r in frame[frame["quantity"] == q].to_dict("records"):
            i, j = rows.index(r["row"]), bands.index(r["slip_band"])
            grid[i, j] = 100.0 * r[f"mean_residual_per_load{tag}"]
            star[i, j] = r[f"significant{tag}"]
        finite = np.abs(grid[np.isfinite(grid)])
        lim = float(finite.max()) if finite.size and finite.max() > 0 else 1.0
        image = ax.imshow(grid, cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto")
        for i, j in zip(*np.nonzero(star)):
            ax.text(j, i, "*", ha="center", va="center", fontsize=12,
                    color="white" if abs(grid[i, j]) > 0.6 * lim else "black")
        ax.set_xticks(range(len(bands)), [slip_band_text(b) for b in bands], rotation=40,
                      ha="right", fontsize=8)
        ax.set_yticks(range(len(rows)), rows if ax is axes[0] else [""] * len(rows),
                      fontsize=8)
        ax.set_xlabel("slip band [%]", fontsize=9)
        ax.set_title(QUANTITIES[q].label.capitalize(), fontsize=10)
        bar = fig.colorbar(image, ax=ax, shrink=0.9)
        bar.set_label(f"measured − simulated [% of {PER_LOAD_OF[q]}]", fontsize=8)
        bar.ax.tick_params(labelsize=7)
    axes[0].set_ylabel(", ".join(["load"] + [{"multipass": "multipass",
                                              "gravity_mps2": "gravity"}[k]
                                             for k in sorted(varying, reverse=True)]),
                       fontsize=9)
    fig.suptitle(("After soil recalibration" if tag else "Simulation as given")
                 + ": mean residual per region (* significant, Benjamini-Hochberg 5 %; "
                   "W load, r wheel radius)", fontsize=9)
    return fig


def gap_probabilities(sets: list[tuple[str, float]], call_probability: float) -> Figure:
    """The posterior probability of each effect set (``sets``: its name in words and its
    probability, laws summed), one horizontal bar each, most probable on top, the value at
    the bar's end and the probability a verdict needs (``call_probability``) as a line."""
    fig = Figure(figsize=(8.0, 0.38 * len(sets) + 1.3), layout="constrained")
    ax = fig.subplots()
    names, values = [s[0] for s in sets], [s[1] for s in sets]
    rows = np.arange(len(sets))
    ax.barh(rows, values, color=LOAD_COLOURS[0], height=0.6)
    for y, p in zip(rows, values):
        ax.text(min(p, 1.0) + 0.01, y, probability_text(p), va="center", fontsize=8)
    ax.axvline(call_probability, color="#D55E00", ls="--", lw=1.2)
    ax.text(call_probability, 1.01, f"a verdict needs {call_probability:g}", ha="center",
            va="bottom", fontsize=8, color="#D55E00", transform=ax.get_xaxis_transform())
    ax.set_yticks(rows, [plain_text(n) for n in names], fontsize=9)
    ax.set_ylim(len(sets) - 0.5, -0.5)
    ax.set_xlim(0.0, 1.12)
    ax.set_xticks(np.linspace(0.0, 1.0, 6))
    ax.set_xlabel("posterior probability (laws of each effect summed)")
    ax.grid(axis="x", alpha=0.3)
    return fig


def probability_text(p: float) -> str:
    """A probability to three decimals, cut rather than rounded (0.8995 reads 0.899: a
    probability below the call is never shown at it); below 0.001, ``< 0.001``."""
    return f"{math.floor(p * 1000.0 + 1e-9) / 1000.0:.3f}" if p >= 0.001 else "< 0.001"


#: the gap page's prediction lines: the simulation as given, after soil recalibration,
#: after the chosen hypothesis (``<name>: (line style, width)``; any other name: the last)
PREDICTION_LINES = {"simulation": (":", 1.2), "soil_only": ("--", 1.2), None: ("-", 1.8)}


def gap_curves(groups: list[tuple[str, list[Mapping[str, Any]]]], quantities: list[str],
               lines: dict[str, str], palette: Palette, offsets: dict | None = None) -> Figure:
    """Measured against simulated, one row per group (``(title, points)``: a source at one
    multipass and gravity level, its points as the gap report's ``points``) and one column
    per quantity: the measured values against slip per load (error bars ± σ, the noise the
    diagnosis used) and each prediction of ``lines`` (key in the points -> its legend text)
    through the measured slips, one colour per load. ``offsets``: prediction key ->
    quantity -> a constant removed from that prediction (a relative sinkage, measured from
    an unknown zero)."""
    offsets = offsets or {}
    fig = Figure(figsize=(3.3 * len(quantities) + 0.4, 3.0 * len(groups) + 0.9),
                 layout="constrained")
    axes = fig.subplots(len(groups), len(quantities), squeeze=False)
    loads = sorted({p["load_n"] for _, points in groups for p in points})
    for row, (title, points) in zip(axes, groups):
        for ax, q in zip(row, quantities):
            scale = QUANTITIES[q].scale
            ax.set_title(f"{plain_text(title)}: {QUANTITIES[q].label}" if title
                         else QUANTITIES[q].label.capitalize(), fontsize=9)
            ax.set_xlabel(QUANTITIES["slip"].axis_label, fontsize=8)
            ax.set_ylabel(QUANTITIES[q].axis_label, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
            for load in loads:
                mine = sorted((p for p in points if p["load_n"] == load and q in p),
                              key=lambda p: p["slip"])
                if mine:
                    _measured_and_predicted(ax, mine, q, lines, palette.colour(load),
                                            {k: v.get(q, 0.0) * scale
                                             for k, v in offsets.items()})
            if not ax.has_data():
                ax.text(0.5, 0.5, "not measured", ha="center", va="center",
                        transform=ax.transAxes, color="0.4")
    handles = palette.legend_handles(loads, [0])
    handles.append(Line2D([], [], ls="", marker="o", color="0.2", label="measured ± σ"))
    handles += [Line2D([], [], color="0.2", ls=_style(k)[0], lw=_style(k)[1], label=text)
                for k, text in lines.items()]
    fig.legend(handles=handles, loc="outside lower center", ncols=min(len(handles), 4),
               fontsize=8)
    return fig


def _style(key: str) -> tuple[str, float]:
    return PREDICTION_LINES.get(key, PREDICTION_LINES[None])


def _measured_and_predicted(ax, points: list[dict], q: str, lines, colour: str,
                            shifts: dict[str, float]) -> None:
    """One load's measured values ± σ and its predictions (display units, slip in %)."""
    scale = QUANTITIES[q].scale
    slip = np.array([p["slip"] for p in points]) * 100.0
    ax.errorbar(slip, [p[q]["measured"] * scale for p in points],
                yerr=[p[q]["sigma"] * scale for p in points], fmt="o", ms=MARKER_PT - 1,
                color=colour, capsize=2.0, lw=1, zorder=3)
    for key in lines:
        ls, lw = _style(key)
        ax.plot(slip, [p[q][key] * scale - shifts.get(key, 0.0) for p in points],
                color=colour, ls=ls, lw=lw, marker="_" if len(points) == 1 else None)
