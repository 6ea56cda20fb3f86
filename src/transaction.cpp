// The step transaction: ga_step, ga_step_adaptive and ga_advance as the solver runs them, and
// the one place that knows the services' order (PETSc's TSSolve loop). A step (take_step,
// adaptive_step: the kernel's attempt, its error estimate, the forward sensitivities' linear
// step, the commit with the adjoint's record) is followed by the services after a commit --
// the event search (EventSet, events.cpp), then the step hook (StepHook, step_hook.cpp) --
// which see it through StepOutput. A service that fails returns its status; the transaction
// undoes the step (undo_step) and each service puts back its own work (EventSet::restore).
#include <exception>
#include <new>

#include "solver.hpp"

namespace ga {

// ---- what the services see (step_output.hpp) ----
double Solver::time() const { return k_.state().t; }
const double *Solver::positions() const { return k_.state().q.data(); }
const double *Solver::velocities() const { return k_.state().v.data(); }
const double *Solver::first_order_states() const { return k_.state().y.data(); }
ga_status Solver::multipliers(double *lambda) { return k_.output_state(nullptr, lambda); }
ga_status Solver::interpolate_at(double t, double *q, double *v, double *lambda)
{
    return k_.interpolate(t, q, v, nullptr, lambda);
}
ga_status Solver::interpolate_y_at(double t, double *y) { return k_.interpolate_y(t, y, nullptr); }
Model &Solver::callbacks() { return k_.model; }

// ---- the doors of a step: the kernel opens the first six (StepDoors), the transaction the
// last two ----
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
        forward_.sens.allocate_matrices(k_.matrix(GA_MATRIX_MASS), k_.matrix(GA_MATRIX_JACOBIAN));
}
// Before an attempt: the forward sensitivities start by differences before Taylor slivers
// and fresh starts.
ga_status Solver::before_attempt(const StepPlan &plan)
{
    return forward_.sens.active() ? forward_.before_attempt(plan, k_.state()) : GA_OK;
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
        k_.invalidate_jacobian();
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

// ---- a step without events: fixed, or adaptive ----
// The Newton tolerance the user gave, or: 1e-10 for fixed steps (far below any discretization
// error worth computing), and in adaptive mode a tenth of the local error tolerance (rtol times
// its calibration, step_controller.hpp): at 1e-2 rtol it spoiled the calibrated control in
// index 3. With a tolerance on the error, iterating the Newton error much further below it buys
// nothing (IDA and Radau5 tie their Newton tests to the error tolerance too).
double Solver::newton_tolerance(bool adaptive) const
{
    constexpr double kFixedStep = 1e-10, kFractionOfLocal = 0.1;
    if (k_.newton_tol > 0.0)
        return k_.newton_tol;
    return adaptive ? kFractionOfLocal * control.rtol * control.calibration() : kFixedStep;
}

ga_status Solver::take_step(double h)
{
    // Every exit that is not a commit counts as a failed step, exceptions included.
    struct FailedStepCounter {
        Counters &c;
        bool committed = false;
        ~FailedStepCounter()
        {
            if (!committed)
                count(c, GA_COUNT_FAILED_STEPS);
        }
    } failed{k_.counters};
    ga_status st = k_.attempt_step(h, newton_tolerance(false), true, false);
    if (!st)
        st = on_converged(h);
    if (st != GA_OK) {
        // Whatever went wrong, the next attempt starts from a fresh iteration matrix.
        k_.invalidate_jacobian();
        return st;
    }
    k_.commit(false, 0.0);
    failed.committed = true;
    return GA_OK;
}

namespace {
bool recoverable(ga_status st)
{
    return st == GA_ERR_NEWTON || st == GA_ERR_CALLBACK_RETRY || st == GA_ERR_NONFINITE ||
           st == GA_ERR_SINGULAR || st == GA_ERR_UNRESOLVED;
}
}  // namespace

ga_status Solver::adaptive_step(double t_stop)
{
    // In index 3 every change of h starts a transient in qdd and lambda whose recursion has
    // the double root -alpha_f/(1 - alpha_f) (docs/algorithms.md sec. 1.4, 6.2): -rho_inf, so at
    // rho_inf = 1 (alpha_f = 1/2) it never decays, and every change of h adds to it. Even with
    // an error estimate blind to it, such runs lose their accuracy and their steps
    // (design-notes.md, "No adaptive steps in index 3 at rho_inf = 1"). Refused at once
    // instead; a system without constraints has no such transient.
    if (k_.formulation == GA_INDEX3 && k_.m() > 0 && !(k_.params.alpha_f < 0.5))
        return k_.diag.fail(GA_ERR_ARG,
                            "adaptive steps in the index-3 formulation need rho_inf < 1 "
                            "(alpha_f = %g): each change of h starts a transient of the "
                            "multipliers that rho_inf = 1 never damps, and the run would lose its "
                            "accuracy and its step size; use the stabilized index-2 formulation "
                            "(ga_set_formulation) or rho_inf < 1",
                            k_.params.alpha_f);
    k_.setup_estimate();
    const State &accepted = k_.state();
    const double t = accepted.t;
    const double remaining = t_stop - t;
    if (!(remaining > 0.0))
        return k_.diag.fail(GA_ERR_ARG, "t_stop = %.17g is not after t = %.17g", t_stop, t);
    double h = control.h_next;
    if (!(h > 0.0)) {
        // First step: the weighted RMS norms of qdd and v at the start (each coordinate
        // against its calibrated atol + rtol |q_i|), from which the controller proposes.
        const double scale = control.calibration();
        double acc = 0.0, vel = 0.0;  // |qdd|_w^2, |v|_w^2
        const int nv = k_.nv();
        for (int i = 0; i < nv; ++i) {
            const double w =
                scale * (control.atol_q(i) + control.rtol * k_.model.space.magnitude(accepted.q, i));
            acc += (accepted.qdd[i] / w) * (accepted.qdd[i] / w);
            vel += (accepted.v[i] / w) * (accepted.v[i] / w);
        }
        acc = std::sqrt(acc / nv);
        vel = std::sqrt(vel / nv);
        h = control.first_step(acc, vel, remaining);
    }
    const double h_min = control.minimum_step(t);
    h = control.bounded(h, h_min);
    const double tol = newton_tolerance(true);
    bool rejected = false;
    // the last recoverable failure, said again if the steps shrink below h_min because of it
    // (a failing callback ended in "step size fell below the minimum" alone)
    char last_failure[Diagnostics::kSize] = "";
    for (;;) {
        bool land = false;
        const double h_planned = h;
        h = control.approach(h, remaining, rejected, land);
        if (h < h_min && !land) {
            k_.diag.fail(GA_ERR_STEP_SIZE,
                         "step size %g fell below the minimum %g at t = %.17g (last error "
                         "estimate %.3g)",
                         h, h_min, t, control.err_last);
            if (last_failure[0] != '\0')
                k_.diag.append("; the last attempt failed: %s", last_failure);
            return GA_ERR_STEP_SIZE;
        }
        // A sliver is a Taylor step (sliver_step) only when it lands on t_stop; retries after
        // failures stay under error control.
        ga_status st = k_.attempt_step(h, tol, land, true);
        double err = 0.0;
        if (st == GA_OK)
            st = k_.error_norm(h, land ? t_stop : k_.trial().t, control, err);
        if (st == GA_OK) {
            control.err_last = err;
            if (err <= 1.0) {
                if (auto st2 = on_converged(h)) {  // of the accepted step only
                    count(k_.counters, GA_COUNT_FAILED_STEPS);
                    k_.invalidate_jacobian();
                    return st2;
                }
                const double h_prev = accepted.h_last;  // the accepted step before this one
                k_.commit(land, t_stop);
                k_.estimate_is_output();
                control.accept(err, h, h_planned, h_prev, land, rejected);
                return GA_OK;
            }
            count(k_.counters, GA_COUNT_REJECTED_STEPS);
            last_failure[0] = '\0';
            on_rejection();
            h = StepController::after_rejection(h, err);
        } else if (recoverable(st)) {
            count(k_.counters, GA_COUNT_FAILED_STEPS);
            k_.invalidate_jacobian();
            k_.diag.copy_to(last_failure);
            h = StepController::after_failure(h);
        } else {
            count(k_.counters, GA_COUNT_FAILED_STEPS);
            k_.invalidate_jacobian();
            return st;
        }
        rejected = true;
    }
}

void Solver::undo_step(const StepUndo &u)
{
    k_.undo_step(u.previous_valid, u.start_pending);
    if (u.adaptive)
        control = undo_control_;
}

// ---- the calls ----
ga_status Solver::step(double h) { return hooked(false, h, &Solver::one_step); }

ga_status Solver::step_adaptive(double t_stop)
{
    return hooked(true, t_stop, &Solver::one_adaptive_step);
}

ga_status Solver::advance(double t_out)
{
    if (t_out < k_.state().t)
        return diag.fail(GA_ERR_ARG, "t_out = %.17g is before t = %.17g", t_out, k_.state().t);
    if (!events_.active()) {
        while (k_.state().t < t_out)
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
    while (k_.state().t < t_out) {
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
    const StepUndo undo = undo_point(adaptive);
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
    const StepUndo undo = undo_point(false);
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
void Solver::set_step_hook(const StepHook &hook) { hook_.assign(hook, k_.m()); }

ga_status Solver::hooked(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    try {
        return hooked_step(adaptive, arg, step);
    } catch (...) {  // a C++ callback threw: the step failed, and drops the kept matrix as such
        k_.invalidate_jacobian();
        throw;
    }
}

// (this->*step)(arg), then the hook if a step was accepted; a failure of the hook's
// multipliers or a throwing hook undoes that step.
ga_status Solver::hooked_step(bool adaptive, double arg, ga_status (Solver::*step)(double))
{
    if (!hook_.active())
        return (this->*step)(arg);
    const double t_before = k_.state().t;
    const StepUndo undo = undo_point(adaptive);
    const StepController control_before = control;
    if (events_.active())
        events_.save();
    const ga_status st = (this->*step)(arg);
    if (st < GA_OK || k_.state().t == t_before)  // failed, or stopped before stepping
        return st;
    bool stop = false;
    if (const ga_status failed = hook_.after_step(*this, diag, k_.m(), stop)) {
        undo_control_ = control_before;
        undo_step(undo);
        if (events_.active())
            events_.restore();
        return failed;
    }
    return stop && st == GA_OK ? GA_STOPPED : st;
}

}  // namespace ga
