/* The curve at any load and the queries of libswtwpm, the same arithmetic as swtlab's
 * Python runtime (docs/wpm-csv.md):
 *
 * - across load (fitting/load_interp.py): the tested curves on 101 Chebyshev-Lobatto slips
 *   of the slip range they share, PCHIP across load at each slip (Fritsch & Carlson 1980, as
 *   scipy.interpolate.PchipInterpolator, its arithmetic reproduced) with 3+ tested loads,
 *   else linear, the least-squares refit of the polynomial (+ braked branch) linear in those
 *   values: so the parameters are a cubic in load per interval between tested loads, whose
 *   four coefficient vectors are projected once at load time (LoadPolynomial). Outside the
 *   tested loads: linear from the two nearest, only when asked;
 * - the covariance at a load: the tested curves' propagated through the interpolation (its
 *   sensitivity by the same forward difference as Python), plus with 3+ loads the
 *   PCHIP-minus-linear interpolation error v v^T / 3; scatter_sd and k95 linear in load;
 * - the inverse: the row solver of wpm_export/inverse.py (16 cells over the slip range,
 *   turning points located in each cell, running extremes, safeguarded Newton). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "swtwpm_internal.h"

#define MAX_ITERATIONS 60
#define STEP_TOLERANCE 1e-14
#define RCOND 1e-15 /* numpy.linalg.pinv's default cut-off of small singular values */
#define P_MAX SWTWPM_MAX_PARAMETERS

/* ---- small numerics ---- */

static double horner(const double *a, int n, double s)
{
    double out = 0.0;
    int k;
    for (k = n - 1; k >= 0; --k)
        out = out * s + a[k];
    return out;
}

static double sign(double x)
{
    return isnan(x) ? x : (double)((x > 0) - (x < 0));
}

/* numpy.maximum / minimum: NaN propagates */
static double np_max(double a, double b) { return (a > b || isnan(a)) ? a : b; }
static double np_min(double a, double b) { return (a < b || isnan(a)) ? a : b; }
/* numpy.fmax / fmin: NaN ignored */
static double np_fmax(double a, double b) { return isnan(b) ? a : isnan(a) ? b : np_max(a, b); }
static double np_fmin(double a, double b) { return isnan(b) ? a : isnan(a) ? b : np_min(a, b); }

/* Root of polynomial c (n coefficients) in [a, b] (a sign change or a root at an end):
 * safeguarded Newton from the secant point, as inverse.py _root. */
static double root(const double *c, int n, double a, double b)
{
    double slope[SWTWPM_MAX_DEGREE + 1], fa, fb, secant, x;
    int i, iteration;
    for (i = 1; i < n; ++i)
        slope[i - 1] = c[i] * i;
    fa = horner(c, n, a);
    fb = horner(c, n, b);
    secant = a - fa * (b - a) / (fb - fa);
    x = fa == 0 ? a : fb == 0 ? b : (secant > a && secant < b) ? secant : 0.5 * (a + b);
    if (fa == 0 || fb == 0)
        return x;
    for (iteration = 0; iteration < MAX_ITERATIONS; ++iteration) {
        double fx = horner(c, n, x), dfx = horner(slope, n - 1, x), newton, step, xl = x;
        if (sign(fx) == sign(fa)) {
            a = x;
            fa = fx;
        } else
            b = x;
        newton = x - fx / dfx;
        step = fx == 0 ? 0.0 : ((newton > a && newton < b) ? newton : 0.5 * (a + b)) - x;
        x = xl + step;
        if (!(fabs(step) > STEP_TOLERANCE * (1.0 + fabs(xl))))
            break;
    }
    return x;
}

/* ---- PCHIP across load at one slip (scipy's arithmetic) ---- */

static double edge_slope(double h0, double h1, double m0, double m1)
{
    double d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    int mask = sign(d) != sign(m0);
    int mask2 = (sign(m0) != sign(m1)) && (fabs(d) > 3. * fabs(m0));
    if (mask)
        return 0.;
    if (mask2)
        return 3. * m0;
    return d;
}

/* derivative at x[j] of PchipInterpolator(x, y) (L >= 2 points) */
static double pchip_slope(const double *x, const double *y, int L, int j)
{
    double h0, h1, m0, m1;
    if (L == 2)
        return (y[1] - y[0]) / (x[1] - x[0]);
    if (j == 0)
        return edge_slope(x[1] - x[0], x[2] - x[1], (y[1] - y[0]) / (x[1] - x[0]),
                          (y[2] - y[1]) / (x[2] - x[1]));
    if (j == L - 1)
        return edge_slope(x[L - 1] - x[L - 2], x[L - 2] - x[L - 3],
                          (y[L - 1] - y[L - 2]) / (x[L - 1] - x[L - 2]),
                          (y[L - 2] - y[L - 3]) / (x[L - 2] - x[L - 3]));
    h0 = x[j] - x[j - 1];
    h1 = x[j + 1] - x[j];
    m0 = (y[j] - y[j - 1]) / h0;
    m1 = (y[j + 1] - y[j]) / h1;
    if (sign(m1) != sign(m0) || m1 == 0 || m0 == 0)
        return 0.0;
    {
        double w1 = 2 * h1 + h0, w2 = h1 + 2 * h0;
        return 1.0 / ((w1 / m0 + w2 / m1) / (w1 + w2));
    }
}

/* the four coefficients (of (w - x[i])^3 ... ^0) of interval i (CubicHermiteSpline) */
static void pchip_piece(const double *x, const double *y, int L, int i, double c[4])
{
    double dx = x[i + 1] - x[i], slope = (y[i + 1] - y[i]) / dx;
    double d0 = pchip_slope(x, y, L, i), d1 = pchip_slope(x, y, L, i + 1);
    double t = (d0 + d1 - 2 * slope) / dx;
    c[0] = t / dx;
    c[1] = (slope - d0) / dx - t;
    c[2] = d0;
    c[3] = y[i];
}

/* the PPoly interval of w inside [x[0], x[L-1]] */
static int pchip_interval(const double *x, int L, double w)
{
    int i = 0;
    if (w >= x[L - 1])
        return L - 2;
    while (i < L - 2 && w >= x[i + 1])
        ++i;
    return i;
}

