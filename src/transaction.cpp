// The step transaction: ga_step, ga_step_adaptive and ga_advance as the solver runs them, and
// the one place that knows the services' order (LAYOUT: PETSc's TSSolve loop). A step
// (take_step, adaptive_step: the kernel, the forward sensitivities' linear step and the
// commit with the adjoint's record) is followed by the services after a commit -- the event
// search (EventSet, events.cpp), then the step hook (StepHook, step_hook.cpp) -- which see it
// through StepOutput. A service that fails returns its status; the transaction undoes the step
// (undo_step) and each service puts back its own work (EventSet::restore).
#include <exception>
#include <new>

#include "solver.hpp"

namespace ga {

// ---- what the services see (step_output.hpp) ----
double Solver::time() const { return accepted_.t; }
const double *Solver::positions() const { return accepted_.q.data(); }
const double *Solver::velocities() const { return accepted_.v.data(); }
const double *Solver::first_order_states() const { return accepted_.y.data(); }
ga_status Solver::multipliers(double *lambda) { return output_state(nullptr, lambda); }
ga_status Solver::interpolate_at(double t, double *q, double *v, double *lambda)
{
    return interpolate(t, q, v, nullptr, lambda);
}
ga_status Solver::interpolate_y_at(double t, double *y) { return interpolate_y(t, y, nullptr); }
Model &Solver::callbacks() { return model; }

// ---- the doors of a step (the kernel, solver.cpp and control.cpp, calls them) ----
// A start (ga_init): the sensitivities' initial derivatives, before the consistent
// accelerations; and once it is the accepted state, the sensitivities take theirs, the record
// its first entry, the event search starts afresh.
ga_status Solver::on_start(const State &x)
{
    return forward_.sens.active() ? forward_.start(x) : GA_OK;
}
void Solver::on_started()
{
    forward_.started();
    if (forward_.sens.adjoint)
        adjoint_.started();
    events_.restart();
}
// At setup, once the matrices' layouts are known: the sensitivities' matrices like them.
void Solver::on_setup()
{
    if (forward_.sens.active())
        forward_.sens.allocate_matrices(M_, J_);
}
// Before an attempt: the forward sensitivities start by differences before Taylor slivers
// and fresh starts.
ga_status Solver::before_attempt(const StepPlan &plan)
{
    return forward_.sens.active() ? forward_.before_attempt(plan, accepted_) : GA_OK;
}
// The attempt converged (and passed the error test): the record's room and how the step began,
// then the sensitivities' linear step; a failure of either fails the step.
ga_status Solver::on_converged(double h)
{
    if (!forward_.sens.active())
        return GA_OK;
    if (forward_.sens.adjoint)
        if (auto st = adjoint_.on_converged(h))
            return st;
    return forward_.step(h);
}
// An attempt's error was rejected: the adjoint's replays from a checkpoint cannot know the
// matrix the rejected attempt left, so the run drops it too.
void Solver::on_rejection()
{
    if (forward_.sens.adjoint)
        invalidate_jacobian();
}
// The commit (after the states' swap): the sensitivities swap theirs, the record logs the step.
void Solver::on_commit()
{
    if (!forward_.sens.active())
        return;
    forward_.on_commit();
    if (forward_.sens.adjoint)
        adjoint_.on_commit();
}
// undo_step (after its swaps): each puts back its own.
void Solver::on_undo()
{
    if (!forward_.sens.active())
        return;
    forward_.on_undo();
    if (forward_.sens.adjoint)
        adjoint_.on_undo();
}

// ---- the services' options ----
ga_status Solver::set_sensitivity(int np, double *p, const double *p_scale, int depends)
{
    const bool ready = workspace_ready_;
    forward_.set(np, p, p_scale, depends, nq_, nv_, m_, r(), ready ? &M_ : nullptr,
                 ready ? &J_ : nullptr);
    adjoint_.forget();  // the method is forward again (ga_set_sensitivity_method)
    return GA_OK;
}

ga_status Solver::set_sensitivity_start(int j, const double *dq0, const double *dv0)
{
    forward_.set_start(j, dq0, dv0, nv_);
    return GA_OK;
}

ga_status Solver::set_sensitivity_method(int methods, long max_steps)
{
    return adjoint_.set_method(methods, max_steps);
}

ga_status Solver::set_adjoint_checkpoints(long interval, long count)
{
    return adjoint_.set_checkpoints(interval, count);
}

ga_status Solver::adjoint_gradient(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ)
{
    return adjoint_.gradient(running, terminal, J, dJ);
}

// ---- the calls ----
ga_status Solver::step(double h) { return hooked(false, h, &Solver::one_step); }

ga_status Solver::step_adaptive(double t_stop)
{
    return hooked(true, t_stop, &Solver::one_adaptive_step);
}

ga_status Solver::advance(double t_out)
{
    if (t_out < accepted_.t)
        return diag.fail(GA_ERR_ARG, "t_out = %.17g is before t = %.17g", t_out, accepted_.t);
    if (!events_.active()) {
        while (accepted_.t < t_out)
            if (auto st = hooked(true, t_out, &Solver::adaptive_step))
                return st;
        return GA_OK;
    }
    events_.clear_log();
    events_.save();
    if (auto st = events_.resume(*this)) {
        if (st < 0)
            events_.restore();
        return st;
    }
    // each step is undone alone: those accepted before a failure stay, with their events
    while (accepted_.t < t_out) {
        events_.save();
        if (auto st = hooked(true, t_out, &Solver::adaptive_step_with_events))
            return st;
    }
    return GA_OK;
}

// ---- the event search after a step ----
// The caller saved the search (events_.save()) where a failure must put it back.
ga_status Solver::step_with_events(bool adaptive, double h_or_t_stop)
{
    const StepUndo undo{previous_valid_, start_pending_, adaptive};
    if (adaptive)
        undo_control_ = control;
    if (auto st = adaptive ? adaptive_step(h_or_t_stop) : take_step(h_or_t_stop)) {
        events_.restore();
        return st;
    }
    const ga_status st = events_.after_step(*this);
    if (st < 0) {
        undo_step(undo);
        events_.restore();
    }
    return st;
}

// ga_step and ga_step_adaptive with events: first the search from the current state or over
// the rest of the step a call stopped in, then one step and the search over it.
ga_status Solver::watched_step(bool adaptive, double h_or_t_stop)
{
    EventSet &e = events_;
    e.clear_log();
    e.save();
    if (!e.started || e.t_lo < e.t_hi) {
        if (auto st = e.resume(*this)) {
            if (st < 0)
                e.restore();
            return st;
        }
    }
    return step_with_events(adaptive, h_or_t_stop);
}

// ga_step with events. The common case -- the search stands at the end of the last step and
// the functions need no multipliers -- goes without save points: a failure puts back what
// it changed (the step, t_hi, the log) from what it knows.
ga_status Solver::one_step(double h)
{
    EventSet &e = events_;
    if (!e.active())
        return take_step(h);
    if (!e.started || e.t_lo < e.t_hi || e.with_lambda())
        return watched_step(false, h);
    e.clear_log();
    const StepUndo undo{previous_valid_, start_pending_, false};
    if (auto st = take_step(h))
        return st;
    const ga_status st = e.after_step(*this);
    if (st >= GA_OK)
        return st;
    undo_step(undo);
    e.t_hi = e.t_lo;  // the search leaves t_lo and g_lo alone when it fails
    e.clear_log();
    return st;
}

ga_status Solver::one_adaptive_step(double t_stop)
{
    return events_.active() ? watched_step(true, t_stop) : adaptive_step(t_stop);
}

// ---- the step hook after the events ----
void Solver::set_step_hook(const StepHook &hook) { hook_.assign(hook, m_); }

ga_status Solver::hooked(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    try {
        return hooked_step(adaptive, arg, step);
    } catch (...) {  // a C++ callback threw: the step failed, and drops the kept matrix as such
        invalidate_jacobian();
        throw;
    }
}

// (this->*step)(arg), then the hook if a step was accepted; a failure of the hook's
// multipliers or a throwing hook undoes that step.
ga_status Solver::hooked_step(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    if (!hook_.active())
        return (this->*step)(arg);
    const double t_before = accepted_.t;
    const StepUndo undo{previous_valid_, start_pending_, adaptive};
    const StepController control_before = control;
    if (events_.active())
        events_.save();
    const ga_status st = (this->*step)(arg);
    if (st < GA_OK || accepted_.t == t_before)  // failed, or stopped before stepping
        return st;
    bool stop = false;
    if (const ga_status failed = hook_.after_step(*this, diag, m_, stop)) {
        undo_control_ = control_before;
        undo_step(undo);
        if (events_.active())
            events_.restore();
        return failed;
    }
    return stop && st == GA_OK ? GA_STOPPED : st;
}

}  // namespace ga
