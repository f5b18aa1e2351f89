/* libswtwpm: the Wheel Performance Module of a swtlab WPM CSV (format swtlab-wpm/1,
 * docs/wpm-csv.md) in C99, libc and libm only.
 *
 * Reads the file (every column: braked branch, uncertainty, the wheel_geometry header) and
 * answers, at any load between the tested ones, as swtlab's Python runtime
 * (wpm_export.WheelPerformanceModule) does:
 *   forward  - a quantity at a slip (swtwpm_value), with its 95 % half-widths
 *              (swtwpm_curve_at + swtwpm_curve_eval, or swtwpm_value_band);
 *   inverse  - the smallest slip giving a required DP, torque, sinkage or resistance
 *              (swtwpm_slip_for): slip 1.0 and the maximum above the curve, NaN and the
 *              minimum below it, slip 0.0 inside the jump at zero slip of a braked branch.
 *
 * Return codes: 0 = answered; > 0 = answered with warnings (bit flags SWTWPM_WARN_*);
 * < 0 = error (SWTWPM_E_*), outputs NaN. Every function that can fail takes an optional
 * message buffer (msg, msg_size; NULL/0 for none) and writes one line there: the same text
 * as the Python runtime's error or warning for the same problem (docs/wpm-csv.md, "Errors of
 * a query"); where a query has two warnings the load's is the message. Nothing here aborts,
 * exits or prints.
 * A loaded model is read-only: queries from several threads on one model are safe.
 */
#ifndef SWTWPM_H
#define SWTWPM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define SWTWPM_FORMAT "swtlab-wpm/1"
#define SWTWPM_VERSION 1 /* bumped when this header changes incompatibly */

/* quantities, in the format's order */
enum swtwpm_quantity {
    SWTWPM_DP_N = 0,      /* drawbar pull, N */
    SWTWPM_TORQUE_NM,     /* driving torque, N*m */
    SWTWPM_SINKAGE_M,     /* sinkage, m */
    SWTWPM_RESISTANCE_N,  /* motion resistance T/r - DP, N */
    SWTWPM_DP_OVER_W,     /* DP / measured wheel load, 1 */
    SWTWPM_N_QUANTITIES
};

/* return codes */
#define SWTWPM_OK 0
#define SWTWPM_WARN_SLIP_OUTSIDE 1      /* slip outside the curve's fitted range: extrapolated */
#define SWTWPM_WARN_LOAD_EXTRAPOLATED 2 /* load outside the tested ones (asked for): linear */
#define SWTWPM_E_FORMAT (-1)     /* the file does not follow docs/wpm-csv.md */
#define SWTWPM_E_IO (-2)         /* the file cannot be read */
#define SWTWPM_E_MEMORY (-3)     /* out of memory */
#define SWTWPM_E_SELECTION (-4)  /* no (or several) curve sets match; no such quantity */
#define SWTWPM_E_LOAD_RANGE (-5) /* load not finite, <= 0, or outside the tested loads */
#define SWTWPM_E_NOT_FINITE (-6) /* a NaN or infinite slip or target */
#define SWTWPM_E_ARGUMENT (-7)   /* a NULL model or output, an unknown quantity or set */

/* query flags */
#define SWTWPM_ALLOW_EXTRAPOLATION 1 /* answer outside the tested loads (linear from the two
                                        nearest), with SWTWPM_WARN_LOAD_EXTRAPOLATED */

/* status of an inverse query */
enum swtwpm_status {
    SWTWPM_STATUS_OK = 0,    /* reached at the returned slip */
    SWTWPM_STATUS_ABOVE_MAX, /* beyond the wheel: slip 1.0, value = the curve's maximum */
    SWTWPM_STATUS_BELOW_MIN, /* below the curve: slip NaN, value = its minimum */
    SWTWPM_STATUS_AT_STEP    /* inside the jump at zero slip: slip 0.0, value = target */
};

#define SWTWPM_MAX_DEGREE 7
#define SWTWPM_MAX_PARAMETERS (SWTWPM_MAX_DEGREE + 3) /* a_0 ... a_7, J, K */

typedef struct swtwpm swtwpm;

/* The curve of one quantity at one load: sum a_i s^i + [s < 0] (J + K s) on
 * [slip_min, slip_max], with the covariance of (a_0 ... a_degree, J, K) (indices 0 ...
 * degree + 2) where the file carries the uncertainty columns. */
typedef struct {
    int degree;
    double a[SWTWPM_MAX_DEGREE + 1];
    double step_below_zero, slope_below_zero; /* J, K */
    double slip_min, slip_max;
    double load_n;
    int extrapolated;    /* 1 when load_n lies outside the tested loads */
    int has_uncertainty; /* 0: covariance, k95, scatter_sd unknown (NaN half-widths) */
    double covariance[SWTWPM_MAX_PARAMETERS][SWTWPM_MAX_PARAMETERS];
    double k95, scatter_sd;
} swtwpm_curve;