static double pchip_at(const double *x, const double *y, int L, double w)
{
    double c[4], s, z, out;
    int i = pchip_interval(x, L, w);
    pchip_piece(x, y, L, i, c);
    s = w - x[i];
    out = 0.0 + c[3];
    z = s;
    out = out + c[2] * z;
    z *= s;
    out = out + c[1] * z;
    z *= s;
    out = out + c[0] * z;
    return out;
}

/* _across_load of one slip's values y over the tested loads x, at w */
static double across_load(const double *x, const double *y, int L, double w, int pchip,
                          int outside)
{
    int hi;
    double t;
    if (L == 1)
        return y[0];
    if (pchip && !outside)
        return pchip_at(x, y, L, w);
    for (hi = 0; hi < L && x[hi] < w; ++hi) /* searchsorted, side left */
        ;
    hi = hi < 1 ? 1 : hi > L - 1 ? L - 1 : hi;
    t = (w - x[hi - 1]) / (x[hi] - x[hi - 1]);
    return (1.0 - t) * y[hi - 1] + t * y[hi];
}

/* ---- least squares: pseudo-inverse by one-sided Jacobi SVD ---- */

/* projection (m x n, m >= n) with solution = values @ projection: pinv(design).T */
static int pinv_transpose(const double *design, int m, int n, double *projection)
{
    double *u = malloc((size_t)m * n * sizeof *u), v[P_MAX][P_MAX], s[P_MAX], smax = 0;
    int i, j, k, sweep;
    if (!u)
        return SWTWPM_E_MEMORY;
    memcpy(u, design, (size_t)m * n * sizeof *u);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j)
            v[i][j] = i == j;
    for (sweep = 0; sweep < 80; ++sweep) {
        int rotated = 0;
        for (i = 0; i < n - 1; ++i)
            for (j = i + 1; j < n; ++j) {
                double alpha = 0, beta = 0, gamma = 0, zeta, t, c, sn;
                for (k = 0; k < m; ++k) {
                    alpha += u[k * n + i] * u[k * n + i];
                    beta += u[k * n + j] * u[k * n + j];
                    gamma += u[k * n + i] * u[k * n + j];
                }
                if (!(fabs(gamma) > 1e-15 * sqrt(alpha * beta)))
                    continue;
                rotated = 1;
                zeta = (beta - alpha) / (2 * gamma);
                t = (zeta >= 0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1 + zeta * zeta));
                c = 1 / sqrt(1 + t * t);
                sn = c * t;
                for (k = 0; k < m; ++k) {
                    double a = u[k * n + i], b = u[k * n + j];
                    u[k * n + i] = c * a - sn * b;
                    u[k * n + j] = sn * a + c * b;
                }
                for (k = 0; k < n; ++k) {
                    double a = v[k][i], b = v[k][j];
                    v[k][i] = c * a - sn * b;
                    v[k][j] = sn * a + c * b;
                }
            }
        if (!rotated)
            break;
    }
    for (j = 0; j < n; ++j) {
        double norm = 0;
        for (k = 0; k < m; ++k)
            norm += u[k * n + j] * u[k * n + j];
        s[j] = sqrt(norm);
        smax = s[j] > smax ? s[j] : smax;
    }
    for (k = 0; k < m; ++k)
        for (i = 0; i < n; ++i) {
            double sum = 0;
            for (j = 0; j < n; ++j)
                if (s[j] > RCOND * smax) /* u_j / s_j / s_j: u normalised, then 1/s */
                    sum += u[k * n + j] / (s[j] * s[j]) * v[i][j];
            projection[k * n + i] = sum;
        }
    free(u);
    return 0;
}

/* power_matrix: Chebyshev coefficients on the scaled interval -> power coefficients of
 * slip (long double, rounded once) */
static void power_matrix(double lo, double hi, int degree, double m[8][8])
{
    long double beta = 2.0L / ((long double)hi - lo), alpha = -((long double)hi + lo)
                                                             / ((long double)hi - lo);
    long double x_powers[8][8], acc[8][8], t_prev[8], t[8], t_next[8];
    int i, j, k;
    memset(acc, 0, sizeof acc);
    for (j = 0; j <= degree; ++j)
        for (i = 0; i <= j; ++i) {
            long double binomial = 1;
            int b;
            for (b = 1; b <= i; ++b)
                binomial = binomial * (j - i + b) / b;
            x_powers[j][i] = binomial * powl(alpha, j - i) * powl(beta, i);
        }
    for (k = 0; k <= degree; ++k) { /* T_k(x) = sum_j t[j] x^j */
        long double *coefficients = k == 0 ? t_prev : t;
        if (k == 0) {
            memset(t_prev, 0, sizeof t_prev);
            t_prev[0] = 1;
        } else if (k == 1) {
            memset(t, 0, sizeof t);
            t[1] = 1;
        } else {
            memset(t_next, 0, sizeof t_next);
            for (j = 0; j < 7; ++j)
                t_next[j + 1] = 2 * t[j];
            for (j = 0; j < 8; ++j)
                t_next[j] -= t_prev[j];
            memcpy(t_prev, t, sizeof t);
            memcpy(t, t_next, sizeof t);
        }
        for (j = 0; j <= k; ++j)
            if (coefficients[j] != 0)
                for (i = 0; i <= j; ++i)
                    acc[i][k] += coefficients[j] * x_powers[j][i];
    }
    for (i = 0; i <= degree; ++i)
        for (k = 0; k <= degree; ++k)
            m[i][k] = (double)acc[i][k];
}

/* ---- building a quantity's interpolation ---- */

static int branch_terms(const wpm_row *row)
{
    return row->slope != 0 ? 2 : row->step != 0 ? 1 : 0;
}

/* numpy.linspace(lo, hi, n + 1) into out */
static void linspace(double lo, double hi, int n, double *out)
{
    double delta = hi - lo, step = delta / n;
    int i;
    for (i = 0; i <= n; ++i)
        out[i] = (step == 0 ? (i / (double)n) * delta : i * step) + lo;
    out[n] = hi;
}

