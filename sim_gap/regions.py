"""Where the gap lies: residuals of each quantity over slip band x load x multipass x
gravity, normalised by load and by uncertainty; a chi-square test per region with
Benjamini-Hochberg control of the false discovery rate (Benjamini & Hochberg 1995, JRSS B
57:289-300). Its heatmap is drawn by ``campaign_report.figures.gap_heatmap``."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.special import chdtrc

from sim_gap.fit import quantities_of, sigmas
from sim_gap.vocabulary import slip_band, slip_band_labels

FDR = 0.05


def benjamini_hochberg(p: np.ndarray, q: float = FDR) -> np.ndarray:
    """True where a p-value is a discovery at false discovery rate ``q``."""
    p = np.asarray(p, dtype=float)
    order = np.argsort(p)
    ranked = p[order] * len(p) / np.arange(1, len(p) + 1)
    passed = np.zeros(len(p), bool)
    below = np.flatnonzero(ranked <= q)
    if below.size:
        passed[order[: below.max() + 1]] = True
    return passed


def _residuals(points: pd.DataFrame, pred: dict[str, np.ndarray], q: str) -> np.ndarray:
    r = points[q].to_numpy(float) - pred[q]
    if q == "sinkage_m" and points.attrs.get("sinkage_relative"):
        r = r - np.nanmean(r)
    return r


def _normaliser(q: str, load: np.ndarray, radius_m: float) -> np.ndarray:
    """Load normalisation: forces by W, torque by W r, sinkage by r."""
    return {"torque_nm": load * radius_m, "sinkage_m": np.full_like(load, radius_m)}.get(q, load)


def residual_map(points: pd.DataFrame, as_given: dict[str, np.ndarray],
                 soil_recalibrated: dict[str, np.ndarray], radius_m: float) -> list[dict]:
    """One entry per region and quantity: mean residual (measured - simulated, SI and over
    load), its z and chi-square p-value with the uncertainty ``SE (+) repeatability floor``,
    significance after BH, for the simulation as given and after soil-only recalibration.
    ``radius_m``: the wheel's radius (normalises torque and sinkage)."""
    sig = sigmas(points, radius_m)
    keys = pd.DataFrame({"slip_band": np.array(slip_band_labels())[
        slip_band(points["slip"].to_numpy(float))], "load_n": points["load_set_n"].round(1),
        "multipass": points["multipass"], "gravity_mps2": points["gravity_mps2"].round(3)})
    load = points["wheel_load_n"].to_numpy(float)
    rows = []
    for key, idx in keys.groupby(list(keys.columns), sort=True).indices.items():
        for q in quantities_of(points):
            entry = dict(zip(keys.columns, (str(key[0]), float(key[1]), int(key[2]),
                                            float(key[3]))), quantity=q)
            for tag, pred in (("", as_given), ("_soil_recalibrated", soil_recalibrated)):
                r = _residuals(points, pred, q)[idx]
                ok = np.isfinite(r)
                z = r[ok] / sig[q][idx][ok]
                entry.update({
                    f"n{tag}": int(ok.sum()), f"mean_residual{tag}": float(np.mean(r[ok])),
                    f"mean_residual_per_load{tag}": float(np.mean(
                        r[ok] / _normaliser(q, load[idx][ok], radius_m))),
                    f"z{tag}": float(z.sum() / np.sqrt(max(ok.sum(), 1))),
                    f"p{tag}": float(chdtrc(max(ok.sum(), 1), np.sum(z ** 2)))})
            rows.append(entry)
    for tag in ("", "_soil_recalibrated"):
        flags = benjamini_hochberg([r[f"p{tag}"] for r in rows]) if rows else []
        for r, f in zip(rows, flags):
            r[f"significant{tag}"] = bool(f)
    return rows


def largest_gap(regions: list[dict]) -> dict:
    """Where the soil-recalibrated model misses most (largest |z|): what to look at when no
    candidate explains the gap."""
    worst = max(regions, key=lambda r: abs(r["z_soil_recalibrated"]))
    return {"test": f"no candidate test separates: the gap lies outside the candidate effects; "
                    f"largest residual {worst['quantity']} in slip band {worst['slip_band']} "
                    f"(mean {worst['mean_residual_soil_recalibrated']:.4g}, "
                    f"z {worst['z_soil_recalibrated']:.1f})", "separation_sigma": None,
            "region": {k: worst[k] for k in ("slip_band", "load_n", "multipass",
                                             "gravity_mps2", "quantity")}}

