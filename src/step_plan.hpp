// What one attempt of a step is to be (Stepper::plan_step, a pure decision) and how the step
// was attempted (the report attempt_step fills at each attempt, so that the accepted step's is
// the last attempt's): the kernel's account of itself, which the adjoint's record copies to
// repeat the step from a checkpoint.
#pragma once

namespace ga {

struct StepPlan {
    // Sliver: a Taylor step (Stepper::sliver_step); Regular: Algorithm 1 or its index-2 form
    enum Kind { Sliver, Regular };
    Kind kind = Regular;
    bool restart_short = false;  // Algorithm 1 afresh from what slivers left
    bool fresh = false;          // a fresh start: first step, long after short, restart_short
    double h = 0.0;
    double tol = 0.0;            // Newton's
    bool sliver_allowed = true;  // as asked by the caller
};

// The kept matrix's reuse state as an attempt begins: valid, theta, refresh steps left,
// backoff, finite-difference tangents (the adjoint log's entries 6 to 10).
constexpr int kReuseStateSize = 5;

struct StepReport {
    StepPlan plan;
    bool adaptive = false;  // an attempt of an adaptive step
    double reuse_before[kReuseStateSize] = {0, 0, 0, 0, 0};
};

}  // namespace ga