/* the cells of the row solver: one side over [lo, hi], or two split at zero slip */
static int build_cells(wpm_quantity *q, int two_sides, wpm_cells *cells)
{
    double width = q->hi - q->lo, bounds[2][2];
    int counts[2], side, g, i, n = q->degree + 1, at = 0;
    cells->n_sides = two_sides ? 2 : 1;
    if (two_sides) {
        bounds[0][0] = q->lo, bounds[0][1] = 0.0, bounds[1][0] = 0.0, bounds[1][1] = q->hi;
    } else
        bounds[0][0] = q->lo, bounds[0][1] = q->hi;
    cells->points = 0;
    for (side = 0; side < cells->n_sides; ++side) {
        double cells_here = nearbyint(CELLS * (bounds[side][1] - bounds[side][0]) / width);
        counts[side] = cells_here > 4 ? (int)cells_here : 4;
        cells->points += counts[side] + 1;
    }
    cells->count0 = counts[0];
    cells->grid = malloc((size_t)cells->points * sizeof *cells->grid);
    cells->power = malloc((size_t)cells->points * n * sizeof *cells->power);
    cells->slope_power = malloc((size_t)cells->points * n * sizeof *cells->slope_power);
    if (!cells->grid || !cells->power || !cells->slope_power)
        return SWTWPM_E_MEMORY;
    for (side = 0; side < cells->n_sides; ++side) {
        linspace(bounds[side][0], bounds[side][1], counts[side], cells->grid + at);
        at += counts[side] + 1;
    }
    for (g = 0; g < cells->points; ++g)
        for (i = 0; i < n; ++i) {
            cells->power[i * cells->points + g] = pow(cells->grid[g], i);
            cells->slope_power[i * cells->points + g] = i > 0 ? i * pow(cells->grid[g], i - 1)
                                                              : 0.0;
        }
    return 0;
}

static double curve_value(const wpm_row *row, double s)
{
    double y = horner(row->a, row->degree + 1, s);
    if (row->step != 0 || row->slope != 0)
        y = y + (s < 0 ? row->step + row->slope * s : 0.0);
    return y;
}

static int compare_loads(const void *a, const void *b)
{
    double x = (*(const wpm_row *const *)a)->load_n, y = (*(const wpm_row *const *)b)->load_n;
    return (x > y) - (x < y);
}

static int build_quantity(wpm_quantity *q)
{
    int L = q->n_loads, k, g, i, j, n_solution, result;
    double *design, *projection, T[P_MAX][P_MAX], power[8][8], span, vmin, vmax, vabs;
    char text[40];
    qsort((void *)q->tested, (size_t)L, sizeof *q->tested, compare_loads);
    q->loads = malloc((size_t)L * sizeof *q->loads);
    if (!q->loads)
        return SWTWPM_E_MEMORY;
    q->lo = -INFINITY;
    q->hi = INFINITY;
    q->degree = 0;
    q->branch = 0;
    q->has_uncertainty = 1;
    for (k = 0; k < L; ++k) {
        const wpm_row *row = q->tested[k];
        q->loads[k] = row->load_n;
        q->lo = row->slip_min > q->lo ? row->slip_min : q->lo;
        q->hi = row->slip_max < q->hi ? row->slip_max : q->hi;
        q->degree = row->degree > q->degree ? row->degree : q->degree;
        q->branch = branch_terms(row) > q->branch ? branch_terms(row) : q->branch;
        q->has_uncertainty &= row->has_uncertainty;
    }
    if (q->lo >= q->hi) { /* fitting.load_interp: a query error, not a file error */
        size_t length = 0, capacity = 64 + 42 * (size_t)L;
        q->error = malloc(capacity);
        if (!q->error)
            return SWTWPM_E_MEMORY;
        length += (size_t)snprintf(q->error, capacity, "the tested loads [");
        for (k = 0; k < L; ++k) {
            wpm_repr(q->loads[k], text);
            length += (size_t)snprintf(q->error + length, capacity - length, "%s%s",
                                       k ? ", " : "", text);
        }
        snprintf(q->error + length, capacity - length, "] share no slip range");
        return 0;
    }
    if (q->lo >= 0)
        q->branch = 0;
    q->pchip = L >= 3;
    q->p = q->degree + 3;
    n_solution = q->degree + 1 + q->branch;
    span = q->lo < 0 ? -q->lo : 1.0;
    for (g = 0; g < GRID_POINTS; ++g) {
        double x = -cos(3.141592653589793 * g / (GRID_POINTS - 1));
        q->grid[g] = q->lo + (x + 1.0) * 0.5 * (q->hi - q->lo);
    }
    design = malloc((size_t)GRID_POINTS * n_solution * sizeof *design);
    projection = malloc((size_t)GRID_POINTS * n_solution * sizeof *projection);
    q->to_theta = calloc((size_t)GRID_POINTS * q->p, sizeof *q->to_theta);
    q->values = malloc((size_t)L * GRID_POINTS * sizeof *q->values);
    q->at_tested = calloc((size_t)L * q->p, sizeof *q->at_tested);
    q->pieces = calloc((size_t)4 * (L > 1 ? L - 1 : 1) * q->p, sizeof *q->pieces);
    if (!design || !projection || !q->to_theta || !q->values || !q->at_tested || !q->pieces) {
        free(design);
        free(projection);
        return SWTWPM_E_MEMORY;
    }
    for (g = 0; g < GRID_POINTS; ++g) { /* branch_design: Chebyshev-Vandermonde + branch */
        double s = q->grid[g], x = (2.0 * s - (q->lo + q->hi)) / (q->hi - q->lo);
        double *row = design + g * n_solution, below = s < 0;
        row[0] = 1.0;
        row[1] = x;
        for (i = 2; i <= q->degree; ++i)
            row[i] = row[i - 1] * (2 * x) - row[i - 2];
        if (q->branch >= 1)
            row[q->degree + 1] = below;
        if (q->branch >= 2)
            row[q->degree + 2] = below * s / span;
    }
    result = pinv_transpose(design, GRID_POINTS, n_solution, projection);
    free(design);
    if (result) {
        free(projection);
        return result;
    }
    memset(T, 0, sizeof T); /* solution -> (a_0 ... a_n, J, K) */
    power_matrix(q->lo, q->hi, q->degree, power);
    for (i = 0; i <= q->degree; ++i)
        for (j = 0; j <= q->degree; ++j)
            T[i][j] = power[j][i];
    if (q->branch >= 1)
        T[q->degree + 1][q->degree + 1] = 1.0;
    if (q->branch >= 2)
        T[q->degree + 2][q->degree + 2] = 1.0 / span;
    for (g = 0; g < GRID_POINTS; ++g)
        for (j = 0; j < q->p; ++j) {
            double sum = 0;
            for (i = 0; i < n_solution; ++i)
                sum += projection[g * n_solution + i] * T[i][j];
            q->to_theta[g * q->p + j] = sum;
        }
    free(projection);
    vmin = INFINITY, vmax = -INFINITY, vabs = 0;
    for (k = 0; k < L; ++k)
        for (g = 0; g < GRID_POINTS; ++g) {
            double v = curve_value(q->tested[k], q->grid[g]);
            q->values[k * GRID_POINTS + g] = v;
            vmin = v < vmin ? v : vmin;
            vmax = v > vmax ? v : vmax;
            vabs = fabs(v) > vabs ? fabs(v) : vabs;
            for (j = 0; j < q->p; ++j)
                q->at_tested[k * q->p + j] += v * q->to_theta[g * q->p + j];
        }
    q->delta = vmax - vmin;
    q->delta = 1e-6 * (vabs > q->delta ? (vabs > 1e-300 ? vabs : 1e-300)
                                       : (q->delta > 1e-300 ? q->delta : 1e-300));
    if (q->pchip) {
        double *y = malloc((size_t)L * sizeof *y);
        if (!y)
            return SWTWPM_E_MEMORY;
        for (g = 0; g < GRID_POINTS; ++g) {
            for (k = 0; k < L; ++k)
                y[k] = q->values[k * GRID_POINTS + g];
            for (k = 0; k < L - 1; ++k) {
                double c[4];
                int m;
                pchip_piece(q->loads, y, L, k, c);
                for (m = 0; m < 4; ++m)
                    for (j = 0; j < q->p; ++j)
                        q->pieces[(m * (L - 1) + k) * q->p + j] += c[m] * q->to_theta[g * q->p + j];
            }
        }
        free(y);
    }
    result = build_cells(q, 0, &q->cells[0]);
    if (!result && q->lo < 0 && 0 <= q->hi)
        result = build_cells(q, 1, &q->cells[1]);
    return result;
}

