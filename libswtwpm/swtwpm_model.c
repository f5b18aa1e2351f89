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
 *   PCHIP-minus-linear interpolation error v v^T / 3, precomputed as a polynomial of load
 *   (sextic in t per interval, LoadPolynomial.covariance_pieces); scatter_sd and k95 linear
 *   in load;
 * - the inverse (wpm_export/kernel.py, the same operations): each side of zero slip cut
 *   at the curve's turning points at the load (the real roots of its derivative in the
 *   range, isolated by those of the next derivative, recursively down to a quadratic) into
 *   monotone pieces; the first piece in slip order whose values span the target holds the
 *   smallest slip, found by safeguarded Newton; the jump at zero slip is a piece of its own.
 *
 * Error and warning messages are the Python runtime's (wpm_export/runtime.py), word for
 * word: they name the keyword argument of the Python call (load_n=..., target=...). */
#include <math.h>
#include <stdarg.h>
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

/* numpy.maximum: NaN propagates */
static double np_max(double a, double b) { return (a > b || isnan(a)) ? a : b; }

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

/* the four coefficients (of (w - x[i])^3 ... ^0) of interval i across load: PCHIP, or
 * linear (fitting.load_interp._linear_pieces) */
static void piece(const double *x, const double *y, int L, int i, int pchip, double c[4])
{
    if (pchip) {
        pchip_piece(x, y, L, i, c);
        return;
    }
    c[0] = c[1] = 0.0;
    c[2] = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
    c[3] = y[i];
}

/* out (p x p) += A^T C B, A and B pk x p (row-major), C the pk x pk covariance */
static void add_sandwich(const double *a, const double covariance[P_MAX][P_MAX],
                         const double *b, int pk, int p, double scale, double *out)
{
    double cb[P_MAX * P_MAX];
    int i, j, l;
    for (i = 0; i < pk; ++i)
        for (j = 0; j < p; ++j) {
            double sum = 0.0;
            for (l = 0; l < pk; ++l)
                sum += covariance[i][l] * b[l * p + j];
            cb[i * p + j] = sum;
        }
    for (i = 0; i < p; ++i)
        for (j = 0; j < p; ++j) {
            double sum = 0.0;
            for (l = 0; l < pk; ++l)
                sum += a[l * p + i] * cb[l * p + j];
            out[i * p + j] += scale * sum;
        }
}

/* The covariance of the parameters as a polynomial of load
 * (fitting.load_interp.LoadPolynomial.covariance_pieces): ends (L x p x p), each tested
 * curve's covariance mapped to the parameters; inside ((L - 1) x 7 x p x p), the
 * coefficients of t^r between tested loads k and k + 1 (t = (load - loads[k]) / width):
 * the propagated tested covariances (forward-difference sensitivities of the across-load
 * pieces, cubic in t, their products sextic) plus, with 3+ loads, the interpolation error
 * v v^T / 3 (v: the parameters of PCHIP less linear). */
