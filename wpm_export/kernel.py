"""The WPM runtime's queries, compiled (numba): one curve set and quantity packed into one
float64 array (:func:`pack`), answered per query in a few hundred floating-point operations,
with no array built per query on the scalar path.

A query at load ``W`` takes the curve parameters ``(a_0 ... a_n, J, K)`` from the exact
piecewise polynomial of load of :class:`fitting.load_interp.LoadPolynomial` (PCHIP pieces
cubic in ``W - W_k``, or linear, docs/wpm-csv.md "Loads between the tested ones"), and the
covariance from :meth:`~fitting.load_interp.LoadPolynomial.covariance_pieces` (sextic in
``t``); then:

- the value (Horner, plus ``J + K s`` below zero slip) and the 95 % half-widths
  ``k95 sqrt(g^T C g)``, ``k95 sqrt(g^T C g + scatter_sd**2)`` (:func:`fitting.band`);
- the inverse (docs/wpm-csv.md "The inverse"): each side of zero slip cut at the curve's
  turning points into monotone pieces (the real roots of the derivative in the range,
  isolated by the roots of the next derivative, recursively down to a linear one, each by
  safeguarded Newton: Press et al. 2007, Numerical Recipes 3rd ed., sec. 9.4, ``rtsafe``);
  the first piece in slip order whose values span the target holds the smallest slip, found
  by safeguarded Newton to 1e-14 (relative, as :mod:`wpm_export.inverse` states); the jump
  at zero slip is a piece of its own (``at_step`` strictly inside it).

Status codes: 0 ok, 1 above_max, 2 below_min, 3 at_step, plus :data:`EXTRAPOLATED` for a load
outside the tested ones (allowed); negative codes are errors (the caller words them).
"""

from __future__ import annotations

import math

import numba
import numpy as np

OK, ABOVE, BELOW, STEP = 0, 1, 2, 3
STATUS = ("ok", "above_max", "below_min", "at_step")
EXTRAPOLATED = 4
BAD_LOAD, OUTSIDE, ONE_LOAD, BAD_TARGET, BAD_SLIP = -1, -2, -3, -4, -5
MAX_ITERATIONS = 60  # safeguarded Newton: a few steps; bisection alone needs ~40
STEP_TOLERANCE = 1e-14
MAX_DEGREE = 7
ROW = MAX_DEGREE + 3  # longest parameter vector (a_0 ... a_7, J, K)
# scratch of one query: parameters, braked polynomial, roots (2 rows), derivatives (ROW rows),
# slips and values of the cuts (at most 2 (n + 1) of them)
BRAKED, ROOTS, DERIVATIVES = ROW, 2 * ROW, 4 * ROW
XS = DERIVATIVES + ROW * ROW
FS = XS + 2 * ROW
WORK = FS + 2 * ROW

# header slots of a packed table
DEGREE, LOADS, PCHIP, SLIP_MIN, SLIP_MAX, KNOWN, TESTED, AT, PIECES, SPREAD, ENDS, INSIDE = \
    range(12)
HEADER = 12


def pack(polynomial) -> np.ndarray:
    """One float64 array holding what queries of one (curve set, quantity) read: header,
    tested loads, parameters at them, PCHIP pieces, (scatter_sd, k95) at them and, where
    every tested curve carries one, the covariance pieces."""
    tested, at = polynomial.tested, polynomial.at_tested
    pieces = polynomial.pieces
    covariance = polynomial.covariance_pieces()
    parts = [tested, at, pieces if pieces is not None else np.zeros(0),
             polynomial.spread_at_tested()]
    if covariance is not None:
        parts += [covariance[1], covariance[0]]
    header = np.zeros(HEADER)
    header[:6] = (polynomial.degree, tested.size, pieces is not None, polynomial.slip_min,
                  polynomial.slip_max, covariance is not None)
    offset = HEADER
    for slot, part in zip((TESTED, AT, PIECES, SPREAD, ENDS, INSIDE), parts):
        header[slot] = offset
        offset += part.size
    return np.concatenate([header] + [np.ravel(p) for p in parts])


