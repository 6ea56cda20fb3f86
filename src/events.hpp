// Event location on a step's interpolant (docs/algorithms.md sec. 12): the earliest root, over
// [t0, t1], among event functions whose sign changes in the requested direction, found by the
// Illinois variant of the secant method (Hiebert & Shampine; SUNDIALS IDA does the same) on
// values the caller interpolates, so that no step is ever taken again.
#pragma once

#include <vector>

namespace ga {

class EventLocator {
public:
    // Fills g (one value per function) at time t from the interpolant; 0 on success, anything
    // else is a failure that locate() returns unchanged.
    using Evaluate = int (*)(double t, double *g, void *context);

    // Storage for `count` functions (allocates; locate() does not).
    void setup(int count);
    int count() const { return static_cast<int>(lo_.size()); }

    // g0 = g(t0) and g1 = g(t1) are given. direction[k]: +1 rising only (from below zero to
    // zero or above), -1 falling only, 0 both; a function exactly zero at t0 does not fire
    // (it fired there already, or starts there). Returns 0 if nothing fires in (t0, t1],
    // 1 with *t_root (within 100 u (|t1| + |t1 - t0|) after the root, so that the root is
    // behind it) and fired[k] = +1 / -1 for the functions that cross by then, 0 for the
    // others; or the failure of `g`.
    int locate(double t0, const double *g0, double t1, const double *g1, const int *direction,
               Evaluate g, void *context, double *t_root, int *fired);

    int last_evaluations() const { return evaluations_; }

private:
    std::vector<double> lo_, hi_, mid_;
    int evaluations_ = 0;
};

}  // namespace ga