static int build_covariance(wpm_quantity *q)
{
    int L = q->n_loads, P = L - 1, p = q->p, k, kk, g, i, j, jj, b, m;
    size_t pp = (size_t)p * p;
    double *y = malloc((size_t)L * sizeof *y), *sensitivity = NULL, *a = NULL;
    q->cov_ends = calloc((size_t)L * pp, sizeof *q->cov_ends);
    q->cov_inside = calloc((size_t)(P > 0 ? P : 1) * 7 * pp, sizeof *q->cov_inside);
    if (P > 0) {
        sensitivity = malloc((size_t)4 * P * GRID_POINTS * sizeof *sensitivity);
        a = malloc((size_t)4 * P_MAX * p * sizeof *a);
    }
    if (!y || !q->cov_ends || !q->cov_inside || (P > 0 && (!sensitivity || !a))) {
        free(y), free(sensitivity), free(a);
        return SWTWPM_E_MEMORY;
    }
    for (k = 0; k < L; ++k) {
        const wpm_row *row = q->tested[k];
        int pk = row->degree + 3;
        double mapped[P_MAX * P_MAX];
        memset(mapped, 0, sizeof mapped);
        for (g = 0; g < GRID_POINTS; ++g) { /* parameter_gradient(grid).T @ to_theta */
            double s = q->grid[g], gradient[P_MAX], below = s < 0;
            for (i = 0; i <= row->degree; ++i)
                gradient[i] = pow(s, i);
            gradient[row->degree + 1] = below;
            gradient[row->degree + 2] = below * s;
            for (i = 0; i < pk; ++i)
                for (b = 0; b < p; ++b)
                    mapped[i * p + b] += gradient[i] * q->to_theta[g * p + b];
        }
        add_sandwich(mapped, row->covariance, mapped, pk, p, 1.0, q->cov_ends + k * pp);
        if (P < 1)
            continue;
        for (g = 0; g < GRID_POINTS; ++g) { /* sensitivities, t^0 ... t^3 */
            for (kk = 0; kk < P; ++kk) {
                double base[4], again[4], width = q->loads[kk + 1] - q->loads[kk];
                int l;
                for (l = 0; l < L; ++l)
                    y[l] = q->values[l * GRID_POINTS + g];
                piece(q->loads, y, L, kk, q->pchip, base);
                y[k] += q->delta;
                piece(q->loads, y, L, kk, q->pchip, again);
                for (m = 0; m < 4; ++m)
                    sensitivity[((3 - m) * P + kk) * GRID_POINTS + g] =
                        (again[m] - base[m]) / q->delta * pow(width, 3 - m);
            }
        }
        for (kk = 0; kk < P; ++kk) {
            memset(a, 0, (size_t)4 * P_MAX * p * sizeof *a);
            for (g = 0; g < GRID_POINTS; ++g) {
                double s = q->grid[g], gradient[P_MAX], below = s < 0;
                for (i = 0; i <= row->degree; ++i)
                    gradient[i] = pow(s, i);
                gradient[row->degree + 1] = below;
                gradient[row->degree + 2] = below * s;
                for (j = 0; j < 4; ++j) {
                    double w = sensitivity[(j * P + kk) * GRID_POINTS + g];
                    for (i = 0; i < pk; ++i)
                        for (b = 0; b < p; ++b)
                            a[(j * P_MAX + i) * p + b] += gradient[i] * w
                                                          * q->to_theta[g * p + b];
                }
            }
            for (j = 0; j < 4; ++j)
                for (jj = 0; jj < 4; ++jj)
                    add_sandwich(a + j * P_MAX * p, row->covariance, a + jj * P_MAX * p, pk, p,
                                 1.0, q->cov_inside + ((size_t)kk * 7 + j + jj) * pp);
        }
    }
    if (L >= 3) { /* interpolation error */
        for (kk = 0; kk < P; ++kk) {
            double v[4][P_MAX], width = q->loads[kk + 1] - q->loads[kk];
            memset(v, 0, sizeof v);
            for (g = 0; g < GRID_POINTS; ++g) {
                double cubic[4], line[4];
                int l;
                for (l = 0; l < L; ++l)
                    y[l] = q->values[l * GRID_POINTS + g];
                piece(q->loads, y, L, kk, 1, cubic);
                piece(q->loads, y, L, kk, 0, line);
                for (m = 0; m < 4; ++m) {
                    double d = (cubic[m] - line[m]) * pow(width, 3 - m);
                    for (b = 0; b < p; ++b)
                        v[3 - m][b] += d * q->to_theta[g * p + b];
                }
            }
            for (j = 0; j < 4; ++j)
                for (jj = 0; jj < 4; ++jj)
                    for (i = 0; i < p; ++i)
                        for (b = 0; b < p; ++b)
                            q->cov_inside[((size_t)kk * 7 + j + jj) * pp + i * p + b] +=
                                v[j][i] * v[jj][b] / 3.0;
        }
    }
    free(y), free(sensitivity), free(a);
    return 0;
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
    return q->has_uncertainty ? build_covariance(q) : 0;
}

