// Event location on a step's interpolant (docs/algorithms.md sec. 10): the earliest root, over
// [t0, t1], among event functions whose sign changes in the requested direction, found by the
// Illinois variant of the secant method (Hiebert & Shampine; SUNDIALS IDA does the same) on
// values the caller interpolates, so that no step is ever taken again.
#pragma once

#include <vector>

#include "galpha.h"
#include "step_output.hpp"

namespace ga {

// A function crosses zero from a to b in a direction it watches (+1 rising, -1 falling, 0
// both). One expression without early exits: it runs after every step.
inline bool crosses(double a, double b, int direction)
{
    return (a < 0.0 && b >= 0.0 && direction >= 0) || (a > 0.0 && b <= 0.0 && direction <= 0);
}
// +1 / -1: the direction of that crossing; 0: none.
inline int crossing(double a, double b, int direction)
{
    return crosses(a, b, direction) ? (a < 0.0 ? 1 : -1) : 0;
}

class EventLocator {
public:
    // Fills g (one value per function) at time t from the interpolant; 0 on success, anything
    // else is a failure that locate() returns unchanged.
    using Evaluate = int (*)(double t, double *g, void *context);

    // Storage for `count` functions (allocates; locate() does not).
    void setup(int count);
    int count() const { return static_cast<int>(lo_.size()); }

    // g0 = g(t0) and g1 = g(t1) are given (g0 may be the root_values() of the last call). direction[k]: +1 rising only (from below zero to
    // zero or above), -1 falling only, 0 both; a function exactly zero at t0 does not fire
    // (it fired there already, or starts there). Returns 0 if nothing fires in (t0, t1],
    // 1 with *t_root (within 100 u (|t1| + |t1 - t0|) after the root, so that the root is
    // behind it) and fired[k] = +1 / -1 for the functions that cross by then, 0 for the
    // others; or the failure of `g`.
    int locate(double t0, const double *g0, double t1, const double *g1, const int *direction,
               Evaluate g, void *context, double *t_root, int *fired);

    int last_evaluations() const { return evaluations_; }
    // g at the *t_root of the last locate() that found one.
    const double *root_values() const { return hi_.data(); }

private:
    std::vector<double> lo_, hi_, mid_;
    int evaluations_ = 0;
};

// The event functions a solver watches (ga_set_events), where their search stands, and the
// log of one stepping call. The search covers the accepted steps one after the other: [t_lo,
// t_hi] is the part of the last step not yet searched (empty once it is done), g_lo and g_hi
// the values at its ends.
class EventSet {
public:
    struct Entry {
        double t;
        int index, direction;
    };

    // Allocates everything the search needs (count 0: no events); throws std::bad_alloc.
    // fn_y instead of fn: the functions see the first-order states (r of them) too.
    void configure(int count, ga_event_fn fn, ga_event_y_fn fn_y, const int *direction,
                   const int *terminal, bool with_lambda, int nq, int nv, int m, int r);
    int count() const { return static_cast<int>(direction_.size()); }
    bool active() const { return count() > 0; }
    ga_event_fn fn() const { return fn_; }
    ga_event_y_fn fn_y() const { return fn_y_; }
    bool with_lambda() const { return with_lambda_; }
    const int *direction() const { return direction_.data(); }
    bool terminal(int k) const { return terminal_[k] != 0; }

    // The search starts again from the state at the next stepping call; the log of a state
    // left behind goes with it.
    void restart()
    {
        started = false;
        log_count_ = 0;
    }

    // A stepping call starts with an empty log; save() keeps where the search stands (and the
    // log's length) so that restore() can put it back when a step fails.
    void clear_log() { log_count_ = 0; }
    void save();
    void restore();

    // The search, on what the step offers (step_output.hpp); each returns GA_EVENT when a
    // terminal function fired or the log filled, a failure leaving t_lo and g_lo as they were
    // (restore() puts back the rest).
    // At the start of a stepping call: g at the state if the search starts afresh, else the
    // rest of the step a call stopped in.
    ga_status resume(StepOutput &out);
    // After a step was committed: g at its end, and the search over it.
    ga_status after_step(StepOutput &out);

    int capacity() const { return static_cast<int>(log_.size()); }
    bool log_full() const { return log_count_ == capacity(); }
    // Some function crosses zero, in the direction it watches, between the values a and b.
    bool any_crossing(const double *a, const double *b) const
    {
        for (int k = 0; k < count(); ++k)
            if (crosses(a[k], b[k], direction_[k]))
                return true;
        return false;
    }
    void log(double t, int index, int direction) { log_[log_count_++] = {t, index, direction}; }
    int logged() const { return log_count_; }
    const Entry &entry(int i) const { return log_[i]; }

    bool started = false;  // g_lo holds g at t_lo
    double t_lo = 0.0, t_hi = 0.0;
    std::vector<double> g_lo, g_hi;
    std::vector<double> q, v, lambda, y;  // the interpolated state g is evaluated at
    std::vector<double> g_past, g_start;  // g just past t_lo, and the search's start values
    EventLocator locator;
    std::vector<int> fired;

private:
    ga_status values(StepOutput &out, double t, double *g);
    ga_status start_values(StepOutput &out, const double **start);
    ga_status search(StepOutput &out);

    ga_event_fn fn_ = nullptr;
    ga_event_y_fn fn_y_ = nullptr;
    bool with_lambda_ = false;
    std::vector<int> direction_, terminal_;
    std::vector<Entry> log_;
    int log_count_ = 0;
    // what save() kept
    bool saved_started_ = false;
    double saved_t_lo_ = 0.0, saved_t_hi_ = 0.0;
    int saved_log_count_ = 0;
    bool saved_values_ = false;
    std::vector<double> saved_g_lo_, saved_g_hi_;
};

}  // namespace ga
