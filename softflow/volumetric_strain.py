"""Volumetric strain of the soil from the measured mean velocity field (SOFT, ``eps_vol^P``).

Plane flow behind the glass wall: the volumetric strain rate is ``-div v``
(geomechanics sign: compression positive). The camera rides with the wheel, so in
the stable phase the camera-frame field ``u = v - V`` is steady and a soil element
follows its streamline; ``div u = div v``. The strain it carries at a point is the
material time integral ``eps = -int div u dt = -int (div u / |u|) ds`` along the
streamline from undisturbed soil upstream (``eps = 0`` there): the Eulerian
("stationary") treatment of steady rolling, internal variables integrated along
streamlines (Dang Van & Maitournam 1993, "Steady-state flow in classical
elastoplasticity: applications to repeated rolling and sliding contact", JMPS 41).
With ``d ln(volume)/dt = div v`` exactly, ``eps = ln(rho_dry / rho_dry0)`` is the
logarithmic (natural) volumetric strain, equal to ``1 - V/V0`` to first order.

Derivatives of the noisy field: Gaussian-weighted local plane fit per pixel over
the valid vectors only (normalised convolution of order 1, Knutsson & Westin 1993,
"Normalized and differential convolution"), ``sigma = 5 px``: no mask leaks in,
and a linear field is exact even at the wheel-mask edge. Streamlines: midpoint (RK2)
steps of 1 px upstream on bilinearly interpolated fields, until the smoothed field
ends (8 px inside the image border, where flow windows are whole; wheel mask; holes);
the end counts as undisturbed soil only if its velocity is within 1 % of the
far-field velocity ``-V`` (1D continuity: about 0.01 of strain left out), else no
value (ending on the wheel, or on an image edge where the soil still moves). A path
that comes closer to the axle than its start also gives no value: it ran along the
rim, where the flow is least reliable (behind the wheel).

Uncertainty bound per bin (what says whether ``eps`` is resolved, without a truth):
smoothing bias + scatter + strain left upstream. The gradient of a Gaussian plane fit
is biased by ``sigma^2/2 grad(laplacian u)`` inside the field (odd moments of the
window vanish) and by about ``sigma`` times the second derivative where the window is
one-sided (mask edge); ``eps(2 sigma) - eps(sigma)`` is then 3 times or once the bias at
``sigma``, so its magnitude bounds it in both cases (Richardson's step doubling,
Richardson 1911, Phil. Trans. R. Soc. A 210). Scatter: 95 % half-width of the mean over
the bin's samples (Student t). Left upstream: where a path ends, 1D continuity
(``rho |u|`` constant) gives the strain still to come as ``|ln(|u_end| / |V|)|``.
A field measured from frames adds the flow engine's own error, the same across a bin and
so not in the scatter: ``FLOW_FIELD_ERROR`` (measured on renders, docs/softflow.md).
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.special import stdtrit

from softflow.flow_engine import BORDER_PX  # dropped at the image edge: windows cut by it

SIGMA_PX = 5.0  # derivative scale: smallest eps error on renders (docs/softflow.md)
UNDISTURBED = 0.01  # |u + V| / |V| where a streamline may end
CLOSER_PX = 2.0  # a path may come this much closer to the axle than its start point
SAMPLES_PER_BIN = 5
#: eps error of a field measured from frames beyond the exact field's, worst bin on the
#: self-consistent renders (seeds 11, 12, 21; eps 0.37-0.67): 0.026 at seed 12, beta -105 deg
FLOW_FIELD_ERROR = 0.026


def local_linear_fit(field: np.ndarray, valid: np.ndarray, sigma_px: float = SIGMA_PX,
                     min_weight: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """Value (H, W, C) and gradient (H, W, C, 2) = (d/dx, d/dy) of a plane fitted per pixel.

    Weights ``exp(-d^2 / 2 sigma^2)`` over the valid pixels; NaN where they sum to
    less than ``min_weight`` of a full window.
    """
    half = int(np.ceil(3 * sigma_px))
    t = np.arange(-half, half + 1, dtype=np.float64)
    g = np.exp(-t ** 2 / (2 * sigma_px ** 2))
    kernels = (g, t * g, t * t * g)

    def moment(f: np.ndarray, px: int, py: int) -> np.ndarray:  # sum w (x'-x)^px (y'-y)^py f
        along_x = ndimage.correlate1d(f, kernels[px], axis=1, mode="constant")
        return ndimage.correlate1d(along_x, kernels[py], axis=0, mode="constant")

    m = valid.astype(np.float64)
    m00, m10, m01, m11 = moment(m, 0, 0), moment(m, 1, 0), moment(m, 0, 1), moment(m, 1, 1)
    normal = np.stack([np.stack([m00, m10, m01], -1),
                       np.stack([m10, moment(m, 2, 0), m11], -1),
                       np.stack([m01, m11, moment(m, 0, 2)], -1)], -2)
    ok = m00 > min_weight * g.sum() ** 2
    normal[~ok] = np.eye(3)
    value = np.full(field.shape, np.nan)
    gradient = np.full(field.shape + (2,), np.nan)
    for c in range(field.shape[-1]):
        f = np.where(valid, field[..., c], 0.0)
        rhs = np.stack([moment(f, 0, 0), moment(f, 1, 0), moment(f, 0, 1)], -1)
        sol = np.linalg.solve(normal, rhs[..., None])[..., 0]
        value[ok, c] = sol[ok, 0]
        gradient[ok, c] = sol[ok, 1:]
    return value, gradient


def smoothed_divergence(velocity: np.ndarray,
                        sigma_px: float = SIGMA_PX) -> tuple[np.ndarray, np.ndarray]:
    """Smoothed velocity (H, W, 2) and its divergence (per unit of velocity / px); NaN-aware."""
    valid = np.isfinite(velocity[..., 0]) & np.isfinite(velocity[..., 1])
    value, gradient = local_linear_fit(np.nan_to_num(velocity), valid, sigma_px)
    return value, gradient[..., 0, 0] + gradient[..., 1, 1]


def accumulated_strain(velocity: np.ndarray, divergence: np.ndarray, start_xy: np.ndarray,
                       far_velocity: np.ndarray, keep_out: np.ndarray | None = None,
                       step_px: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """``eps`` (compression positive) at each start point (N, 2: x, y) and the strain left
    upstream of its end, ``|ln(|u_end| / |V|)|``; NaN without an undisturbed upstream end or
    where the path enters ``keep_out`` (bool map).
    ``velocity``: steady camera frame; ``far_velocity``: ``-V``.
    """
    x, y = start_xy[:, 0].astype(np.float64), start_xy[:, 1].astype(np.float64)
    eps = np.zeros(len(x))
    end = np.full(len(x), -1)  # -1 still tracing; 0 no value; 1 undisturbed end
    calm = np.zeros(len(x), bool)  # at the last point with a velocity: undisturbed soil
    speed_end = np.full(len(x), np.nan)  # |u| there
    far = np.asarray(far_velocity, np.float64)

    def upstream(px, py):  # unit step direction (against u) and d eps / ds
        at = [py, px]
        ux = ndimage.map_coordinates(velocity[..., 0], at, order=1, cval=np.nan)
        uy = ndimage.map_coordinates(velocity[..., 1], at, order=1, cval=np.nan)
        d = ndimage.map_coordinates(divergence, at, order=1, cval=np.nan)
        speed = np.hypot(ux, uy)
        return -ux / speed, -uy / speed, -d / speed, ux, uy

    for _ in range(int(4 * sum(divergence.shape) / step_px)):
        live = end < 0
        if not live.any():
            break
        a = upstream(x[live], y[live])
        b = upstream(x[live] + step_px / 2 * a[0], y[live] + step_px / 2 * a[1])
        idx = np.flatnonzero(live)
        here = np.isfinite(a[2])
        calm[idx[here]] = (np.hypot(a[3] - far[0], a[4] - far[1])
                           <= UNDISTURBED * np.hypot(*far))[here]
        speed_end[idx[here]] = np.hypot(a[3], a[4])[here]
        stop = ~here | ~np.isfinite(b[2])
        end[idx[stop]] = calm[idx[stop]]
        if keep_out is not None:
            inside = keep_out[np.clip(np.rint(y[idx]).astype(int), 0, keep_out.shape[0] - 1),
                              np.clip(np.rint(x[idx]).astype(int), 0, keep_out.shape[1] - 1)]
            end[idx[inside]] = 0
            stop |= inside
        go = idx[~stop]
        x[go] += step_px * b[0][~stop]
        y[go] += step_px * b[1][~stop]
        eps[go] += step_px * b[2][~stop]
    done = end == 1
    left = np.abs(np.log(speed_end / np.hypot(*far)))
    return np.where(done, eps, np.nan), np.where(done, left, np.nan)


def _bin_samples(velocity_px_per_s: np.ndarray, center_px: tuple[float, float],
                 radius_px: float, beta_centres: np.ndarray, width_rad: float,
                 far_velocity_px_per_s: np.ndarray,
                 sigma_px: float) -> tuple[np.ndarray, np.ndarray]:
    """``eps`` and strain left upstream at 5 angles across each bin (bins, 5); NaN: no value."""
    u, div = smoothed_divergence(velocity_px_per_s, sigma_px)
    inner = np.zeros(div.shape, bool)
    inner[BORDER_PX:-BORDER_PX, BORDER_PX:-BORDER_PX] = True
    u[~inner], div[~inner] = np.nan, np.nan
    offsets = np.linspace(-0.4, 0.4, SAMPLES_PER_BIN) * width_rad
    beta = (beta_centres[:, None] + offsets[None, :]).ravel()
    start = np.stack([center_px[0] + radius_px * np.cos(beta),
                      center_px[1] - radius_px * np.sin(beta)], -1)
    y, x = np.mgrid[0:div.shape[0], 0:div.shape[1]]
    near = np.hypot(x - center_px[0], y - center_px[1]) < radius_px - CLOSER_PX
    eps, left = accumulated_strain(u, div, start, far_velocity_px_per_s, near)
    return eps.reshape(-1, len(offsets)), left.reshape(-1, len(offsets))


def strain_by_beta(velocity_px_per_s: np.ndarray, center_px: tuple[float, float],
                   radius_px: float, beta_centres: np.ndarray, width_rad: float,
                   far_velocity_px_per_s: np.ndarray,
                   sigma_px: float = SIGMA_PX) -> tuple[np.ndarray, np.ndarray]:
    """``eps`` per beta bin at ``radius_px`` from the axle and its uncertainty bound
    (smoothing bias + scatter + strain left upstream, module docstring). ``eps``: mean over
    5 angles across the bin, NaN where fewer than 3 have an undisturbed upstream end; the
    bound is NaN where ``eps`` is, or where the ``2 sigma`` pass has no value. Paths that
    come closer to the wheel than their start (behind the wheel: soil that slid along the
    rim, where the flow is least reliable) give no value.

    ``velocity_px_per_s``: mean camera-frame field (H, W, 2), NaN where masked.
    """
    args = (velocity_px_per_s, center_px, radius_px, beta_centres, width_rad,
            far_velocity_px_per_s)
    samples, left = _bin_samples(*args, sigma_px)
    coarse = _bin_mean(_bin_samples(*args, 2 * sigma_px)[0])
    eps = _bin_mean(samples)
    count = np.isfinite(samples).sum(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        scatter = (stdtrit(np.maximum(count - 1, 1), 0.975)
                   * np.nanstd(np.where(count[:, None] >= 3, samples, 0.0), axis=1, ddof=1)
                   / np.sqrt(np.maximum(count, 1)))
        bound = np.abs(coarse - eps) + scatter + np.nanmean(
            np.where(count[:, None] >= 3, left, 0.0), axis=1)
    return eps, np.where(np.isfinite(eps), bound, np.nan)


def _bin_mean(samples: np.ndarray) -> np.ndarray:
    """Mean per row over the finite samples; NaN where fewer than 3."""
    count = np.isfinite(samples).sum(axis=1)
    return np.where(count >= 3, np.nansum(samples, axis=1) / np.maximum(count, 1), np.nan)
