// Shared vocabulary of the core: Eigen types and the work counters.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <cstddef>
#include <vector>

#include "galpha.h"

namespace ga {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;  // column-major, as the C API promises
using Counters = std::array<long long, GA_COUNTER_COUNT>;

inline void count(Counters &c, ga_counter key, long long by = 1) { c[key] += by; }

// true if no entry is Inf or NaN: x * 0 is 0 for every finite x and NaN otherwise, summed in
// four independent chains (the compiler pairs them into vector instructions); the test runs on
// every callback output and every increment of every Newton iteration.
inline bool all_finite(const double *x, Eigen::Index size)
{
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    Eigen::Index k = 0;
    for (; k + 4 <= size; k += 4) {
        a0 += x[k] * 0.0;
        a1 += x[k + 1] * 0.0;
        a2 += x[k + 2] * 0.0;
        a3 += x[k + 3] * 0.0;
    }
    for (; k < size; ++k)
        a0 += x[k] * 0.0;
    return (a0 + a1) + (a2 + a3) == 0.0;
}
inline bool all_finite(const Vec &x) { return all_finite(x.data(), x.size()); }

// Whether `count` blocks of `each` doubles fit in one std::vector<double>: sizes computed from
// a caller's counts are checked before they are multiplied, so that they never wrap.
inline bool fits_doubles(std::size_t count, std::size_t each)
{
    return each == 0 || count <= std::vector<double>().max_size() / each;
}

}  // namespace ga