static void free_quantity(wpm_quantity *q)
{
    int c;
    if (!q)
        return;
    free(q->error);
    free((void *)q->tested);
    free(q->loads);
    free(q->to_theta);
    free(q->values);
    free(q->at_tested);
    free(q->pieces);
    for (c = 0; c < 2; ++c) {
        free(q->cells[c].grid);
        free(q->cells[c].power);
        free(q->cells[c].slope_power);
    }
    free(q);
}

static int compare_sets(const wpm_row *a, const wpm_row *b)
{
    int c = strcmp(a->soil, b->soil);
    if (!c)
        c = strcmp(a->wheel, b->wheel);
    if (!c)
        c = (a->multipass > b->multipass) - (a->multipass < b->multipass);
    return c;
}

static int compare_row_pointers(const void *a, const void *b)
{
    return compare_sets(*(const wpm_row *const *)a, *(const wpm_row *const *)b);
}

int wpm_build_sets(swtwpm *model, char *msg, size_t msg_size)
{
    const wpm_row **order = malloc((size_t)model->n_rows * sizeof *order);
    int r, result = 0;
    (void)msg;
    (void)msg_size;
    if (!order)
        return SWTWPM_E_MEMORY;
    for (r = 0; r < model->n_rows; ++r)
        order[r] = &model->rows[r];
    qsort((void *)order, (size_t)model->n_rows, sizeof *order, compare_row_pointers);
    model->sets = calloc((size_t)model->n_rows, sizeof *model->sets);
    if (!model->sets) {
        free((void *)order);
        return SWTWPM_E_MEMORY;
    }
    for (r = 0; r < model->n_rows && !result; ++r) {
        const wpm_row *row = order[r];
        wpm_set *set;
        wpm_quantity *q;
        if (!r || compare_sets(order[r - 1], row)) {
            set = &model->sets[model->n_sets++];
            set->soil = row->soil;
            set->wheel = row->wheel;
            set->multipass = row->multipass;
        }
        set = &model->sets[model->n_sets - 1];
        q = set->quantity[row->quantity];
        if (!q) {
            q = set->quantity[row->quantity] = calloc(1, sizeof *q);
            if (!q || !(q->tested = calloc((size_t)model->n_rows, sizeof *q->tested))) {
                result = SWTWPM_E_MEMORY;
                break;
            }
        }
        q->tested[q->n_loads++] = row;
    }
    free((void *)order);
    for (r = 0; r < model->n_sets && !result; ++r) {
        int k;
        for (k = 0; k < SWTWPM_N_QUANTITIES && !result; ++k)
            if (model->sets[r].quantity[k])
                result = build_quantity(model->sets[r].quantity[k]);
    }
    return result;
}

void wpm_free_sets(swtwpm *model)
{
    int s, k;
    for (s = 0; model->sets && s < model->n_sets; ++s)
        for (k = 0; k < SWTWPM_N_QUANTITIES; ++k)
            free_quantity(model->sets[s].quantity[k]);
    free(model->sets);
    model->sets = NULL;
}

/* ---- sets ---- */

int swtwpm_set_count(const swtwpm *model)
{
    return model ? model->n_sets : SWTWPM_E_ARGUMENT;
}

int swtwpm_set_info(const swtwpm *model, int set, const char **soil, const char **wheel,
                    long long *multipass)
{
    if (!model || set < 0 || set >= model->n_sets)
        return SWTWPM_E_ARGUMENT;
    if (soil)
        *soil = model->sets[set].soil;
    if (wheel)
        *wheel = model->sets[set].wheel;
    if (multipass)
        *multipass = model->sets[set].multipass;
    return 0;
}

static size_t append_set(char *out, size_t size, size_t at, const wpm_set *set, int first)
{
    int n;
    if (at >= size)
        return at;
    n = snprintf(out + at, size - at, "%s--soil %s --wheel %s --multipass %lld",
                 first ? "" : "; ", set->soil, set->wheel, set->multipass);
    return n < 0 ? at : at + (size_t)n;
}

