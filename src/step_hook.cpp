// The step hook (step_hook.hpp).
#include "step_hook.hpp"

#include <exception>
#include <new>

#include "model.hpp"

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

void StepHook::assign(const StepHook &from, int m)
{
    Vec lambda(from.with_lambda ? m : 0);
    fn = from.fn;
    user = from.user;
    handle = from.handle;
    running = from.running;
    with_lambda = from.with_lambda;
    lambda_.swap(lambda);
}

ga_status StepHook::after_step(StepOutput &out, Diagnostics &diag, int m, bool &stop)
{
    stop = false;
    const double *lambda = nullptr;
    if (with_lambda && m > 0) {
        if (ga_status e = out.multipliers(lambda_.data())) {
            diag.append(" (the step hook's multipliers)");
            return e;
        }
        lambda = lambda_.data();
    }
    const double t = out.time();
    int rc = 0;
    try {
        HookRunning hook_running(running);
        rc = out.callbacks().run_user(
            [&] { return fn(handle, t, out.positions(), out.velocities(), lambda, user); });
    } catch (const std::bad_alloc &) {
        return diag.fail(GA_ERR_NOMEM, "out of memory in the step hook at t = %.17g", t);
    } catch (const std::exception &e) {
        return diag.fail(GA_ERR_INTERNAL, "the step hook threw at t = %.17g: %s", t, e.what());
    } catch (...) {
        return diag.fail(GA_ERR_INTERNAL, "the step hook threw a C++ exception of unknown type "
                         "at t = %.17g", t);
    }
    stop = rc != 0;
    return GA_OK;
}

}  // namespace ga
