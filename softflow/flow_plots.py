"""Plots of a SOFT result: velocity magnitude over the frame, profiles with fits, rates per beta.

Each function returns a matplotlib figure; :func:`write_plots` writes them as PNGs.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from softflow.flow_result import FlowResult
from swtlab_base.atomic import atomic_file


def magnitude_map(result: FlowResult, frame: np.ndarray):
    """World-frame soil speed (mm/s) over the first frame, with the wheel outline and axle."""
    v = result.mean.velocity_px_per_s / result.px_per_m + np.array(result.sled_velocity_mps)
    speed_mmps = 1000 * np.hypot(v[..., 0], v[..., 1])
    fig, ax = plt.subplots(figsize=(7, 6))
    ax.imshow(frame, cmap="gray")
    im = ax.imshow(np.ma.masked_invalid(speed_mmps), cmap="viridis", alpha=0.75)
    p = result.poses[0]
    for radius in (p.radius_px, p.radius_px + p.grouser_height_px):
        ax.add_patch(plt.Circle(p.center_px, radius, fill=False, color="w", lw=0.8))
    ax.plot(*p.center_px, "w+")
    step = max(frame.shape) // 32
    y, x = np.mgrid[step // 2:frame.shape[0]:step, step // 2:frame.shape[1]:step]
    vmax = np.nanmax(np.hypot(v[y, x, 0], v[y, x, 1]))
    ax.quiver(x, y, v[y, x, 0], v[y, x, 1], color="w", angles="xy", scale_units="xy",
              scale=vmax / step, width=0.002)  # image y down: arrows drawn as seen
    fig.colorbar(im, ax=ax, label="soil speed in the bin frame (mm/s)")
    ax.set_title("soil velocity (bin frame), frames %d:%d" % result.frame_range)
    return fig


def profiles_with_fits(result: FlowResult, every: int = 3):
    """v_r and v_theta against the distance from the rim per beta bin, with their fits."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharex=True)
    rim = result.poses[0].radius_px
    colours = plt.cm.twilight(np.linspace(0, 1, len(result.beta_rad)))
    for name, ax, profs, fits in (("v_r", axes[0], result.profiles_r, result.radial),
                                  ("v_theta", axes[1], result.profiles_t, result.tangential)):
        for i in range(0, len(result.beta_rad), every):
            r, v, _ = profs[i]
            if len(r) == 0:
                continue
            rho_mm = 1000 * (r - rim) / result.px_per_m
            ax.plot(rho_mm, 1000 * v, ".", ms=3, color=colours[i])
            if fits[i]:
                f = fits[i]
                ax.plot(rho_mm, 1000 * f.amplitude * np.exp(-f.rate_per_m * rho_mm / 1000), "-",
                        color=colours[i], label=f"{np.rad2deg(result.beta_rad[i]):.0f} deg")
        ax.set_xlabel("distance from the rim (mm)")
        ax.set_ylabel(f"{name} (mm/s)")
    axes[1].legend(fontsize=6, ncol=2)
    fig.tight_layout()
    return fig


def rates_by_beta(result: FlowResult):
    """k(beta) and alpha3(beta) with their 95 % confidence intervals."""
    fig, ax = plt.subplots(figsize=(8, 4))
    beta_deg = np.rad2deg(result.beta_rad)
    for name, fits, marker in (("k (radial)", result.radial, "o"),
                               ("alpha3 (tangential)", result.tangential, "s")):
        ok = [i for i, f in enumerate(fits) if f]
        rate = np.array([fits[i].rate_per_m for i in ok])
        lo = np.array([fits[i].ci95_per_m[0] for i in ok])
        hi = np.array([fits[i].ci95_per_m[1] for i in ok])
        ax.errorbar(beta_deg[ok], rate, yerr=[rate - lo, hi - rate], fmt=marker, ms=4,
                    capsize=2, label=name)
    ax.set_xlabel("beta (deg, 0 at the image right, counter-clockwise)")
    ax.set_ylabel("decay rate (1/m)")
    ax.legend()
    fig.tight_layout()
    return fig


def write_plots(result: FlowResult, frame: np.ndarray, folder: str | Path) -> list[Path]:
    """``flow_magnitude.png``, ``flow_profiles.png``, ``flow_rates.png`` in ``folder``."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name, fig in (("flow_magnitude.png", magnitude_map(result, frame)),
                      ("flow_profiles.png", profiles_with_fits(result)),
                      ("flow_rates.png", rates_by_beta(result))):
        with atomic_file(folder / name, "wb") as stream:
            fig.savefig(stream, format="png", dpi=110)
        plt.close(fig)
        out.append(folder / name)
    return out
