/* What the interleaved-round benchmarks share: a monotonic clock and the order of doubles for
 * the medians and quartiles of their ratios. */
#ifndef GALPHA_BENCH_ROUNDS_H
#define GALPHA_BENCH_ROUNDS_H

#include <time.h>

static inline double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static inline int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif
