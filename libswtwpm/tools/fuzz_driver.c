/* Fuzz driver of libswtwpm (bench/wpm_fuzz.py builds it with AddressSanitizer and UBSan):
 * reads the file names on standard input, one a line; opens each, and when it reads, asks
 * every set and quantity forward, band and inverse queries at edge loads, slips and targets
 * (inside, at and beyond the tested loads; NaN, infinite, zero, negative). Prints one line
 * per file: the open's return code, a tab, its message (empty when it read). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "swtwpm.h"

static void queries(const swtwpm *model)
{
    static const double slips[] = {-2.0, -1.0, -0.1, -0.0, 0.0, 1e-12, 0.2, 0.6, 1.0, 3.0};
    static const double targets[] = {-1e300, -50.0, -1.0, 0.0, 1e-3, 1.0, 10.0, 1e300};
    char msg[512];
    double geometry[5];
    int set, q, n_sets = swtwpm_set_count(model);
    swtwpm_select(model, NULL, NULL, -1, msg, sizeof msg);
    swtwpm_select(model, "x", NULL, 3, msg, sizeof msg);
    swtwpm_wheel_geometry(model, NULL, geometry, msg, sizeof msg);
    swtwpm_header(model, "format");
    for (set = 0; set < n_sets; ++set) {
        const char *soil, *wheel;
        long long multipass;
        swtwpm_set_info(model, set, &soil, &wheel, &multipass);
        swtwpm_select(model, soil, wheel, multipass, msg, sizeof msg);
        swtwpm_wheel_geometry(model, wheel, geometry, msg, sizeof msg);
        for (q = -1; q <= SWTWPM_N_QUANTITIES; ++q) {
            double loads[16], tested[4], lo = 0, hi = 0;
            int n_tested = swtwpm_tested_loads(model, set, q, tested, 4), n = 0, i, j, flags;
            swtwpm_slip_range(model, set, q, &lo, &hi);
            if (n_tested > 0) {
                double first = tested[0], last = tested[(n_tested < 4 ? n_tested : 4) - 1];
                loads[n++] = first;
                loads[n++] = last;
                loads[n++] = 0.5 * (first + last);
                loads[n++] = 0.999 * first + 0.001 * last;
                loads[n++] = 0.5 * first;
                loads[n++] = 2.0 * last;
            }
            loads[n++] = NAN;
            loads[n++] = INFINITY;
            loads[n++] = 0.0;
            loads[n++] = -5.0;
            for (flags = 0; flags <= 1; ++flags)
                for (i = 0; i < n; ++i) {
                    swtwpm_curve curve;
                    double v, c, p, s;
                    int status;
                    swtwpm_curve_at(model, set, q, loads[i], flags, &curve, msg, sizeof msg);
                    for (j = 0; j < (int)(sizeof slips / sizeof *slips); ++j) {
                        swtwpm_value(model, set, q, loads[i], slips[j], flags, &v, msg,
                                     sizeof msg);
                        swtwpm_curve_eval(&curve, slips[j], &v, &c, &p);
                    }
                    swtwpm_curve_eval(&curve, NAN, &v, &c, &p);
                    swtwpm_value(model, set, q, loads[i], NAN, flags, &v, msg, sizeof msg);
                    swtwpm_value(model, set, q, loads[i], 0.5 * (lo + hi), flags, &v, msg,
                                 sizeof msg);
                    for (j = 0; j < (int)(sizeof targets / sizeof *targets); ++j)
                        swtwpm_slip_for(model, set, q, loads[i], targets[j], flags, &s, &v,
                                        &status, msg, sizeof msg);
                    swtwpm_value(model, set, q, loads[i], 0.3, flags, &v, msg, sizeof msg);
                    swtwpm_slip_for(model, set, q, loads[i], v, flags, &s, &v, &status, msg,
                                    sizeof msg);
                    swtwpm_slip_for(model, set, q, loads[i], NAN, flags, &s, &v, &status, msg,
                                    sizeof msg);
                }
        }
    }
}

int main(void)
{
    char path[4096];
    while (fgets(path, sizeof path, stdin)) {
        char msg[1024] = "";
        swtwpm *model = NULL;
        int code;
        path[strcspn(path, "\n")] = '\0';
        code = swtwpm_open(path, &model, msg, sizeof msg);
        if (code == 0)
            queries(model);
        swtwpm_free(model);
        msg[strcspn(msg, "\n")] = '\0';
        printf("%d\t%s\n", code, msg);
    }
    return 0;
}
