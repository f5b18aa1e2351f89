/* Scalar query rate of libswtwpm (bench/bench_wpm_c.py builds it with -O2): one query per
 * call at a random continuous load in the tested range, as a simulator asks every step.
 * Usage: bench_queries WPM.csv MULTIPASS N; prints "forward <queries per wall s> <per CPU s>",
 * "inverse ...", "band ..." (curve at the load with its covariance, then value and
 * half-widths). */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "swtwpm.h"

static double now(clockid_t clock)
{
    struct timespec t;
    clock_gettime(clock, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* a case: n calls of one kind; prints "<kind> <queries per wall s> <per CPU s>" */
static double wall, cpu;
static void start(void)
{
    wall = now(CLOCK_MONOTONIC);
    cpu = now(CLOCK_PROCESS_CPUTIME_ID);
}
static void stop(const char *kind, long n)
{
    printf("%s %.6g %.6g\n", kind, n / (now(CLOCK_MONOTONIC) - wall),
           n / (now(CLOCK_PROCESS_CPUTIME_ID) - cpu));
}

int main(int argc, char **argv)
{
    char msg[1024];
    swtwpm *model;
    double loads[8], lo, hi, sum = 0, *w, *s, *t;
    long i, n;
    int set, count;
    if (argc != 4 || swtwpm_open(argv[1], &model, msg, sizeof msg) < 0) {
        fprintf(stderr, "%s\n", argc == 4 ? msg : "usage: bench_queries WPM.csv MULTIPASS N");
        return 2;
    }
    set = swtwpm_select(model, NULL, NULL, atoll(argv[2]), msg, sizeof msg);
    n = atol(argv[3]);
    count = swtwpm_tested_loads(model, set, SWTWPM_DP_N, loads, 8);
    if (set < 0 || count < 1 || swtwpm_slip_range(model, set, SWTWPM_DP_N, &lo, &hi) < 0) {
        fprintf(stderr, "%s\n", msg);
        return 2;
    }
    w = malloc(n * sizeof *w);
    s = malloc(n * sizeof *s);
    t = malloc(n * sizeof *t);
    srand(1);
    for (i = 0; i < n; ++i) {
        w[i] = loads[0] + (loads[count - 1] - loads[0]) * (rand() / (RAND_MAX + 1.0));
        s[i] = lo + (hi - lo) * (rand() / (RAND_MAX + 1.0));
        t[i] = -10.0 + 60.0 * (rand() / (RAND_MAX + 1.0));
    }
    start();
    for (i = 0; i < n; ++i) {
        double v;
        swtwpm_value(model, set, SWTWPM_DP_N, w[i], s[i], 0, &v, NULL, 0);
        sum += v;
    }
    stop("forward", n);
    start();
    for (i = 0; i < n; ++i) {
        double slip, v;
        int status;
        swtwpm_slip_for(model, set, SWTWPM_DP_N, w[i], t[i], 0, &slip, &v, &status, NULL, 0);
        sum += v;
    }
    stop("inverse", n);
    start();
    for (i = 0; i < n / 100; ++i) {
        double v, c, p;
        swtwpm_value_band(model, set, SWTWPM_DP_N, w[i], s[i], 0, &v, &c, &p, NULL, 0);
        sum += c;
    }
    stop("band", n / 100);
    fprintf(stderr, "checksum %g\n", sum);
    free(w);
    free(s);
    free(t);
    swtwpm_free(model);
    return 0;
}