int swtwpm_select(const swtwpm *model, const char *soil, const char *wheel, long long multipass,
                  char *msg, size_t msg_size)
{
    int s, found = -1, count = 0;
    size_t at;
    char multipass_text[32];
    if (!model)
        return SWTWPM_E_ARGUMENT;
    for (s = 0; s < model->n_sets; ++s) {
        const wpm_set *set = &model->sets[s];
        if ((!soil || !strcmp(soil, set->soil)) && (!wheel || !strcmp(wheel, set->wheel))
            && (multipass < 0 || multipass == set->multipass)) {
            found = found < 0 ? s : found;
            ++count;
        }
    }
    if (count == 1)
        return found;
    if (!msg || !msg_size)
        return SWTWPM_E_SELECTION;
    if (multipass < 0)
        strcpy(multipass_text, "None");
    else
        snprintf(multipass_text, sizeof multipass_text, "%lld", multipass);
    if (!count) {
        int n = snprintf(msg, msg_size, "no curves for soil=%s wheel=%s multipass=%s in %s; "
                         "choices: ", soil ? soil : "None", wheel ? wheel : "None",
                         multipass_text, model->name);
        at = n < 0 ? 0 : (size_t)n;
        for (s = 0; s < model->n_sets; ++s)
            at = append_set(msg, msg_size, at, &model->sets[s], !s);
    } else {
        int n = snprintf(msg, msg_size, "%d curve sets match in %s; pick one: ", count,
                         model->name), first = 1;
        at = n < 0 ? 0 : (size_t)n;
        for (s = 0; s < model->n_sets; ++s) {
            const wpm_set *set = &model->sets[s];
            if ((!soil || !strcmp(soil, set->soil)) && (!wheel || !strcmp(wheel, set->wheel))
                && (multipass < 0 || multipass == set->multipass)) {
                at = append_set(msg, msg_size, at, set, first);
                first = 0;
            }
        }
    }
    return SWTWPM_E_SELECTION;
}

int swtwpm_has_quantity(const swtwpm *model, int set, int quantity)
{
    return model && set >= 0 && set < model->n_sets && quantity >= 0
           && quantity < SWTWPM_N_QUANTITIES && model->sets[set].quantity[quantity] != NULL;
}

/* the quantity's interpolation, or an error code with the message */
static const wpm_quantity *quantity_of(const swtwpm *model, int set, int quantity, char *msg,
                                       size_t msg_size, int *code)
{
    const wpm_set *s;
    const wpm_quantity *q;
    int k, first = 1;
    size_t at;
    if (!model || set < 0 || set >= model->n_sets || quantity < 0
        || quantity >= SWTWPM_N_QUANTITIES) {
        wpm_message(msg, msg_size, "no curve set %d or quantity %d", set, quantity);
        *code = SWTWPM_E_ARGUMENT;
        return NULL;
    }
    s = &model->sets[set];
    q = s->quantity[quantity];
    if (!q) {
        if (msg && msg_size) {
            int n = snprintf(msg, msg_size, "no %s curves for ('%s', '%s', %lld) in %s; it has ",
                             swtwpm_quantity_name(quantity), s->soil, s->wheel, s->multipass,
                             model->name);
            at = n < 0 ? 0 : (size_t)n;
            for (k = 0; k < SWTWPM_N_QUANTITIES; ++k)
                if (s->quantity[k] && at < msg_size) {
                    n = snprintf(msg + at, msg_size - at, "%s%s", first ? "" : ", ",
                                 swtwpm_quantity_name(k));
                    at += n < 0 ? 0 : (size_t)n;
                    first = 0;
                }
        }
        *code = SWTWPM_E_SELECTION;
        return NULL;
    }
    if (q->error) {
        wpm_message(msg, msg_size, "%s", q->error);
        *code = SWTWPM_E_LOAD_RANGE;
        return NULL;
    }
    *code = 0;
    return q;
}

int swtwpm_tested_loads(const swtwpm *model, int set, int quantity, double *loads,
                        int max_loads)
{
    const wpm_quantity *q;
    int k;
    if (!swtwpm_has_quantity(model, set, quantity))
        return SWTWPM_E_ARGUMENT;
    q = model->sets[set].quantity[quantity];
    for (k = 0; loads && k < q->n_loads && k < max_loads; ++k)
        loads[k] = q->tested[k]->load_n;
    return q->n_loads;
}

int swtwpm_slip_range(const swtwpm *model, int set, int quantity, double *slip_min,
                      double *slip_max)
{
    int code;
    const wpm_quantity *q = quantity_of(model, set, quantity, NULL, 0, &code);
    if (!q)
        return code;
    if (slip_min)
        *slip_min = q->lo;
    if (slip_max)
        *slip_max = q->hi;
    return 0;
}

int swtwpm_wheel_geometry(const swtwpm *model, const char *wheel, double geometry[5],
                          char *msg, size_t msg_size)
{
    int s, w;
    const char *name = wheel;
    if (!model || !geometry)
        return SWTWPM_E_ARGUMENT;
    for (s = 0; !wheel && s < model->n_sets; ++s) {
        if (name && strcmp(name, model->sets[s].wheel)) {
            wpm_message(msg, msg_size, "%s: several wheels; name one", model->name);
            return SWTWPM_E_SELECTION;
        }
        name = model->sets[s].wheel;
    }
    for (s = 0; s < model->n_sets && strcmp(name, model->sets[s].wheel); ++s)
        ;
    if (s == model->n_sets) {
        wpm_message(msg, msg_size, "%s: no curves of wheel '%s'", model->name, name);
        return SWTWPM_E_SELECTION;
    }
    for (w = 0; w < model->n_wheels; ++w)
        if (!strcmp(model->wheels[w].name, name)) {
            memcpy(geometry, model->wheels[w].geometry, 5 * sizeof *geometry);
            return 0;
        }
    wpm_message(msg, msg_size, "%s: no wheel geometry (header '# wheel_geometry:'), and this "
                "needs wheel '%s''s radius, width and grousers; export the WPM CSV again with "
                "this swtlab, or add the header (docs/wpm-csv.md)", model->name, name);
    return SWTWPM_E_SELECTION;
}

/* ---- the curve at a load ---- */

