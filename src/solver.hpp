// ga::Solver, the step transaction: it owns the step kernel (Stepper), the step-size
// controller, and the services -- forward sensitivities, the adjoint, the event search, the
// step hook -- and is the one place that knows their order (transaction.cpp). The kernel calls
// the services only at its doors (StepDoors); the services after a commit see the step through
// StepOutput.
#pragma once

#include <cstddef>

#include "adjoint.hpp"
#include "events.hpp"
#include "sensitivity.hpp"
#include "step_controller.hpp"
#include "step_doors.hpp"
#include "step_hook.hpp"
#include "step_output.hpp"
#include "stepper.hpp"

namespace ga {

class Solver : private StepOutput, private StepDoors {
    // First: the references below and the services are bound to it, which is defined only
    // once it is constructed.
    Stepper k_;

public:
    Solver(int n, int m) : Solver(ConfigurationSpace(n), m) {}
    Solver(const ConfigurationSpace &space, int m);
    Solver(const Solver &) = delete;
    Solver &operator=(const Solver &) = delete;

    // The kernel: the options, the state, the output; and its model and diagnostics, which
    // every call of the C API reaches.
    Stepper &kernel() { return k_; }
    const Stepper &kernel() const { return k_; }
    Diagnostics &diag;
    Model &model;
    StepController control;  // step sizes of adaptive mode (step_controller.hpp)

    // ga_init, ga_init_y (init.cpp: the kernel's consistent start, with the doors).
    ga_status init(double t0, const double *q0, const double *v0);
    ga_status init_y(double t0, const double *q0, const double *v0, const double *y0);
    // One step of size h; with events GA_EVENT when a terminal one fired.
    ga_status step(double h);
    // Adaptive mode: one controlled step, not beyond t_stop (landing on it exactly if it is
    // reached); or steps until t_out exactly.
    ga_status step_adaptive(double t_stop);
    ga_status advance(double t_out);

    // Forward sensitivities (ForwardSensitivity, sensitivity.cpp): the C API validated the
    // arguments; allocates (std::bad_alloc leaves the set before).
    const Sensitivities &sens() const { return forward_.sens; }
    ga_status set_sensitivity(int np, double *p, const double *p_scale, int depends);
    ga_status set_sensitivity_start(int j, const double *dq0, const double *dv0);
    // The adjoint (Adjoint, adjoint.cpp)
    ga_status set_sensitivity_method(int methods, long max_steps);
    ga_status adjoint_gradient(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ);
    ga_status set_adjoint_checkpoints(long interval, long count);

    // The step hook (ga_set_step_hook), called by step, step_adaptive and advance; throws
    // std::bad_alloc.
    void set_step_hook(const StepHook &hook);

    // Events (events.cpp): the functions watched, where their search stands, the last log.
    EventSet &events() { return events_; }
    const EventSet &events() const { return events_; }

    // ga_check_derivatives (derivative_check.cpp; the C API validated the pointers)
    ga_status check_derivatives(double t, const double *q, const double *v, const double *qdd,
                                const double *lambda, const double *y, double tol, double *worst);

    // Checkpoint (checkpoint.cpp, layout 4): the kernel's share with the controller's
    // entries, then the forward sensitivities' tail. internal: the adjoint sweep's own
    // restores into a recorded run; keep_matrix (internal): the kept iteration matrix is the
    // one of this checkpoint already (set aside and taken back): not rebuilt.
    std::size_t state_size() const;
    void get_state(double *buf) const;
    ga_status set_state(const double *buf, std::size_t len, bool internal = false,
                        bool keep_matrix = false);

private:
    // The doors (step_doors.hpp) and the two the transaction opens itself: an attempt that
    // converged and passed the error test (a failure fails the step), an attempt rejected.
    ga_status on_start(const State &x) override;
    void on_started() override;
    void on_setup() override;
    ga_status before_attempt(const StepPlan &plan) override;
    void on_commit() override;
    void on_undo() override;
    ga_status on_converged(double h);
    void on_rejection();

    // Newton's tolerance: the option, or automatic (a fraction of the local tolerance).
    double newton_tolerance(bool adaptive) const;
    ga_status take_step(double h);           // ga_step's step, without events
    ga_status adaptive_step(double t_stop);  // ga_step_adaptive's, likewise
    // What a step changes besides the states, so that a step whose event search fails after
    // its commit can be undone (the controller's state only after an adaptive step).
    struct StepUndo {
        bool previous_valid, start_pending, adaptive;
    };
    StepUndo undo_point(bool adaptive) const
    {
        return StepUndo{k_.previous_valid(), k_.start_pending(), adaptive};
    }
    StepController undo_control_;  // the controller before the step (adaptive steps)
    void undo_step(const StepUndo &u);
    // A step (take_step(h), or adaptive_step(t_stop) if adaptive) with the event search after
    // it; a failure of either leaves the solver as it was and the search as the caller saved
    // it.
    ga_status step_with_events(bool adaptive, double h_or_t_stop);
    ga_status adaptive_step_with_events(double t_stop) { return step_with_events(true, t_stop); }
    ga_status watched_step(bool adaptive, double h_or_t_stop);
    // ga_step's and ga_step_adaptive's step with events, before the step hook
    ga_status one_step(double h);
    ga_status one_adaptive_step(double t_stop);
    // (this->*step)(arg), then the step hook if a step was accepted; a failure of the hook's
    // multipliers or a throwing hook undoes that step.
    ga_status hooked(bool adaptive, double arg, ga_status (Solver::*step)(double));
    ga_status hooked_step(bool adaptive, double arg, ga_status (Solver::*step)(double));
    ga_status restore_state(const double *buf, std::size_t len, bool internal, bool keep_matrix);
    std::size_t sensitivity_tail() const;

    // What the services after a commit see (step_output.hpp)
    double time() const override;
    const double *positions() const override;
    const double *velocities() const override;
    const double *first_order_states() const override;
    ga_status multipliers(double *lambda) override;
    ga_status interpolate_at(double t, double *q, double *v, double *lambda) override;
    ga_status interpolate_y_at(double t, double *y) override;
    Model &callbacks() override;

    ForwardSensitivity forward_{k_};
    Adjoint adjoint_{k_, forward_, *this};
    EventSet events_;
    StepHook hook_;
};

}  // namespace ga