static void free_quantity(wpm_quantity *q)
{
    if (!q)
        return;
    free(q->error);
    free((void *)q->tested);
    free(q->loads);
    free(q->to_theta);
    free(q->values);
    free(q->at_tested);
    free(q->pieces);
    free(q->cov_ends);
    free(q->cov_inside);
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

/* printf to out + *at, at most up to size (the text cut, NUL-terminated) */
static void append(char *out, size_t size, size_t *at, const char *format, ...)
{
    va_list args;
    int n;
    if (!out || *at + 1 >= size)
        return;
    va_start(args, format);
    n = vsnprintf(out + *at, size - *at, format, args);
    va_end(args);
    *at = n < 0 ? *at : *at + (size_t)n < size ? *at + (size_t)n : size - 1;
}

/* "soil='a', wheel='b', multipass=0" (runtime._selection_text): the arguments given, NULL /
   negative ones left out */
static void append_selection(char *out, size_t size, size_t *at, const char *soil,
                             const char *wheel, long long multipass)
{
    char text[1024];
    const char *sep = "";
    if (soil) {
        wpm_repr_text(soil, text, sizeof text);
        append(out, size, at, "soil=%s", text);
        sep = ", ";
    }
    if (wheel) {
        wpm_repr_text(wheel, text, sizeof text);
        append(out, size, at, "%swheel=%s", sep, text);
        sep = ", ";
    }
    if (multipass >= 0)
        append(out, size, at, "%smultipass=%lld", sep, multipass);
}

static int matches(const wpm_set *set, const char *soil, const char *wheel,
                   long long multipass)
{
    return (!soil || !strcmp(soil, set->soil)) && (!wheel || !strcmp(wheel, set->wheel))
           && (multipass < 0 || multipass == set->multipass);
}

int swtwpm_select(const swtwpm *model, const char *soil, const char *wheel, long long multipass,
                  char *msg, size_t msg_size)
{
    int s, found = -1, count = 0, first = 1;
    size_t at = 0;
    if (!model)
        return SWTWPM_E_ARGUMENT;
    for (s = 0; s < model->n_sets; ++s)
        if (matches(&model->sets[s], soil, wheel, multipass)) {
            found = found < 0 ? s : found;
            ++count;
        }
    if (count == 1)
        return found;
    if (!msg || !msg_size)
        return SWTWPM_E_SELECTION;
    msg[0] = '\0';
    if (!count) {
        append(msg, msg_size, &at, "no curves for ");
        append_selection(msg, msg_size, &at, soil, wheel, multipass);
        append(msg, msg_size, &at, " in %s; choices: ", model->name);
    } else
        append(msg, msg_size, &at, "%d curve sets match in %s; pick one: ", count, model->name);
    for (s = 0; s < model->n_sets; ++s) {
        const wpm_set *set = &model->sets[s];
        if (count && !matches(set, soil, wheel, multipass))
            continue;
        append(msg, msg_size, &at, first ? "" : "; ");
        append_selection(msg, msg_size, &at, set->soil, set->wheel, set->multipass);
        first = 0;
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
    size_t at = 0;
    if (!model || set < 0 || set >= model->n_sets || quantity < 0
        || quantity >= SWTWPM_N_QUANTITIES) {
        wpm_message(msg, msg_size, "no curve set %d or quantity %d", set, quantity);
        *code = SWTWPM_E_ARGUMENT;
        return NULL;
    }
    s = &model->sets[set];
    q = s->quantity[quantity];
    if (!q) {
        append(msg, msg_size, &at, "quantity='%s': no such curves for ",
               swtwpm_quantity_name(quantity));
        append_selection(msg, msg_size, &at, s->soil, s->wheel, s->multipass);
        append(msg, msg_size, &at, " in %s; it has ", model->name);
        for (k = 0; k < SWTWPM_N_QUANTITIES; ++k)
            if (s->quantity[k]) {
                append(msg, msg_size, &at, "%s%s", first ? "" : ", ", swtwpm_quantity_name(k));
                first = 0;
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

static int compare_text(const void *a, const void *b)
{
    return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Python's repr of the sorted list of the model's wheel names: ['a', 'b'] */
static void append_wheels(const swtwpm *model, char *msg, size_t msg_size, size_t *at)
{
    const char **names = malloc((size_t)(model->n_sets ? model->n_sets : 1) * sizeof *names);
    char text[1024];
    int s, first = 1;
    if (!names)
        return;
    for (s = 0; s < model->n_sets; ++s)
        names[s] = model->sets[s].wheel;
    qsort((void *)names, (size_t)model->n_sets, sizeof *names, compare_text);
    append(msg, msg_size, at, "[");
    for (s = 0; s < model->n_sets; ++s)
        if (!s || strcmp(names[s - 1], names[s])) {
            wpm_repr_text(names[s], text, sizeof text);
            append(msg, msg_size, at, "%s%s", first ? "" : ", ", text);
            first = 0;
        }
    append(msg, msg_size, at, "]");
    free((void *)names);
}

int swtwpm_wheel_geometry(const swtwpm *model, const char *wheel, double geometry[5],
                          char *msg, size_t msg_size)
{
    int s, w;
    const char *name = wheel;
    char text[1024];
    size_t at = 0;
    if (!model || !geometry)
        return SWTWPM_E_ARGUMENT;
    for (s = 0; !wheel && s < model->n_sets; ++s) {
        if (name && strcmp(name, model->sets[s].wheel)) {
            append(msg, msg_size, &at, "%s: several wheels ", model->name);
            append_wheels(model, msg, msg_size, &at);
            append(msg, msg_size, &at, "; name one");
            return SWTWPM_E_SELECTION;
        }
        name = model->sets[s].wheel;
    }
    for (s = 0; name && s < model->n_sets && strcmp(name, model->sets[s].wheel); ++s)
        ;
    wpm_repr_text(name ? name : "", text, sizeof text);
    if (!name || s == model->n_sets) {
        append(msg, msg_size, &at, "%s: no curves of wheel %s; wheels: ", model->name, text);
        append_wheels(model, msg, msg_size, &at);
        return SWTWPM_E_SELECTION;
    }
    for (w = 0; w < model->n_wheels; ++w)
        if (!strcmp(model->wheels[w].name, name)) {
            memcpy(geometry, model->wheels[w].geometry, 5 * sizeof *geometry);
            return 0;
        }
    wpm_message(msg, msg_size, "%s: no wheel geometry (header '# wheel_geometry:'), and this "
                "needs wheel %s's radius, width and grousers; export the WPM CSV again with "
                "this swtlab, or add the header (docs/wpm-csv.md)", model->name, text);
    return SWTWPM_E_SELECTION;
}

/* ---- the curve at a load ---- */

/* 0, SWTWPM_WARN_LOAD_EXTRAPOLATED, or an error with the message (the kernel's _locate,
 * the runtime's _outcome) */
static int check_load(const wpm_quantity *q, int quantity, double load, int flags, char *msg,
                      size_t msg_size)
{
    char a[40], b[32], c[32], span[80];
    const char *name = swtwpm_quantity_name(quantity);
    int L = q->n_loads;
    if (!(load > 0.0 && load < INFINITY)) {
        wpm_repr(load, a);
        wpm_message(msg, msg_size, "load_n=%s: the wheel load must be a finite number > 0 N", a);
        return SWTWPM_E_LOAD_RANGE;
    }
    if (q->loads[0] <= load && load <= q->loads[L - 1])
        return 0;
    if (L > 1)
        snprintf(span, sizeof span, "%s-%s N", wpm_g(q->loads[0], b), wpm_g(q->loads[L - 1], c));
    else
        snprintf(span, sizeof span, "%s N", wpm_g(q->loads[0], b));
    if (L < 2) {
        wpm_message(msg, msg_size, "load_n=%s N: %s was tested at %s only, nothing to "
                    "interpolate from", wpm_g(load, a), name, span);
        return SWTWPM_E_LOAD_RANGE;
    }
    if (!(flags & SWTWPM_ALLOW_EXTRAPOLATION)) {
        wpm_message(msg, msg_size, "load_n=%s N is outside the tested loads (%s) of %s; pass "
                    "allow_extrapolation=True to extrapolate linearly from the two nearest "
                    "loads", wpm_g(load, a), span, name);
        return SWTWPM_E_LOAD_RANGE;
    }
    wpm_message(msg, msg_size, "1 load(s) outside the tested loads (%s) of %s, e.g. load_n=%s "
                "N: extrapolated linearly", span, name, wpm_g(load, a));
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

/* The checks of a query in the runtime's order (set and quantity, then the slip or target
 * named `name` when not NULL, then the load) and the parameters at the load: 0 or
 * SWTWPM_WARN_LOAD_EXTRAPOLATED, else an error code with the message. */
static int prepare(const swtwpm *model, int set, int quantity, double load, int flags,
                   const char *name, double x, double *theta, const wpm_quantity **out,
                   char *msg, size_t msg_size)
{
    int code;
    const wpm_quantity *q = quantity_of(model, set, quantity, msg, msg_size, &code);
    if (!q)
        return code;
    if (name && !(x - x == 0.0)) {
        char a[40];
        wpm_repr(x, a);
        wpm_message(msg, msg_size, "%s=%s: %s queries need a finite number", name, a,
                    swtwpm_quantity_name(quantity));
        return SWTWPM_E_NOT_FINITE;
    }
    code = check_load(q, quantity, load, flags, msg, msg_size);
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
    code = prepare(model, set, quantity, load_n, flags, "slip", slip, theta, &q, msg,
                   msg_size);
    if (code < 0)
        return code;
    *value = horner(theta, q->degree + 1, slip);
    if (slip < 0.0)
        *value += theta[q->degree + 1] + theta[q->degree + 2] * slip;
    if (slip < q->lo || slip > q->hi) {
        char a[32], b[32];
        if (!code) /* the load's warning is the message when there are both */
            wpm_message(msg, msg_size, "slip outside the range of %s [%s, %s]: extrapolated",
                        swtwpm_quantity_name(quantity), wpm_g(q->lo, a), wpm_g(q->hi, b));
        code |= SWTWPM_WARN_SLIP_OUTSIDE;
    }
    return code;
}

/* ---- the inverse (wpm_export/kernel.py: _root, _turning_points, _cuts, _find) ---- */

#define ROW P_MAX /* longest parameter vector: room for the cuts of one side */

static double horner_degree(const double *c, int degree, double x)
{
    double y = c[degree];
    int i;
    for (i = degree - 1; i >= 0; --i)
        y = y * x + c[i];
    return y;
}

/* Slip in [a, b] where sum c_i x^i - level crosses zero (fa, fb: the values at the ends, of
 * opposite sign or one zero): safeguarded Newton from the secant point, bisection where a
 * step would leave the bracket (Press et al. 2007, Numerical Recipes 3rd ed., sec. 9.4,
 * rtsafe) */
static double root(const double *c, int degree, double level, double a, double b, double fa,
                   double fb)
{
    double secant, x;
    int iteration;
    if (fa == 0.0)
        return a;
    if (fb == 0.0)
        return b;
    secant = a - fa * (b - a) / (fb - fa);
    x = (a < secant && secant < b) ? secant : 0.5 * (a + b);
    for (iteration = 0; iteration < MAX_ITERATIONS; ++iteration) {
        double f = c[degree], d = 0.0, newton, following, step;
        int i;
        for (i = degree - 1; i >= 0; --i) {
            d = d * x + f;
            f = f * x + c[i];
        }
        f -= level;
        if (f == 0.0)
            return x;
        if ((f < 0.0) == (fa < 0.0)) {
            a = x;
            fa = f;
        } else
            b = x;
        newton = d != 0.0 ? x - f / d : a - 1.0;
        following = (a < newton && newton < b) ? newton : 0.5 * (a + b);
        step = following - x;
        x = following;
        if (fabs(step) <= STEP_TOLERANCE * (1.0 + fabs(x - step)))
            break;
    }
    return x;
}

/* simple real roots in (u, v) of c0 + c1 x + c2 x^2, increasing, into out; how many
 * (the cancellation-free form: Press et al. 2007, sec. 5.6) */
static int quadratic_roots(double c0, double c1, double c2, double u, double v, double *out)
{
    double disc, q, r0, r1, r[2];
    int count = 0, j;
    if (c2 == 0.0) {
        if (c1 != 0.0 && u < -c0 / c1 && -c0 / c1 < v) {
            out[0] = -c0 / c1;
            count = 1;
        }
        return count;
    }
    disc = c1 * c1 - 4.0 * c2 * c0;
    if (!(disc > 0.0))
        return 0;
    q = -0.5 * (c1 + copysign(sqrt(disc), c1));
    r0 = q / c2;
    r1 = c0 / q;
    r[0] = r1 < r0 ? r1 : r0;
    r[1] = r0 < r1 ? r1 : r0;
    for (j = 0; j < 2; ++j)
        if (u < r[j] && r[j] < v)
            out[count++] = r[j];
    return count;
}

/* Slips in (u, v) where the derivative of the degree-n polynomial c changes sign,
 * increasing, into roots; how many. The k-th derivative is monotone between sign changes of
 * the (k+1)-th: each level's roots bracket the next (the quadratic level in closed form). */
static int turning_points(const double *c, int n, double u, double v, double *roots)
{
    double d[ROW][ROW], spare[ROW];
    int k, i, j, count;
    if (n < 2)
        return 0;
    for (i = 0; i <= n; ++i)
        d[0][i] = c[i];
    for (k = 1; k < n; ++k)
        for (i = 0; i < n - k + 1; ++i)
            d[k][i] = (i + 1) * d[k - 1][i + 1];
    if (n == 2) { /* the derivative is linear */
        double c0 = d[1][0], c1 = d[1][1];
        if (c1 != 0.0 && u < -c0 / c1 && -c0 / c1 < v) {
            roots[0] = -c0 / c1;
            return 1;
        }
        return 0;
    }
    count = quadratic_roots(d[n - 2][0], d[n - 2][1], d[n - 2][2], u, v, roots);
    for (k = n - 3; k > 0; --k) {
        double x0 = u, f0 = horner_degree(d[k], n - k, u);
        int found = 0;
        for (j = 0; j < count + 1; ++j) {
            double x1 = j < count ? roots[j] : v, f1 = horner_degree(d[k], n - k, x1);
            if ((f0 < 0.0 && f1 > 0.0) || (f0 > 0.0 && f1 < 0.0))
                spare[found++] = root(d[k], n - k, 0.0, x0, x1, f0, f1);
            x0 = x1;
            f0 = f1;
        }
        for (j = 0; j < found; ++j)
            roots[j] = spare[j];
        count = found;
    }
    return count;
}

/* the curve at one load cut into monotone pieces: slips xs and values fs of the cuts in
 * slip order, the braked polynomial, the index of the cut that ends the braked side (-1
 * without two sides) */
typedef struct {
    double braked[SWTWPM_MAX_DEGREE + 1], xs[2 * ROW], fs[2 * ROW];
    int m, jump;
} wpm_cuts;

static void cut(const double *theta, int n, double lo, double hi, wpm_cuts *w)
{
    double roots[ROW];
    int two = lo < 0.0 && 0.0 <= hi && (theta[n + 1] != 0.0 || theta[n + 2] != 0.0), side;
    memcpy(w->braked, theta, (size_t)(n + 1) * sizeof *theta);
    w->braked[0] += theta[n + 1];
    w->braked[1] += theta[n + 2];
    w->m = 0;
    w->jump = -1;
    for (side = 0; side < (two ? 2 : 1); ++side) {
        int braked = (side == 0 && two) || (!two && hi < 0.0), count, j;
        const double *poly = braked ? w->braked : theta;
        double u = side == 0 ? lo : 0.0, v = two && side == 0 ? 0.0 : hi;
        count = turning_points(poly, n, u, v, roots);
        for (j = 0; j < count + 2; ++j) {
            double x = j == 0 ? u : j == count + 1 ? v : roots[j - 1];
            w->xs[w->m] = x;
            w->fs[w->m] = horner_degree(poly, n, x);
            ++w->m;
        }
        if (two && side == 0)
            w->jump = w->m - 1;
    }
}

/* slip, value and status of a target on the cut curve */
static void find(const wpm_cuts *w, const double *theta, int n, double lo, double target,
                 double *slip, double *value, int *status)
{
    double top = w->fs[0], bottom = w->fs[0];
    int i;
    for (i = 1; i < w->m; ++i) {
        top = w->fs[i] > top ? w->fs[i] : top;
        bottom = w->fs[i] < bottom ? w->fs[i] : bottom;
    }
    if (target > top) {
        *slip = 1.0, *value = top, *status = SWTWPM_STATUS_ABOVE_MAX;
        return;
    }
    if (target < bottom) {
        *slip = NAN, *value = bottom, *status = SWTWPM_STATUS_BELOW_MIN;
        return;
    }
    *value = target;
    *status = SWTWPM_STATUS_OK;
    if (target == w->fs[0]) {
        *slip = lo;
        return;
    }
    for (i = 0; i < w->m - 1; ++i) {
        double f0 = w->fs[i], f1 = w->fs[i + 1];
        double low = f0 < f1 ? f0 : f1, high = f0 < f1 ? f1 : f0;
        if (low <= target && target <= high) {
            const double *poly;
            if (i == w->jump) {
                *slip = 0.0;
                if (low < target && target < high)
                    *status = SWTWPM_STATUS_AT_STEP;
                return;
            }
            poly = (w->jump >= 0 && i < w->jump) || (w->jump < 0 && w->xs[w->m - 1] < 0.0)
                       ? w->braked : theta;
            *slip = root(poly, n, target, w->xs[i], w->xs[i + 1], f0 - target, f1 - target);
            return;
        }
    }
    *slip = NAN, *status = SWTWPM_STATUS_BELOW_MIN; /* not reached: the pieces span it */
}

int swtwpm_slip_for(const swtwpm *model, int set, int quantity, double load_n, double target,
                    int flags, double *slip, double *value, int *status, char *msg,
                    size_t msg_size)
{
    double theta[P_MAX];
    const wpm_quantity *q;
    wpm_cuts cuts;
    int code;
    if (!slip || !value || !status)
        return SWTWPM_E_ARGUMENT;
    *slip = *value = NAN;
    *status = SWTWPM_STATUS_BELOW_MIN;
    code = prepare(model, set, quantity, load_n, flags, "target", target, theta, &q, msg,
                   msg_size);
    if (code < 0)
        return code;
    cut(theta, q->degree, q->lo, q->hi, &cuts);
    find(&cuts, theta, q->degree, q->lo, target, slip, value, status);
    return code;
}

/* ---- bands: the curve at a load with its covariance ---- */

int swtwpm_curve_at(const swtwpm *model, int set, int quantity, double load_n, int flags,
                    swtwpm_curve *curve, char *msg, size_t msg_size)
{
    double theta[P_MAX], t, y[2];
    const wpm_quantity *q;
    const double *c;
    int code, outside, L, p, k, hi, i, j, r;
    size_t pp;
    if (!curve)
        return SWTWPM_E_ARGUMENT;
    memset(curve, 0, sizeof *curve);
    curve->k95 = curve->scatter_sd = NAN;
    code = prepare(model, set, quantity, load_n, flags, NULL, 0.0, theta, &q, msg, msg_size);
    if (code < 0)
        return code;
    outside = code != 0;
    L = q->n_loads;
    p = q->p;
    pp = (size_t)p * p;
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
    if (L == 1) { /* the kernel's _variance, as a matrix */
        for (i = 0; i < p; ++i)
            for (j = 0; j < p; ++j)
                curve->covariance[i][j] = q->cov_ends[i * p + j];
        curve->scatter_sd = q->tested[0]->scatter_sd > 0 ? q->tested[0]->scatter_sd : 0.0;
        curve->k95 = q->tested[0]->k95 > 0 ? q->tested[0]->k95 : 0.0;
        return code;
    }
    for (hi = 0; hi < L && q->loads[hi] < load_n; ++hi)
        ;
    k = (hi < 1 ? 1 : hi > L - 1 ? L - 1 : hi) - 1;
    t = (load_n - q->loads[k]) / (q->loads[k + 1] - q->loads[k]);
    for (i = 0; i < p; ++i)
        for (j = 0; j < p; ++j) {
            if (outside) /* linear: (1 - t)^2 D_k + t^2 D_k+1 */
                curve->covariance[i][j] = (1.0 - t) * (1.0 - t) * q->cov_ends[k * pp + i * p + j]
                                          + t * t * q->cov_ends[(k + 1) * pp + i * p + j];
            else {
                c = q->cov_inside + (size_t)k * 7 * pp + i * p + j;
                curve->covariance[i][j] = c[6 * pp];
                for (r = 5; r >= 0; --r)
                    curve->covariance[i][j] = curve->covariance[i][j] * t + c[r * pp];
            }
        }
    y[0] = (1.0 - t) * q->tested[k]->scatter_sd + t * q->tested[k + 1]->scatter_sd;
    y[1] = (1.0 - t) * q->tested[k]->k95 + t * q->tested[k + 1]->k95;
    curve->scatter_sd = y[0] > 0 ? y[0] : 0.0;
    curve->k95 = y[1] > 0 ? y[1] : 0.0;
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
    double theta[P_MAX];
    const wpm_quantity *q;
    int code = prepare(model, set, quantity, load_n, flags, "slip", slip, theta, &q, msg,
                       msg_size);
    if (code >= 0)
        code = swtwpm_curve_at(model, set, quantity, load_n, flags, &curve, msg, msg_size);
    if (code < 0) {
        if (value)
            *value = NAN;
        if (conf95)
            *conf95 = NAN;
        if (pred95)
            *pred95 = NAN;
        return code;
    }
    return code | swtwpm_curve_eval(&curve, slip, value, conf95, pred95);
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