/* _check_loads: 0, SWTWPM_WARN_LOAD_EXTRAPOLATED, or an error with the message */
static int check_load(const wpm_quantity *q, double load, int flags, char *msg,
                      size_t msg_size)
{
    char a[32], b[32], c[32], span[80];
    int L = q->n_loads;
    if (!isfinite(load) || load <= 0) {
        char shown[48] = "";
        if (isnan(load))
            strcpy(shown, "nan");
        else if (!(load > 0)) { /* numpy's str of a float array: 5. for 5.0 */
            wpm_repr(load, shown);
            if (strlen(shown) > 2 && !strcmp(shown + strlen(shown) - 2, ".0"))
                shown[strlen(shown) - 1] = '\0';
        }
        wpm_message(msg, msg_size, "loads must be finite and > 0 N, got [%s]", shown);
        return SWTWPM_E_LOAD_RANGE;
    }
    if (load >= q->loads[0] && load <= q->loads[L - 1])
        return 0;
    if (L > 1)
        snprintf(span, sizeof span, "%s-%s N", wpm_g(q->loads[0], b), wpm_g(q->loads[L - 1], c));
    else
        snprintf(span, sizeof span, "%s N only", wpm_g(q->loads[0], b));
    if (L < 2) {
        wpm_message(msg, msg_size, "load %s N: one tested load (%s), nothing to interpolate "
                    "from", wpm_g(load, a), span);
        return SWTWPM_E_LOAD_RANGE;
    }
    if (!(flags & SWTWPM_ALLOW_EXTRAPOLATION)) {
        wpm_message(msg, msg_size, "load %s N outside the tested loads (%s); pass "
                    "allow_extrapolation to extrapolate linearly from the two nearest loads",
                    wpm_g(load, a), span);
        return SWTWPM_E_LOAD_RANGE;
    }
    wpm_message(msg, msg_size, "1 load(s) outside the tested loads (%s), e.g. %s N: "
                "extrapolated linearly", span, wpm_g(load, a));
    return SWTWPM_WARN_LOAD_EXTRAPOLATED;
}

/* the parameters (a_0 ... a_n, J, K) at a checked load (LoadPolynomial.parameters) */
static void parameters(const wpm_quantity *q, double load, int outside, double *theta)
{
    int L = q->n_loads, p = q->p, hi, j;
    double t;
    if (L == 1) {
        memcpy(theta, q->at_tested, (size_t)p * sizeof *theta);
        return;
    }
    for (hi = 0; hi < L && q->loads[hi] < load; ++hi)
        ;
    hi = hi < 1 ? 1 : hi > L - 1 ? L - 1 : hi;
    if (q->pchip && !outside) {
        int k = hi - 1, pieces = L - 1;
        double dx = load - q->loads[k];
        const double *c0 = q->pieces + (0 * pieces + k) * p, *c1 = q->pieces + (1 * pieces + k) * p;
        const double *c2 = q->pieces + (2 * pieces + k) * p, *c3 = q->pieces + (3 * pieces + k) * p;
        for (j = 0; j < p; ++j)
            theta[j] = ((c0[j] * dx + c1[j]) * dx + c2[j]) * dx + c3[j];
        return;
    }
    t = (load - q->loads[hi - 1]) / (q->loads[hi] - q->loads[hi - 1]);
    for (j = 0; j < p; ++j)
        theta[j] = (1.0 - t) * q->at_tested[(hi - 1) * p + j] + t * q->at_tested[hi * p + j];
}

static int prepare(const swtwpm *model, int set, int quantity, double load, int flags,
                   double *theta, const wpm_quantity **out, char *msg, size_t msg_size)
{
    int code;
    const wpm_quantity *q = quantity_of(model, set, quantity, msg, msg_size, &code);
    if (!q)
        return code;
    code = check_load(q, load, flags, msg, msg_size);
    if (code < 0)
        return code;
    parameters(q, load, code != 0, theta);
    *out = q;
    return code;
}

int swtwpm_value(const swtwpm *model, int set, int quantity, double load_n, double slip,
                 int flags, double *value, char *msg, size_t msg_size)
{
    double theta[P_MAX];
    const wpm_quantity *q;
    int code;
    if (!value)
        return SWTWPM_E_ARGUMENT;
    *value = NAN;
    code = prepare(model, set, quantity, load_n, flags, theta, &q, msg, msg_size);
    if (code < 0)
        return code;
    if (!isfinite(slip)) {
        char a[32];
        wpm_message(msg, msg_size, "slip %s: slips must be finite numbers", wpm_g(slip, a));
        return SWTWPM_E_NOT_FINITE;
    }
    *value = horner(theta, q->degree + 1, slip);
    if (theta[q->degree + 1] != 0 || theta[q->degree + 2] != 0)
        *value = *value + (slip < 0 ? theta[q->degree + 1] + theta[q->degree + 2] * slip : 0.0);
    if (slip < q->lo || slip > q->hi) {
        char a[32], b[32];
        wpm_message(msg, msg_size, "slip outside the range of %s [%s, %s]: extrapolated",
                    swtwpm_quantity_name(quantity), wpm_g(q->lo, a), wpm_g(q->hi, b));
        code |= SWTWPM_WARN_SLIP_OUTSIDE;
    }
    return code;
}

/* ---- the inverse (wpm_export/inverse.py, one row) ---- */

#define MAX_POINTS 64