/* --- loading --- */

/* Read a WPM CSV file; on success *out is a model to free with swtwpm_free. Errors:
 * SWTWPM_E_IO, SWTWPM_E_FORMAT ("path:line: problem"), SWTWPM_E_MEMORY. */
int swtwpm_open(const char *path, swtwpm **out, char *msg, size_t msg_size);
/* The same from text in memory (size bytes, need not end in NUL); name is used in
 * messages. */
int swtwpm_parse(const char *text, size_t size, const char *name, swtwpm **out, char *msg,
                 size_t msg_size);
void swtwpm_free(swtwpm *model);

/* The value of header key (e.g. "swtlab_version"), or NULL. */
const char *swtwpm_header(const swtwpm *model, const char *key);

/* --- curve sets: (soil, wheel, multipass) --- */

int swtwpm_set_count(const swtwpm *model);
/* soil, wheel (owned by the model) and multipass of set index set (0 ... count - 1) */
int swtwpm_set_info(const swtwpm *model, int set, const char **soil, const char **wheel,
                    long long *multipass);
/* The one set matching the given fields (NULL / negative multipass: any): its index >= 0,
 * else SWTWPM_E_SELECTION with the choices in msg. */
int swtwpm_select(const swtwpm *model, const char *soil, const char *wheel,
                  long long multipass, char *msg, size_t msg_size);
/* 1 when the set has curves of quantity, else 0 */
int swtwpm_has_quantity(const swtwpm *model, int set, int quantity);
/* tested loads (N) of a quantity of a set: their count; up to max_loads written */
int swtwpm_tested_loads(const swtwpm *model, int set, int quantity, double *loads,
                        int max_loads);
/* the slip range all tested loads share (where the curve at any load is valid) */
int swtwpm_slip_range(const swtwpm *model, int set, int quantity, double *slip_min,
                      double *slip_max);
/* "dp_n", "torque_nm", ... ("?" for an unknown index) and the unit ("N", "N*m", ...) */
const char *swtwpm_quantity_name(int quantity);
const char *swtwpm_quantity_unit(int quantity);
/* Index of a quantity name, or SWTWPM_E_ARGUMENT. */
int swtwpm_quantity_index(const char *name);

/* Geometry of wheel (NULL: the only wheel) from the wheel_geometry header: radius_m,
 * width_m, grouser_count, grouser_height_m, stiffness_n_per_mm (NaN: rigid) into
 * geometry[0..4]. SWTWPM_E_SELECTION when the file does not carry it. */
int swtwpm_wheel_geometry(const swtwpm *model, const char *wheel, double geometry[5],
                          char *msg, size_t msg_size);

/* --- queries --- */

/* The quantity at slip and load_n (forward). */
int swtwpm_value(const swtwpm *model, int set, int quantity, double load_n, double slip,
                 int flags, double *value, char *msg, size_t msg_size);
/* The smallest slip in the shared slip range where the curve at load_n equals target
 * (inverse); *value is the target where reached, else the extreme; *status a
 * swtwpm_status. */
int swtwpm_slip_for(const swtwpm *model, int set, int quantity, double load_n, double target,
                    int flags, double *slip, double *value, int *status, char *msg,
                    size_t msg_size);
/* The curve at load_n with its covariance (what the bands need: the covariance is a
 * polynomial of load precomputed at open, evaluated here; to ask many slips at one load,
 * compute it once and evaluate it at each). */
int swtwpm_curve_at(const swtwpm *model, int set, int quantity, double load_n, int flags,
                    swtwpm_curve *curve, char *msg, size_t msg_size);
/* The curve's value and 95 % half-widths at slip: conf95 = k95 sqrt(g'Cg) (where the true
 * curve lies), pred95 = k95 sqrt(g'Cg + scatter_sd^2) (one new run); NaN when unknown.
 * Any output may be NULL. Returns SWTWPM_WARN_SLIP_OUTSIDE outside the fitted range. */
int swtwpm_curve_eval(const swtwpm_curve *curve, double slip, double *value, double *conf95,
                      double *pred95);
/* swtwpm_curve_at and swtwpm_curve_eval in one call. */
int swtwpm_value_band(const swtwpm *model, int set, int quantity, double load_n, double slip,
                      int flags, double *value, double *conf95, double *pred95, char *msg,
                      size_t msg_size);

/* Arrays of n queries (for bindings): results per element, return code per element in
 * codes (may be NULL); returns the number of elements with an error (< 0 code). */
int swtwpm_value_many(const swtwpm *model, int set, int quantity, size_t n,
                      const double *load_n, const double *slip, int flags, double *value,
                      int *codes);
int swtwpm_slip_for_many(const swtwpm *model, int set, int quantity, size_t n,
                         const double *load_n, const double *target, int flags, double *slip,
                         double *value, int *status, int *codes);

#ifdef __cplusplus
}
#endif

#endif /* SWTWPM_H */
