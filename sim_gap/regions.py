"""Where the gap lies: residuals of each quantity over slip band x load x multipass x
gravity, normalised by load and by uncertainty; a chi-square test per region with
Benjamini-Hochberg control of the false discovery rate (Benjamini & Hochberg 1995, JRSS B
57:289-300); a heatmap."""

from __future__ import annotations

import io

import numpy as np
import pandas as pd
from scipy.stats import chi2

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
                    f"p{tag}": float(chi2.sf(np.sum(z ** 2), max(ok.sum(), 1)))})
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


def heatmap_png(regions: list[dict], tag: str = "") -> bytes:
    """PNG: one panel per quantity, rows = (load, multipass, gravity), columns = slip bands,
    colour = mean residual over load, '*' = significant."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    frame = pd.DataFrame(regions)
    quantities = list(dict.fromkeys(frame["quantity"]))
    bands = [b for b in slip_band_labels() if b in set(frame["slip_band"])]
    frame["row"] = frame.apply(lambda r: f"{r.load_n:g} N, mp{r.multipass}, "
                                         f"g={r.gravity_mps2:g}", axis=1)
    rows = list(dict.fromkeys(frame.sort_values(["gravity_mps2", "multipass", "load_n"])["row"]))
    fig, axes = plt.subplots(1, len(quantities), figsize=(3.2 * len(quantities) + 1,
                                                         0.45 * len(rows) + 1.8), squeeze=False)
    for ax, q in zip(axes[0], quantities):
        sub = frame[frame["quantity"] == q]
        grid = np.full((len(rows), len(bands)), np.nan)
        star = np.zeros_like(grid, bool)
        for _, r in sub.iterrows():
            i, j = rows.index(r["row"]), bands.index(r["slip_band"])
            grid[i, j] = r[f"mean_residual_per_load{tag}"]
            star[i, j] = r[f"significant{tag}"]
        lim = np.nanmax(np.abs(grid)) or 1.0
        im = ax.imshow(grid, cmap="RdBu_r", vmin=-lim, vmax=lim, aspect="auto")
        for i, j in zip(*np.nonzero(star)):
            ax.text(j, i, "*", ha="center", va="center", fontsize=12)
        ax.set_xticks(range(len(bands)), bands, rotation=45, fontsize=7)
        ax.set_yticks(range(len(rows)), rows if ax is axes[0][0] else [""] * len(rows),
                      fontsize=7)
        ax.set_title(f"{q} (measured - sim) / load", fontsize=8)
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return buf.getvalue()