int swtwpm_slip_for(const swtwpm *model, int set, int quantity, double load_n, double target,
                    int flags, double *slip, double *value, int *status, char *msg,
                    size_t msg_size)
{
    double theta[P_MAX], braked[SWTWPM_MAX_DEGREE + 1], f[MAX_POINTS], d[MAX_POINTS];
    double x_turn[MAX_POINTS], f_turn[MAX_POINTS], rise[MAX_POINTS], fall[MAX_POINTS];
    double start, top, bottom, a, b, fa, fb, xt, ft, poly[SWTWPM_MAX_DEGREE + 1];
    const double *polys[2];
    const wpm_quantity *q;
    const wpm_cells *cells;
    int code, n, two, g, c, n_cells, first, jump, side_of_first, i;
    if (!slip || !value || !status)
        return SWTWPM_E_ARGUMENT;
    *slip = *value = NAN;
    *status = SWTWPM_STATUS_BELOW_MIN;
    if (!quantity_of(model, set, quantity, msg, msg_size, &code))
        return code;
    if (!isfinite(target)) {
        wpm_message(msg, msg_size, "targets must be finite numbers");
        return SWTWPM_E_NOT_FINITE;
    }
    code = prepare(model, set, quantity, load_n, flags, theta, &q, msg, msg_size);
    if (code < 0)
        return code;
    n = q->degree + 1;
    memcpy(braked, theta, (size_t)n * sizeof *braked);
    braked[0] += theta[n];
    braked[1] += theta[n + 1];
    two = q->lo < 0 && 0 <= q->hi && (braked[0] != theta[0] || braked[1] != theta[1]);
    cells = &q->cells[two];
    polys[0] = two ? braked : (q->hi < 0 ? braked : theta);
    polys[1] = theta;
    n_cells = cells->points - 1;
    jump = two ? cells->count0 : -1;
    for (g = 0; g < cells->points; ++g) /* f = a @ power, d = a @ slope_power, per side */
        f[g] = d[g] = 0.0;
    for (i = 0; i < n; ++i) {
        const double *power = cells->power + i * cells->points;
        const double *slope_power = cells->slope_power + i * cells->points;
        int split = two ? cells->count0 + 1 : cells->points;
        double a0 = polys[0][i], a1 = polys[1][i];
        for (g = 0; g < split; ++g) {
            f[g] += a0 * power[g];
            d[g] += a0 * slope_power[g];
        }
        for (g = split; g < cells->points; ++g) {
            f[g] += a1 * power[g];
            d[g] += a1 * slope_power[g];
        }
    }
    for (c = 0; c < n_cells; ++c) {
        x_turn[c] = f_turn[c] = NAN;
        if (c != jump && ((d[c] > 0 && d[c + 1] < 0) || (d[c] < 0 && d[c + 1] > 0))) {
            const double *poly_c = polys[two && c > cells->count0];
            double derivative[SWTWPM_MAX_DEGREE];
            for (i = 1; i < n; ++i)
                derivative[i - 1] = poly_c[i] * i;
            x_turn[c] = root(derivative, n - 1, cells->grid[c], cells->grid[c + 1]);
            f_turn[c] = horner(poly_c, n, x_turn[c]);
        }
    }
    start = f[0];
    {
        double up = np_fmax(f[1], f_turn[0]), down = np_fmin(f[1], f_turn[0]);
        rise[0] = up;
        fall[0] = down;
        for (c = 1; c < n_cells; ++c) { /* running extremes, kept in registers */
            up = np_max(up, np_fmax(f[c + 1], f_turn[c]));
            down = np_min(down, np_fmin(f[c + 1], f_turn[c]));
            rise[c] = up;
            fall[c] = down;
        }
    }
    top = np_max(start, rise[n_cells - 1]);
    bottom = np_min(start, fall[n_cells - 1]);
    *value = np_min(np_max(target, bottom), top);
    if (target > top) {
        *slip = 1.0;
        *status = SWTWPM_STATUS_ABOVE_MAX;
        return code;
    }
    if (target < bottom) {
        *status = SWTWPM_STATUS_BELOW_MIN;
        return code;
    }
    first = 0;
    if (target >= start)
        while (first < n_cells && rise[first] < target)
            ++first;
    else
        while (first < n_cells && fall[first] > target)
            ++first;
    first = first < n_cells - 1 ? first : n_cells - 1;
    a = cells->grid[first];
    b = cells->grid[first + 1];
    fa = f[first];
    fb = f[first + 1];
    xt = x_turn[first];
    ft = f_turn[first];
    if (isfinite(xt)) {
        if (np_min(fa, ft) <= target && target <= np_max(fa, ft))
            b = xt; /* the target is met before the turning point */
        else
            a = xt; /* ... or after it */
    }
    side_of_first = two && first > cells->count0;
    memcpy(poly, polys[side_of_first], (size_t)n * sizeof *poly);
    poly[0] -= target;
    *slip = root(poly, n, a, b);
    if (first == jump)
        *slip = 0.0;
    if (target == start)
        *slip = q->lo;
    *status = (first == jump && np_min(fa, fb) < target && target < np_max(fa, fb))
                  ? SWTWPM_STATUS_AT_STEP : SWTWPM_STATUS_OK;
    return code;
}

/* ---- bands: the curve at a load with its covariance ---- */

