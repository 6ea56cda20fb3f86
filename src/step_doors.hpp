// ga::StepDoors: the points inside the kernel's own operations where the services of the step
// transaction attach (transaction.cpp implements them). The kernel calls them at fixed places
// and knows nothing of what stands behind: the forward sensitivities, the adjoint's record.
#pragma once

#include "galpha.h"

namespace ga {

struct State;
struct StepPlan;

class StepDoors {
public:
    // A start (ga_init): before the consistent accelerations (differences there leave the
    // matrices at a perturbed p), and once it is the accepted state.
    virtual ga_status on_start(const State &x) = 0;
    virtual void on_started() = 0;
    // At setup, once the matrices' layouts are known.
    virtual void on_setup() = 0;
    // Before an attempt is made as planned (Taylor steps and fresh starts included).
    virtual ga_status before_attempt(const StepPlan &plan) = 0;
    // A commit, after the states' swap (before the counters); its undoing, after the swaps.
    virtual void on_commit() = 0;
    virtual void on_undo() = 0;

protected:
    ~StepDoors() = default;
};

}  // namespace ga