@numba.njit(cache=True, nogil=True)
def _locate(table, load, allow):
    """(interval k, t, load - tested[k], inside, code) of a load."""
    n_loads, x = int(table[LOADS]), int(table[TESTED])
    if not (load > 0.0 and load < math.inf):
        return 0, 0.0, 0.0, False, BAD_LOAD
    inside = table[x] <= load <= table[x + n_loads - 1]
    code = 0
    if not inside:
        if n_loads < 2:
            return 0, 0.0, 0.0, False, ONE_LOAD
        if not allow:
            return 0, 0.0, 0.0, False, OUTSIDE
        code = EXTRAPOLATED
    if n_loads == 1:
        return 0, 0.0, 0.0, True, code
    hi = 0  # numpy.searchsorted(tested, load), then clipped to 1 ... L-1
    while hi < n_loads and table[x + hi] < load:
        hi += 1
    k = min(max(hi, 1), n_loads - 1) - 1
    left = table[x + k]
    return k, (load - left) / (table[x + k + 1] - left), load - left, inside, code


@numba.njit(cache=True, nogil=True)
def _parameters(table, k, t, dx, inside, out):
    """``(a_0 ... a_n, J, K)`` at the located load into ``out[:n + 3]``
    (:meth:`LoadPolynomial.parameters`, the same operations)."""
    n_loads, p = int(table[LOADS]), int(table[DEGREE]) + 3
    at = int(table[AT])
    if n_loads == 1:
        for j in range(p):
            out[j] = table[at + j]
    elif table[PCHIP] > 0.0 and inside:
        c, stride = int(table[PIECES]) + k * p, (n_loads - 1) * p
        for j in range(p):
            out[j] = (((table[c + j] * dx + table[c + stride + j]) * dx
                       + table[c + 2 * stride + j]) * dx + table[c + 3 * stride + j])
    else:
        a = at + k * p
        for j in range(p):
            out[j] = (1.0 - t) * table[a + j] + t * table[a + p + j]


@numba.njit(cache=True, nogil=True)
def _horner(c, start, degree, x):
    y = c[start + degree]
    for i in range(degree - 1, -1, -1):
        y = y * x + c[start + i]
    return y


@numba.njit(cache=True, nogil=True)
def _value(theta, n, s):
    """The curve at slip ``s``: polynomial, plus ``J + K s`` below zero slip."""
    y = _horner(theta, 0, n, s)
    if s < 0.0:
        y += theta[n + 1] + theta[n + 2] * s
    return y


@numba.njit(cache=True, nogil=True)
def _slope(theta, n, s):
    """``dy/ds`` at ``s`` (the braked side adds K)."""
    d = n * theta[n]
    for i in range(n - 1, 0, -1):
        d = d * s + i * theta[i]
    if s < 0.0:
        d += theta[n + 2]
    return d


@numba.njit(cache=True, nogil=True)
def _root(c, start, degree, level, a, b, fa, fb):
    """Slip in [a, b] where ``sum c_i x**i - level`` (coefficients from ``c[start]``) crosses
    zero (values ``fa``, ``fb`` at the ends, of opposite sign or one zero): safeguarded
    Newton from the secant point, bisection where a step would leave the bracket."""
    if fa == 0.0:
        return a
    if fb == 0.0:
        return b
    secant = a - fa * (b - a) / (fb - fa)
    x = secant if a < secant < b else 0.5 * (a + b)
    for _ in range(MAX_ITERATIONS):
        f, d = c[start + degree], 0.0
        for i in range(degree - 1, -1, -1):
            d = d * x + f
            f = f * x + c[start + i]
        f -= level
        if f == 0.0:
            return x
        if (f < 0.0) == (fa < 0.0):
            a, fa = x, f
        else:
            b = x
        newton = x - f / d if d != 0.0 else a - 1.0
        following = newton if a < newton < b else 0.5 * (a + b)
        step = following - x
        x = following
        if abs(step) <= STEP_TOLERANCE * (1.0 + abs(x - step)):
            break
    return x


@numba.njit(cache=True, nogil=True)
def _turning_points(c, start, n, u, v, w, out):
    """Slips in (u, v) where the derivative of the degree-``n`` polynomial at ``c[start]``
    changes sign, increasing, into ``w[out:]``; returns how many. The k-th derivative is
    monotone between sign changes of the (k+1)-th: each level's roots bracket the next (the
    quadratic level in closed form)."""
    if n < 2:
        return 0
    d = DERIVATIVES  # row k: the k-th derivative
    for i in range(n + 1):
        w[d + i] = c[start + i]
    for k in range(1, n):
        for i in range(n - k + 1):
            w[d + k * ROW + i] = (i + 1) * w[d + (k - 1) * ROW + i + 1]
    roots, spare = out, out + ROW
    if n == 2:  # the derivative is linear
        c0, c1 = w[d + ROW], w[d + ROW + 1]
        if c1 != 0.0 and u < -c0 / c1 < v:
            w[roots] = -c0 / c1
            return 1
        return 0
    count = _quadratic_roots(w, d + (n - 2) * ROW, u, v, roots)
    for k in range(n - 3, 0, -1):
        row, found = d + k * ROW, 0
        x0, f0 = u, _horner(w, row, n - k, u)
        for j in range(count + 1):
            x1 = w[roots + j] if j < count else v
            f1 = _horner(w, row, n - k, x1)
            if (f0 < 0.0 and f1 > 0.0) or (f0 > 0.0 and f1 < 0.0):
                w[spare + found] = _root(w, row, n - k, 0.0, x0, x1, f0, f1)
                found += 1
            x0, f0 = x1, f1
        for j in range(found):
            w[roots + j] = w[spare + j]
        count = found
    return count


