/* Internal structures of libswtwpm (not installed; see swtwpm.h for the interface). */
#ifndef SWTWPM_INTERNAL_H
#define SWTWPM_INTERNAL_H

#include <stddef.h>

#include "swtwpm.h"

#define GRID_POINTS 101 /* Chebyshev-Lobatto slips of the refit across load (docs/wpm-csv.md) */

/* one row of the file */
typedef struct {
    char *soil, *wheel;
    long long multipass;
    double load_n;
    int quantity, degree, line;
    double a[SWTWPM_MAX_DEGREE + 1];
    double slip_min, slip_max, step, slope;
    int has_uncertainty;
    double k95, scatter_sd;
    double covariance[SWTWPM_MAX_PARAMETERS][SWTWPM_MAX_PARAMETERS];
} wpm_row;

/* one quantity of one curve set: the tested curves and what the interpolation across load
 * precomputes (fitting/load_interp.py) */
typedef struct {
    char *error; /* set when the tested curves cannot be interpolated (queries report it) */
    int n_loads;
    const wpm_row **tested; /* by increasing load */
    double *loads;
    double lo, hi;          /* the shared slip range */
    int degree, p, branch, pchip, has_uncertainty;
    double grid[GRID_POINTS];
    double *to_theta;  /* GRID x p: grid values -> parameters (a_0 ... a_n, J, K) */
    double *values;    /* L x GRID: the tested curves on the grid */
    double *at_tested; /* L x p */
    double *pieces;    /* 4 x (L - 1) x p: parameters cubic in (load - loads[k]) */
    double delta;      /* forward-difference step of the covariance propagation */
    double *cov_ends;   /* L x p x p: each tested curve's covariance mapped to parameters */
    double *cov_inside; /* (L - 1) x 7 x p x p: covariance, coefficients of t^0 ... t^6 */
} wpm_quantity;

typedef struct {
    char *soil, *wheel;
    long long multipass;
    wpm_quantity *quantity[SWTWPM_N_QUANTITIES];
} wpm_set;

typedef struct {
    char *name;
    double geometry[5];
} wpm_wheel;

struct swtwpm {
    char *name;
    int n_header;
    char **keys, **values;
    int n_rows;
    wpm_row *rows;
    int n_sets;
    wpm_set *sets;
    int n_wheels;
    wpm_wheel *wheels;
};

/* swtwpm_model.c: the sets and their interpolation, after the rows are read */
int wpm_build_sets(swtwpm *model, char *msg, size_t msg_size);
void wpm_free_sets(swtwpm *model);

/* messages */
void wpm_message(char *msg, size_t msg_size, const char *format, ...);
/* %g as Python's format(x, "g") (nan, inf, -inf) */
const char *wpm_g(double x, char buffer[32]);
/* repr() of a Python float */
void wpm_repr(double x, char buffer[40]);
/* repr() of a Python str (quotes, escapes of control characters), cut to size */
void wpm_repr_text(const char *s, char *buffer, size_t size);

#endif
