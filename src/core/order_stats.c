/* fovea — order statistics of timings (core/order_stats.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/order_stats.h"

int fv_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

double fv_median(const double *v, int n)
{
    double *c = malloc((size_t)n * sizeof *c);
    if (!c) return v[0];
    memcpy(c, v, (size_t)n * sizeof *c);
    qsort(c, (size_t)n, sizeof *c, fv_cmp_double);
    double m = n % 2 ? c[n / 2] : 0.5 * (c[n / 2 - 1] + c[n / 2]);
    free(c);
    return m;
}

double fv_percentile(double *v, int n, double q)
{
    qsort(v, (size_t)n, sizeof *v, fv_cmp_double);
    int k = (int)ceil(q / 100.0 * n) - 1;
    return v[k < 0 ? 0 : k >= n ? n - 1 : k];
}
