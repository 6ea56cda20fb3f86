// ga::StepHook: the user's function after every accepted step of ga_step, ga_step_adaptive and
// ga_advance (ga_set_step_hook). A service of the transaction (transaction.cpp): it sees the
// step through StepOutput, and the transaction undoes the step when the hook fails. Replays
// of the adjoint sweep step through attempt_step and never come here.
#pragma once

#include <atomic>

#include "diagnostics.hpp"
#include "step_output.hpp"
#include "types.hpp"

namespace ga {

class StepHook {
public:
    ga_step_hook_fn fn = nullptr;
    void *user = nullptr;
    const ga_solver *handle = nullptr;
    std::atomic<bool> *running = nullptr;  // the handle's flag: reads allowed from the hook
    bool with_lambda = false;

    bool active() const { return fn != nullptr; }
    // Takes the hook of `from`, with room for m multipliers if it asks for them; throws
    // std::bad_alloc, leaving the hook as it was.
    void assign(const StepHook &from, int m);
    // The function on the step just committed: GA_OK (stop: it asked the run to stop), or
    // the failure of its multipliers or of the hook itself (a C++ exception), with a message.
    ga_status after_step(StepOutput &out, Diagnostics &diag, int m, bool &stop);

private:
    Vec lambda_;  // the multipliers the hook sees, its own: reads from the hook reuse the output's
};

}  // namespace ga
