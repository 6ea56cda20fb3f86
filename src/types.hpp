// Shared vocabulary of the core: Eigen types and the work counters.
#pragma once

#include <Eigen/Dense>
#include <array>

#include "galpha.h"

namespace ga {

using Vec = Eigen::VectorXd;
using Mat = Eigen::MatrixXd;  // column-major, as the C API promises
using Counters = std::array<long long, GA_COUNTER_COUNT>;

inline void count(Counters &c, ga_counter key, long long by = 1) { c[key] += by; }

}  // namespace ga