int swtwpm_curve_at(const swtwpm *model, int set, int quantity, double load_n, int flags,
                    swtwpm_curve *curve, char *msg, size_t msg_size)
{
    double theta[P_MAX], base[GRID_POINTS], *y, sensitivity[GRID_POINTS];
    const wpm_quantity *q;
    int code, outside, L, p, k, g, i, j;
    if (!curve)
        return SWTWPM_E_ARGUMENT;
    memset(curve, 0, sizeof *curve);
    curve->k95 = curve->scatter_sd = NAN;
    code = prepare(model, set, quantity, load_n, flags, theta, &q, msg, msg_size);
    if (code < 0)
        return code;
    outside = code != 0;
    L = q->n_loads;
    p = q->p;
    curve->degree = q->degree;
    memcpy(curve->a, theta, (size_t)(q->degree + 1) * sizeof *theta);
    curve->step_below_zero = theta[q->degree + 1];
    curve->slope_below_zero = theta[q->degree + 2];
    curve->slip_min = q->lo;
    curve->slip_max = q->hi;
    curve->load_n = load_n;
    curve->extrapolated = outside;
    curve->has_uncertainty = q->has_uncertainty;
    if (!curve->has_uncertainty)
        return code;
    y = malloc((size_t)L * sizeof *y);
    if (!y) {
        wpm_message(msg, msg_size, "out of memory");
        return SWTWPM_E_MEMORY;
    }
    for (g = 0; g < GRID_POINTS; ++g) {
        for (k = 0; k < L; ++k)
            y[k] = q->values[k * GRID_POINTS + g];
        base[g] = across_load(q->loads, y, L, load_n, q->pchip, outside);
    }
    for (k = 0; k < L; ++k) { /* _propagate */
        const wpm_row *row = q->tested[k];
        int pk = row->degree + 3;
        double mapped[P_MAX][P_MAX], cm[P_MAX][P_MAX];
        for (g = 0; g < GRID_POINTS; ++g) {
            int l;
            for (l = 0; l < L; ++l)
                y[l] = q->values[l * GRID_POINTS + g];
            y[k] += q->delta;
            sensitivity[g] = (across_load(q->loads, y, L, load_n, q->pchip, outside) - base[g])
                             / q->delta;
        }
        memset(mapped, 0, sizeof mapped);
        for (g = 0; g < GRID_POINTS; ++g) {
            double s = q->grid[g], gradient[P_MAX], below = s < 0;
            for (i = 0; i <= row->degree; ++i)
                gradient[i] = pow(s, i);
            gradient[row->degree + 1] = below;
            gradient[row->degree + 2] = below * s;
            for (i = 0; i < pk; ++i) {
                double w = sensitivity[g] * gradient[i];
                for (j = 0; j < p; ++j)
                    mapped[i][j] += w * q->to_theta[g * p + j];
            }
        }
        for (i = 0; i < pk; ++i) /* C_k mapped */
            for (j = 0; j < p; ++j) {
                double sum = 0;
                int l;
                for (l = 0; l < pk; ++l)
                    sum += row->covariance[i][l] * mapped[l][j];
                cm[i][j] = sum;
            }
        for (i = 0; i < p; ++i)
            for (j = 0; j < p; ++j) {
                double sum = 0;
                int l;
                for (l = 0; l < pk; ++l)
                    sum += mapped[l][i] * cm[l][j];
                curve->covariance[i][j] += sum;
            }
    }
    if (L >= 3) { /* _interpolation_error: v v^T / 3, v the parameters of PCHIP - linear */
        double v[P_MAX];
        memset(v, 0, sizeof v);
        for (g = 0; g < GRID_POINTS; ++g) {
            double difference;
            for (k = 0; k < L; ++k)
                y[k] = q->values[k * GRID_POINTS + g];
            difference = across_load(q->loads, y, L, load_n, 1, outside)
                         - across_load(q->loads, y, L, load_n, 0, outside);
            for (j = 0; j < p; ++j)
                v[j] += difference * q->to_theta[g * p + j];
        }
        for (i = 0; i < p; ++i)
            for (j = 0; j < p; ++j)
                curve->covariance[i][j] += v[i] * v[j] / 3.0;
    }
    for (k = 0; k < L; ++k)
        y[k] = q->tested[k]->scatter_sd;
    curve->scatter_sd = across_load(q->loads, y, L, load_n, 0, outside);
    curve->scatter_sd = curve->scatter_sd > 0 ? curve->scatter_sd : 0.0;
    for (k = 0; k < L; ++k)
        y[k] = q->tested[k]->k95;
    curve->k95 = across_load(q->loads, y, L, load_n, 0, outside);
    curve->k95 = curve->k95 > 0 ? curve->k95 : 0.0;
    free(y);
    return code;
}

int swtwpm_curve_eval(const swtwpm_curve *curve, double slip, double *value, double *conf95,
                      double *pred95)
{
    double gradient[P_MAX], variance = 0, y;
    int p, i, j;
    if (!curve || curve->degree < 3 || curve->degree > SWTWPM_MAX_DEGREE)
        return SWTWPM_E_ARGUMENT;
    if (!isfinite(slip)) {
        if (value)
            *value = NAN;
        if (conf95)
            *conf95 = NAN;
        if (pred95)
            *pred95 = NAN;
        return SWTWPM_E_NOT_FINITE;
    }
    p = curve->degree + 3;
    y = horner(curve->a, curve->degree + 1, slip);
    if (curve->step_below_zero != 0 || curve->slope_below_zero != 0)
        y = y + (slip < 0 ? curve->step_below_zero + curve->slope_below_zero * slip : 0.0);
    if (value)
        *value = y;
    for (i = 0; i <= curve->degree; ++i)
        gradient[i] = pow(slip, i);
    gradient[curve->degree + 1] = slip < 0;
    gradient[curve->degree + 2] = (slip < 0) * slip;
    for (i = 0; i < p; ++i) {
        double row = 0;
        for (j = 0; j < p; ++j)
            row += curve->covariance[i][j] * gradient[j];
        variance += gradient[i] * row;
    }
    variance = np_max(variance, 0.0);
    if (!curve->has_uncertainty)
        variance = NAN;
    if (conf95)
        *conf95 = curve->k95 * sqrt(variance);
    if (pred95)
        *pred95 = curve->k95 * sqrt(variance + curve->scatter_sd * curve->scatter_sd);
    return (slip < curve->slip_min || slip > curve->slip_max) ? SWTWPM_WARN_SLIP_OUTSIDE : 0;
}

int swtwpm_value_band(const swtwpm *model, int set, int quantity, double load_n, double slip,
                      int flags, double *value, double *conf95, double *pred95, char *msg,
                      size_t msg_size)
{
    swtwpm_curve curve;
    int code = swtwpm_curve_at(model, set, quantity, load_n, flags, &curve, msg, msg_size);
    int evaluated;
    if (code < 0) {
        if (value)
            *value = NAN;
        if (conf95)
            *conf95 = NAN;
        if (pred95)
            *pred95 = NAN;
        return code;
    }
    evaluated = swtwpm_curve_eval(&curve, slip, value, conf95, pred95);
    if (evaluated == SWTWPM_E_NOT_FINITE) {
        char a[32];
        wpm_message(msg, msg_size, "slip %s: slips must be finite numbers", wpm_g(slip, a));
    }
    return evaluated < 0 ? evaluated : (code | evaluated);
}

int swtwpm_value_many(const swtwpm *model, int set, int quantity, size_t n,
                      const double *load_n, const double *slip, int flags, double *value,
                      int *codes)
{
    size_t i;
    int errors = 0;
    for (i = 0; i < n; ++i) {
        int code = swtwpm_value(model, set, quantity, load_n[i], slip[i], flags, &value[i],
                                NULL, 0);
        errors += code < 0;
        if (codes)
            codes[i] = code;
    }
    return errors;
}

int swtwpm_slip_for_many(const swtwpm *model, int set, int quantity, size_t n,
                         const double *load_n, const double *target, int flags, double *slip,
                         double *value, int *status, int *codes)
{
    size_t i;
    int errors = 0;
    for (i = 0; i < n; ++i) {
        int code = swtwpm_slip_for(model, set, quantity, load_n[i], target[i], flags, &slip[i],
                                   &value[i], &status[i], NULL, 0);
        errors += code < 0;
        if (codes)
            codes[i] = code;
    }
    return errors;
}