@numba.njit(cache=True, nogil=True)
def _quadratic_roots(w, c, u, v, out):
    """Simple real roots in (u, v) of ``w[c] + w[c+1] x + w[c+2] x**2``, increasing, into
    ``w[out:]`` (the cancellation-free form: Press et al. 2007, sec. 5.6); returns how
    many."""
    c0, c1, c2 = w[c], w[c + 1], w[c + 2]
    count = 0
    if c2 == 0.0:
        if c1 != 0.0 and u < -c0 / c1 < v:
            w[out], count = -c0 / c1, 1
        return count
    disc = c1 * c1 - 4.0 * c2 * c0
    if not disc > 0.0:
        return 0
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
    r0, r1 = q / c2, c0 / q
    for r in (min(r0, r1), max(r0, r1)):
        if u < r < v:
            w[out + count] = r
            count += 1
    return count


@numba.njit(cache=True, nogil=True)
def _cuts(theta, n, lo, hi, w):
    """Cut the curve into monotone pieces: slips and values of the cuts in slip order at
    ``w[XS:]``, ``w[FS:]``; the braked polynomial at ``w[BRAKED:]``. Returns (number of
    cuts, index of the cut that ends the braked side, -1 without two sides)."""
    for i in range(n + 1):
        w[BRAKED + i] = theta[i]
    w[BRAKED] += theta[n + 1]
    w[BRAKED + 1] += theta[n + 2]
    roots, xs, fs = ROOTS, XS, FS
    two = lo < 0.0 <= hi and (theta[n + 1] != 0.0 or theta[n + 2] != 0.0)
    m, jump = 0, -1
    for side in range(2 if two else 1):
        braked = (side == 0 and two) or (not two and hi < 0.0)
        start = BRAKED if braked else 0
        u = lo if side == 0 else 0.0
        v = 0.0 if two and side == 0 else hi
        count = _turning_points(w, start, n, u, v, w, roots)
        for j in range(count + 2):
            x = u if j == 0 else (v if j == count + 1 else w[roots + j - 1])
            w[xs + m], w[fs + m] = x, _horner(w, start, n, x)
            m += 1
        if two and side == 0:
            jump = m - 1
    return m, jump


@numba.njit(cache=True, nogil=True)
def _find(target, n, lo, m, jump, w):
    """(slip, value, status) of a target on the cut curve (:func:`_cuts`)."""
    xs, fs = XS, FS
    top, bottom = w[fs], w[fs]
    for i in range(1, m):
        top, bottom = max(top, w[fs + i]), min(bottom, w[fs + i])
    if target > top:
        return 1.0, top, ABOVE
    if target < bottom:
        return math.nan, bottom, BELOW
    if target == w[fs]:
        return lo, target, OK
    for i in range(m - 1):
        f0, f1 = w[fs + i], w[fs + i + 1]
        if min(f0, f1) <= target <= max(f0, f1):
            if i == jump:
                return 0.0, target, STEP if min(f0, f1) < target < max(f0, f1) else OK
            start = BRAKED if (jump >= 0 and i < jump) or (jump < 0 and w[xs + m - 1] < 0.0) \
                else 0
            return _root(w, start, n, target, w[xs + i], w[xs + i + 1], f0 - target,
                         f1 - target), target, OK
    return math.nan, target, BELOW  # not reached: the pieces span [bottom, top]


