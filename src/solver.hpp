// ga::Solver: the state (t, q, v, qdd, lambda, a), the options, and one step of Algorithm 1
// with commit/rollback and the reuse of the iteration matrix. The consistent start lives in
// init.cpp.
#pragma once

#include <cstddef>

#include "diagnostics.hpp"
#include "linear/iteration_matrix.hpp"
#include "model.hpp"
#include "newton.hpp"
#include "params.hpp"

namespace ga {

struct State {
    double t = 0.0;
    double h_last = 0.0;  // size of the step that produced this state (0 at the start)
    Vec q, v, qdd, lambda, a;

    void allocate(int n, int m);
    void swap(State &other);  // pointer swaps only: no allocation, no copy
};

class Solver {
public:
    Solver(int n, int m);

    int n() const { return n_; }
    int m() const { return m_; }

    // Options (validated by the C API before they get here).
    Params params;
    double newton_tol = 1e-10;
    int max_iter = 20;
    bool scaling = true;
    ga_predictor predictor = GA_PREDICTOR_EXTRAPOLATE;
    ga_init_mode init_mode = GA_INIT_PROJECT;
    double init_tol = 1e-10;
    ga_reuse_mode reuse = GA_REUSE_AUTO;
    ga_linear_solver linear_solver = GA_LINEAR_AUTO;

    Counters counters{};
    Diagnostics diag;
    Model model;

    // Layout of the user's matrices (dense unless a pattern was declared); fixed at setup.
    ModelMatrix &matrix(ga_matrix which);
    bool setup_done() const { return workspace_ready_; }
    const char *linear_backend() const { return S_.backend_name(); }

    bool initialized() const { return initialized_; }
    const State &state() const { return accepted_; }

    ga_status init(double t0, const double *q0, const double *v0);  // init.cpp
    ga_status step(double h);

    // Anything that changes the iteration matrix (options, callbacks) calls this.
    void invalidate_jacobian() const
    {
        jacobian_valid_ = false;
        theta_prev_ = -1.0;
        mass_valid_ = false;
        refresh_steps_left_ = 0;
        reuse_backoff_ = 1;
    }

    // For bench/: the unavoidable work of a step, done once at the current state -- one
    // residual evaluation (callbacks and r^q, r^lambda) and one solve with the factorization
    // at hand (made first if there is none). The per-step cost is measured against it.
    ga_status unavoidable_work(double h);

    double last_rcond() const { return S_.rcond(); }
    int last_newton_iters() const { return last_newton_iters_; }
    double last_newton_ratio() const { return convergence_.ratio(); }

    // Checkpoint: [magic, version, n, m, t, h_last, q, v, qdd, lambda, a]. Taking one also
    // drops the reusable iteration matrix, so that the run continues exactly as a restart
    // from the checkpoint does (the matrix is not part of the state).
    std::size_t state_size() const;
    void get_state(double *buf) const;
    ga_status set_state(const double *buf, std::size_t len);

private:
    ga_status setup();  // chooses the backend and allocates everything; throws std::bad_alloc
    ga_status attempt_step(double h);
    ga_status newton(double h, bool refresh, bool &converged, bool &used_stale);
    ga_status evaluate_mass(double t, const Vec &q);
    ga_status project_positions(double t, Vec &q);                  // init.cpp
    ga_status project_velocities(double t, const Vec &q, Vec &v);   // init.cpp

    int n_, m_;
    bool initialized_ = false;
    bool workspace_ready_ = false;
    int last_newton_iters_ = 0;

    State accepted_;  // the last accepted step: never touched by a step that fails
    State trial_;     // the step being computed

    // Reuse of the factorized iteration matrix across iterations and steps.
    mutable bool jacobian_valid_ = false;
    mutable double theta_prev_ = -1.0;  // contraction rate seen with the current matrix
    mutable bool mass_valid_ = false;   // constant mass: M evaluated
    mutable int refresh_steps_left_ = 0;  // steps to start with a fresh matrix
    mutable int reuse_backoff_ = 1;       // ... after the next failed attempt to reuse
    bool reuse_attempted_ = false;        // this step started with an old matrix
    double jacobian_h_ = 0.0;

    // Step workspace, sized once.
    ModelMatrix M_, J_, K_, C_;
    Vec f_, phi_, rq_, dq_, dlambda_, c_;
    IterationMatrix S_;
    ConvergenceTest convergence_;
};

}  // namespace ga
