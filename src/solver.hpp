// ga::Solver: the state (t, q, v, qdd, lambda, a), the options, and one step of Algorithm 1
// with commit/rollback. The consistent start lives in init.cpp.
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
    ga_predictor predictor = GA_PREDICTOR_CONSTANT_A;
    ga_init_mode init_mode = GA_INIT_PROJECT;
    double init_tol = 1e-10;

    Counters counters{};
    Diagnostics diag;
    Model model;

    bool initialized() const { return initialized_; }
    const State &state() const { return accepted_; }

    ga_status init(double t0, const double *q0, const double *v0);  // init.cpp
    ga_status step(double h);

    double last_rcond() const { return S_.rcond(); }
    int last_newton_iters() const { return last_newton_iters_; }
    double last_newton_ratio() const { return convergence_.ratio(); }

    // Checkpoint: [magic, version, n, m, t, h_last, q, v, qdd, lambda, a].
    std::size_t state_size() const;
    void get_state(double *buf) const;
    ga_status set_state(const double *buf, std::size_t len);

private:
    void allocate_workspace();  // throws std::bad_alloc
    ga_status attempt_step(double h);
    ga_status project_positions(double t, Vec &q);                  // init.cpp
    ga_status project_velocities(double t, const Vec &q, Vec &v);   // init.cpp

    int n_, m_;
    bool initialized_ = false;
    bool workspace_ready_ = false;
    int last_newton_iters_ = 0;

    State accepted_;  // the last accepted step: never touched by a step that fails
    State trial_;     // the step being computed

    // Step workspace, sized once.
    Mat M_, C_, K_, Phi_q_;
    Vec f_, phi_, rq_, dq_, dlambda_, c_;
    IterationMatrix S_;
    ConvergenceTest convergence_;
};

}  // namespace ga