@numba.njit(cache=True, nogil=True)
def _variance(table, k, t, inside, s):
    """``g(s)^T C g(s)`` at the located load (:meth:`LoadPolynomial.covariance_pieces`)."""
    n, n_loads = int(table[DEGREE]), int(table[LOADS])
    p = n + 3
    g = np.empty(p)
    g[0] = 1.0
    for i in range(1, n + 1):
        g[i] = g[i - 1] * s
    g[n + 1], g[n + 2] = (1.0, s) if s < 0.0 else (0.0, 0.0)
    ends = int(table[ENDS])
    if n_loads == 1:
        return _quadratic(table, ends, g, p)
    if not inside:
        return ((1.0 - t) ** 2 * _quadratic(table, ends + k * p * p, g, p)
                + t * t * _quadratic(table, ends + (k + 1) * p * p, g, p))
    base = int(table[INSIDE]) + k * 7 * p * p
    var = _quadratic(table, base + 6 * p * p, g, p)
    for r in range(5, -1, -1):
        var = var * t + _quadratic(table, base + r * p * p, g, p)
    return var


@numba.njit(cache=True, nogil=True)
def _quadratic(table, start, g, p):
    out = 0.0
    for i in range(p):
        row = 0.0
        for j in range(p):
            row += table[start + i * p + j] * g[j]
        out += g[i] * row
    return out


@numba.njit(cache=True, nogil=True)
def _spread(table, k, t):
    """``(scatter_sd, k95)`` at the located load: linear across load, at least 0."""
    s = int(table[SPREAD])
    if int(table[LOADS]) == 1:
        return max(table[s], 0.0), max(table[s + 1], 0.0)
    a = s + 2 * k
    return (max((1.0 - t) * table[a] + t * table[a + 2], 0.0),
            max((1.0 - t) * table[a + 1] + t * table[a + 3], 0.0))


@numba.njit(cache=True, nogil=True)
def _bands(table, k, t, inside, s):
    """95 % half-widths (confidence, prediction) at slip ``s``; NaN when unknown."""
    if table[KNOWN] == 0.0:
        return math.nan, math.nan
    var = max(_variance(table, k, t, inside, s), 0.0)
    scatter, k95 = _spread(table, k, t)
    return k95 * math.sqrt(var), k95 * math.sqrt(var + scatter * scatter)


@numba.njit(cache=True, nogil=True)
def _slip_bands(table, k, t, inside, theta, s):
    """The bands carried to slip: half-widths over ``|dy/ds|`` at ``s`` (inf where the slope
    is 0, NaN where the bands are unknown or 0 there, NaN for a NaN slip)."""
    if s != s:
        return math.nan, math.nan
    conf, pred = _bands(table, k, t, inside, s)
    slope = abs(_slope(theta, int(table[DEGREE]), s))
    if slope == 0.0:
        return (math.inf if conf > 0.0 else math.nan), (math.inf if pred > 0.0 else math.nan)
    return conf / slope, pred / slope


_TABLE = "float64[::1]"
_ARRAY = "float64[::1]"


@numba.njit(f"Tuple((float64, float64, int64))({_TABLE}, float64, float64, boolean)",
            cache=True, nogil=True)
def solve_one(table, target, load, allow):
    """(slip, value, code) of one target at one load."""
    if not (target - target == 0.0):
        return math.nan, math.nan, BAD_TARGET
    k, t, dx, inside, code = _locate(table, load, allow)
    if code < 0:
        return math.nan, math.nan, code
    n = int(table[DEGREE])
    w = np.empty(WORK)
    _parameters(table, k, t, dx, inside, w)
    m, jump = _cuts(w, n, table[SLIP_MIN], table[SLIP_MAX], w)
    slip, value, status = _find(target, n, table[SLIP_MIN], m, jump, w)
    return slip, value, status + code


@numba.njit(f"Tuple((float64, float64, float64, int64))({_TABLE}, float64, float64, boolean)",
            cache=True, nogil=True)
def value_one(table, slip, load, allow):
    """(value, conf_half95, pred_half95, code) at one slip and load."""
    if not (slip - slip == 0.0):
        return math.nan, math.nan, math.nan, BAD_SLIP
    k, t, dx, inside, code = _locate(table, load, allow)
    if code < 0:
        return math.nan, math.nan, math.nan, code
    w = np.empty(ROW)
    _parameters(table, k, t, dx, inside, w)
    conf, pred = _bands(table, k, t, inside, slip)
    return _value(w, int(table[DEGREE]), slip), conf, pred, code


def _machine_code(kernel):
    """The compiled function of a kernel of one explicit signature, called without the
    dispatcher (which types every argument to pick the overload: a sixth of a scalar query).
    Its arguments must be of the signature's types: a packed table, then numbers (unboxed
    as ``float(x)``, ``bool(x)``)."""
    (compiled,) = kernel.overloads.values()
    return compiled.entry_point


#: :func:`solve_one`, :func:`value_one` without the dispatcher (the runtime's scalar queries)
solve_number, value_number = _machine_code(solve_one), _machine_code(value_one)


