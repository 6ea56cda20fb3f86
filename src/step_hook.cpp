// The step hook (ga_set_step_hook): the user's function after every accepted step of ga_step,
// ga_step_adaptive and ga_advance. Replays of the adjoint sweep step through attempt_step and
// never come here.
#include <exception>
#include <new>

#include "solver.hpp"

namespace ga {

namespace {
// The handle's flag, up while the hook runs: read-only calls are let in (capi.cpp).
class HookRunning {
public:
    explicit HookRunning(std::atomic<bool> *flag) : flag_(flag)
    {
        if (flag_)
            flag_->store(true);
    }
    ~HookRunning()
    {
        if (flag_)
            flag_->store(false);
    }
    HookRunning(const HookRunning &) = delete;
    HookRunning &operator=(const HookRunning &) = delete;

private:
    std::atomic<bool> *flag_;
};
}  // namespace

void Solver::set_step_hook(const StepHook &hook)
{
    Vec lambda(hook.with_lambda ? m_ : 0);
    hook_ = hook;
    hook_lambda_.swap(lambda);
}

ga_status Solver::step(double h)
{
    return hooked(false, h, &Solver::one_step);
}

ga_status Solver::step_adaptive(double t_stop)
{
    return hooked(true, t_stop, &Solver::one_adaptive_step);
}

ga_status Solver::hooked(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    try {
        return hooked_step(adaptive, arg, step);
    } catch (...) {  // a C++ callback threw: the step failed, and drops the kept matrix as such
        invalidate_jacobian();
        throw;
    }
}

ga_status Solver::hooked_step(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    if (!hook_.fn)
        return (this->*step)(arg);
    const double t_before = accepted_.t;
    const StepUndo undo{previous_valid_, start_pending_, adaptive};
    const StepController control_before = control;
    if (events_.active())
        events_.save();
    const ga_status st = (this->*step)(arg);
    if (st < GA_OK || accepted_.t == t_before)  // failed, or stopped before stepping
        return st;
    auto undo_this_step = [&] {
        undo_control_ = control_before;
        undo_step(undo);
        if (events_.active())
            events_.restore();
    };
    const double *lambda = nullptr;
    if (hook_.with_lambda && m_ > 0) {
        if (ga_status e = output_state(nullptr, nullptr)) {
            diag.append(" (the step hook's multipliers)");
            undo_this_step();
            return e;
        }
        hook_lambda_ = output == GA_OUTPUT_CONSISTENT ? out_lambda_ : accepted_.lambda;
        lambda = hook_lambda_.data();
    }
    const double t = accepted_.t;
    int rc = 0;
    try {
        HookRunning running(hook_.running);
        rc = model.run_user([&] {
            return hook_.fn(hook_.handle, t, accepted_.q.data(), accepted_.v.data(), lambda,
                            hook_.user);
        });
    } catch (const std::bad_alloc &) {
        undo_this_step();
        return diag.fail(GA_ERR_NOMEM, "out of memory in the step hook at t = %.17g", t);
    } catch (const std::exception &e) {
        undo_this_step();
        return diag.fail(GA_ERR_INTERNAL, "the step hook threw at t = %.17g: %s", t, e.what());
    } catch (...) {
        undo_this_step();
        return diag.fail(GA_ERR_INTERNAL, "the step hook threw a C++ exception of unknown type "
                         "at t = %.17g", t);
    }
    if (rc != 0 && st == GA_OK)
        return GA_STOPPED;
    return st;
}

}  // namespace ga
