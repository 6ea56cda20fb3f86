// ga::State: one point of a run -- t, q, v, qdd, lambda, a and what the error estimate and
// first-order states keep with it. The solver holds three (accepted, trial, previous) and
// moves them by swaps, never by copies.
#pragma once

#include "types.hpp"

namespace ga {

struct State {
    double t = 0.0;
    double h_last = 0.0;  // size of the step that produced this state (0 at the start)
    // Time covered by Taylor steps (sliver_step) since the last step of Algorithm 1: once it
    // passes h_last / kShortStepRatio, short steps are Algorithm 1 steps again.
    double sliver_span = 0.0;
    Vec q, v, qdd, lambda, a;
    Vec a_prev;           // a of the state before (variable-step error estimate)
    // Index-3 adaptive steps (error_estimate.cpp): qdd consistent with (q, v) here (c) and at the
    // state before (c_prev), c_dt apart; c_count of them known (0-2; 0 after a fixed step).
    Vec c, c_prev;
    double c_dt = 0.0;
    int c_count = 0;
    // First-order states (docs/algorithms.md sec. 9): y, y' = g, the auxiliary w of y' (as a
    // is of qdd) and w of the state before; empty when r = 0.
    Vec y, ydot, w, w_prev;

    void allocate(int nq, int nv, int m);  // q: nq; v, qdd, a, a_prev, c, c_prev: nv
    void allocate_first_order(int r);
    void swap(State &other);  // pointer swaps only: no allocation, no copy
};

}  // namespace ga