@numba.njit(f"Tuple((float64, float64, int64))({_TABLE}, float64, float64, boolean)",
            cache=True, nogil=True)
def slip_band_one(table, slip, load, allow):
    """(conf, pred, code) of the slip found at ``slip`` (:func:`_slip_bands`)."""
    k, t, dx, inside, code = _locate(table, load, allow)
    if code < 0:
        return math.nan, math.nan, code
    w = np.empty(ROW)
    _parameters(table, k, t, dx, inside, w)
    conf, pred = _slip_bands(table, k, t, inside, w, slip)
    return conf, pred, code


@numba.njit(f"UniTuple(int64, 3)({_TABLE}, {_ARRAY}, {_ARRAY}, boolean, {_ARRAY}, {_ARRAY}, "
            "int8[::1])", cache=True, nogil=True)
def solve_many(table, targets, loads, allow, slip, value, status):
    """:func:`solve_one` over arrays; returns (first error code or 0, its index, number of
    extrapolated loads). The cuts are reused while the load repeats."""
    n, lo, hi = int(table[DEGREE]), table[SLIP_MIN], table[SLIP_MAX]
    w = np.empty(WORK)
    last, m, jump, extrapolated = math.nan, 0, -1, 0
    k, t, dx, inside, code = 0, 0.0, 0.0, True, 0
    for i in range(targets.size):
        target, load = targets[i], loads[i]
        if not (target - target == 0.0):
            return BAD_TARGET, i, extrapolated
        if load != last:
            k, t, dx, inside, code = _locate(table, load, allow)
            if code < 0:
                return code, i, extrapolated
            _parameters(table, k, t, dx, inside, w)
            m, jump = _cuts(w, n, lo, hi, w)
            last = load
        slip[i], value[i], status[i] = _find(target, n, lo, m, jump, w)
        if code == EXTRAPOLATED:
            extrapolated += 1
    return 0, 0, extrapolated


VALUES, BANDS, SLIP_BANDS = 0, 1, 2  # what values_many gives


@numba.njit(f"UniTuple(int64, 3)({_TABLE}, {_ARRAY}, {_ARRAY}, boolean, {_ARRAY}, {_ARRAY}, "
            f"{_ARRAY}, int64)", cache=True, nogil=True)
def values_many(table, slips, loads, allow, value, conf, pred, mode):
    """Over arrays: the values (``mode`` VALUES), with the half-widths (BANDS), or the
    half-widths carried to slip (SLIP_BANDS, NaN slips give NaN); returns as
    :func:`solve_many`."""
    n = int(table[DEGREE])
    w = np.empty(ROW)
    last, extrapolated = math.nan, 0
    k, t, dx, inside, code = 0, 0.0, 0.0, True, 0
    for i in range(slips.size):
        s, load = slips[i], loads[i]
        if not (s - s == 0.0) and mode != SLIP_BANDS:
            return BAD_SLIP, i, extrapolated
        if load != last:
            k, t, dx, inside, code = _locate(table, load, allow)
            if code < 0:
                return code, i, extrapolated
            _parameters(table, k, t, dx, inside, w)
            last = load
        value[i] = _value(w, n, s)
        if mode == BANDS:
            conf[i], pred[i] = _bands(table, k, t, inside, s)
        elif mode == SLIP_BANDS:
            conf[i], pred[i] = _slip_bands(table, k, t, inside, w, s)
        if code == EXTRAPOLATED:
            extrapolated += 1
    return 0, 0, extrapolated


@numba.njit(f"void(float64[:, ::1], float64[:, ::1], int64[::1], {_ARRAY}, float64, float64, "
            f"{_ARRAY}, {_ARRAY}, int8[::1])", cache=True, nogil=True)
def solve_rows(coefficients, below_zero, row, targets, lo, hi, slip, value, status):
    """The inverse of curves given as rows of power coefficients and (J, K): target ``i`` on
    row ``row[i]`` (:func:`wpm_export.inverse.solve_slip`)."""
    n = coefficients.shape[1] - 1
    w = np.empty(WORK)
    last, m, jump = -1, 0, -1
    for i in range(targets.size):
        r = row[i]
        if r != last:
            for j in range(n + 1):
                w[j] = coefficients[r, j]
            w[n + 1], w[n + 2] = below_zero[r, 0], below_zero[r, 1]
            m, jump = _cuts(w, n, lo, hi, w)
            last = r
        slip[i], value[i], status[i] = _find(targets[i], n, lo, m, jump, w)

