/* fovea — order statistics of timings: the median of a bench row's repeats and the percentiles of
 * its frame times (docs/bench.md, "Frame pacing"), and `fovea bench scaling`'s p50/p99. One
 * definition, so that every report's p50 and p99 mean the same thing. */
#ifndef FV_CORE_ORDER_STATS_H
#define FV_CORE_ORDER_STATS_H

/* qsort's comparison of doubles, ascending. */
int fv_cmp_double(const void *a, const void *b);

/* The median of n > 0 values: the middle one, or the mean of the two middle ones when n is even.
 * v is left as it is (a copy is sorted; v[0] when the copy cannot be made). */
double fv_median(const double *v, int n);

/* The nearest-rank percentile q (0..100) of n > 0 values, sorted in place: the smallest value
 * with at least q% of the values at or below it, v[ceil(q/100 n) - 1] (q = 0: the least). Never
 * interpolated: it is always one of the values, so a p99 over fewer than 100 frames is the worst
 * frame, and p50 of an even count is the lower middle value (not fv_median's mean). */
double fv_percentile(double *v, int n, double q);

#endif
