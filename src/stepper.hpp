// ga::Stepper, the step kernel: the state (t, q, v, qdd, lambda, a), the options, one step of
// Algorithm 1 (or of its stabilized index-2 variant) with commit and rollback, the reuse of the
// iteration matrix, and the linearization the services need. The consistent start lives in
// init.cpp, the error estimate in error_estimate.cpp, dense output in dense_output.hpp and
// output.cpp. It knows no service: they attach at the doors (step_doors.hpp) of the
// transaction (solver.hpp, transaction.cpp).
#pragma once

#include <atomic>
#include <limits>
#include <cstddef>

#include "diagnostics.hpp"
#include "linear/index2_matrix.hpp"
#include "linear/iteration_matrix.hpp"
#include "model.hpp"
#include "newton.hpp"
#include "params.hpp"
#include "step_controller.hpp"
#include "step_doors.hpp"
#include "step_plan.hpp"
#include "tangent_product.hpp"
#include "dense_output.hpp"
#include "state.hpp"

namespace ga {

// The matrix and scratch of an acceleration-level solve (init.cpp): the step's own at the
// consistent start, separate ones for consistent output, so that reading the output never
// touches what the next step reuses.
struct SaddleWorkspace {
    IterationMatrix &K;
    ModelMatrix &M, &J;
    Vec &f, &c, &r;
    bool mass_given = false;      // M holds the constant mass matrix already
    bool mass_evaluated = false;  // set by the solve
    double sigma = 1.0;           // set by the solve: the first block row's scaling
};

// Puts a value back when the scope ends, however it ends: options an attempt changes for
// itself stay as they were when a C++ callback throws through it.
template <class T>
class Restore {
public:
    explicit Restore(T &x) : x_(x), value_(x) {}
    ~Restore() { x_ = value_; }
    Restore(const Restore &) = delete;
    Restore &operator=(const Restore &) = delete;

private:
    T &x_;
    T value_;
};

// The live run's kept iteration matrix (and the first-order blocks factorized with it),
// set aside while a sweep recomputes segments in matrices of their own (adjoint.cpp).
struct KeptMatrix {
    IterationMatrix S;
    Index2Matrix S2;
    CouplingBlocks blocks;
};

class Stepper {
public:
    Stepper(int n, int m) : Stepper(ConfigurationSpace(n), m) {}
    Stepper(const ConfigurationSpace &space, int m);  // (ga_create_space)
    void attach(StepDoors &doors) { doors_ = &doors; }  // (the transaction, before any call)
    Stepper(const Stepper &) = delete;  // (dense_ refers to its own states)
    Stepper &operator=(const Stepper &) = delete;

    int nq() const { return nq_; }  // q's coordinates
    int nv() const { return nv_; }  // v's, and those of every increment of q
    int m() const { return m_; }

    // Options (validated by the C API before they get here).
    Params params;
    // Newton tolerance (ga_set_newton); 0 = automatic, see newton_tolerance().
    double newton_tol = 0.0;
    int max_iter = 20;
    bool scaling = true;
    ga_predictor predictor = GA_PREDICTOR_EXTRAPOLATE;
    ga_init_mode init_mode = GA_INIT_PROJECT;
    double init_tol = 1e-10;
    ga_reuse_mode reuse = GA_REUSE_AUTO;
    ga_linear_solver linear_solver = GA_LINEAR_AUTO;
    ga_formulation formulation = GA_INDEX3;
    ga_redundancy redundancy = GA_REDUNDANT_REFUSE;
    ga_output output = GA_OUTPUT_CONSISTENT;
    bool rescale_a = true;
    bool corrected_start = true;
    // First-order states: the method's parameters (from rho_inf, or from alpha_f after
    // ga_set_params) and whether the coupling blocks are in the iteration matrix.
    FirstOrderParams params1;
    bool coupling_exact = true;
    // ga_set_resolution_check: the index-3 step's largest velocity-constraint residual
    // (resolution_check.cpp). Resolved runs stay below 3e-3 (the shipped scenes at every h where
    // they converge at order 2, a pendulum up to 0.25 rad per step at every rho_inf); the
    // rotating pendulum's energy was 7 % off when its residual crossed 0.02.
    static constexpr double kNoCheck = std::numeric_limits<double>::infinity();
    double max_velocity_residual = 0.02;
    int r() const { return model.first_order_count(); }
    // Declares r first-order states (before setup; allocates the states' vectors).
    void set_first_order(int r);
    // ga_init_y: ga_init with y0.
    ga_status init_y(double t0, const double *q0, const double *v0, const double *y0);
    ga_status interpolate_y(double t, double *y, double *ydot);

    Counters counters{};
    Diagnostics diag;
    Model model;

    // Layout of the user's matrices (dense unless a pattern was declared); fixed at setup.
    ModelMatrix &matrix(ga_matrix which);
    bool setup_done() const { return workspace_ready_; }
    // Allocates the stabilized index-2 system if the workspace exists and it does not yet;
    // throws std::bad_alloc.
    void setup_index2();
    const char *linear_backend() const;
    // Whether setup chooses (or chose) the sparse backend for these options and layouts (before
    // setup too: the operating points follow it); possible: the layouts allow it.
    bool sparse_wanted() const;
    bool sparse_possible() const;

    bool initialized() const { return initialized_; }
    // Constraints in use (1) or dropped as redundant (0); all 1 unless GA_REDUNDANT_DROP.
    bool constraint_active(int i) const { return active_.empty() || active_[i] != 0; }
    const State &state() const { return accepted_; }

    ga_status init(double t0, const double *q0, const double *v0);  // init.cpp
    // Output (output.cpp): qdd and lambda at the accepted state, consistent with (q, v) or the
    // step's own (ga_output); dense output inside the last step (any pointer may be null).
    // They evaluate callbacks in GA_OUTPUT_CONSISTENT, and do not touch what steps reuse.
    ga_status output_state(double *qdd, double *lambda);
    ga_status interpolate(double t, double *q, double *v, double *qdd, double *lambda);
    // Allocates the workspace of consistent output if the solver's workspace exists and it
    // does not yet; throws std::bad_alloc.
    void setup_output();

    // Anything that changes the iteration matrix (options, callbacks) calls this.
    void invalidate_jacobian() const
    {
        output_for_ = -1;
        out_mass_valid_ = false;
        jacobian_valid_ = false;
        theta_prev_ = -1.0;
        mass_valid_ = false;
        refresh_steps_left_ = 0;
        reuse_backoff_ = 1;
        fd_tangents_ = false;
    }

    // An option or callback that shapes the tangents changed (ga_set_tangents,
    // ga_set_tangent_mode, ga_set_constant_mass): a fresh matrix, and after setup the
    // finite-difference scratch the new choice needs, allocated here rather than in a step.
    // GA_ERR_ARG if the sparse path has no place for a tangent now needed; may throw
    // std::bad_alloc. The caller puts its option back when this fails.
    ga_status tangent_options_changed();

    // For bench/: the unavoidable work of a step, done once at the current state -- one
    // residual evaluation (callbacks and r^q, r^lambda) and one solve with the factorization
    // at hand (made first if there is none). The per-step cost is measured against it.
    ga_status unavoidable_work(double h);

    double last_rcond() const;
    int last_newton_iters() const { return last_newton_iters_; }
    double last_newton_ratio() const { return convergence_.ratio(); }
    double last_velocity_residual() const { return velocity_residual_; }
    // Checkpoint (checkpoint.cpp, layout 4): the state, the step-size control, and what
    // rebuilds the kept iteration matrix and the pivots of every sparse LU bit for bit, so
    // that taking one changes nothing and a restored run continues as the run it came from.
    // Layout 2 (galpha 0.2: the state and the control only) is read as a restart, layout 3
    // (no consistent accelerations for the index-3 error estimate) as a state without them.
    // The kernel's share: all but the step-size controller's entries 6-8 of the header, which
    // the transaction passes, and the forward sensitivities' tail after it.
    std::size_t checkpoint_size(bool layout3 = false) const;  // 4, or layout 3's; no tail
    void save_checkpoint(double *buf, const StepController &control) const;
    // Is buf (len doubles, `tail` of them the sensitivities' unless layout 2) a checkpoint this
    // solver can restore? Changes nothing but the diagnostics.
    ga_status check_checkpoint(const double *buf, std::size_t len, std::size_t tail);
    // Restores a checked one (setting the solver up if needed); control takes entries 6-8.
    // internal: the adjoint sweep's own restores into a recorded run; keep_matrix (internal):
    // the kept iteration matrix is the one of this checkpoint already (set aside and taken
    // back): not rebuilt
    ga_status load_checkpoint(const double *buf, bool internal, bool keep_matrix,
                              StepController &control);
    // The first ga_init, ga_init_y or ga_set_state sets the solver up; when it fails (an
    // exception included) it leaves it as before: not set up, so that what set-up fixes
    // (patterns, first-order states, the linear solver, redundancy) can still be declared.
    template <class Call>
    ga_status undoing_a_first_setup(Call &&call)
    {
        struct Undo {
            Stepper &s;
            bool was_set_up;
            ~Undo()
            {
                if (!was_set_up && !s.initialized_)
                    s.forget_setup();
            }
        } undo{*this, workspace_ready_};
        return call();
    }

    // ---- what the transaction runs (transaction.cpp) ----
    // One attempt of a step from the accepted state into the trial one, planned here, with
    // the door before_attempt (adaptive: an attempt of an adaptive step).
    ga_status attempt_step(double h, double tol, bool sliver_allowed, bool adaptive)
    {
        const Restore<bool> keep_mode(adaptive_attempt_);
        adaptive_attempt_ = adaptive;
        return attempt_step(h, tol, sliver_allowed);
    }
    const State &trial() const { return trial_; }
    // The trial state becomes the accepted one (landing on t_land exactly); the door on_commit.
    void commit(bool land_on, double t_land);
    // A committed step taken back: the states swapped back, the door on_undo, the flags as
    // they were before the step.
    void undo_step(bool previous_valid, bool start_pending);
    bool previous_valid() const { return previous_valid_; }
    bool start_pending() const { return start_pending_; }
    // Adaptive steps (error_estimate.cpp): which index-3 estimate, the scratch it needs, the
    // error norm of the trial step (a step of h ending at t_end) against control's tolerances,
    // and, after the commit, its accelerations taken as the consistent output.
    bool consistent_estimate() const;
    void setup_estimate()
    {
        if (consistent_estimate())
            setup_output();
        else
            setup_projection();
    }
    ga_status error_norm(double h, double t_end, const StepController &control, double &err);
    void estimate_is_output()
    {
        if (consistent_estimate() && estimate_is_output_)
            output_for_ = state_id_;
    }

    // ---- the linearization services (ForwardSensitivity, Adjoint) ----
    // The start of the attempt just prepared (prepare_start) from `from`: v_n, a_n, qdd_n and,
    // with first-order states, w_n and y'_n (null without them); a_n and w_n rescaled to h
    // unless they are from's own.
    struct StepStart {
        const Vec *v, *a, *qdd, *w, *ydot;
        bool a_rescaled, w_rescaled;
    };
    StepStart step_start(const State &from) const
    {
        return {v_start_, a_start_, qdd_start_, w_start_, ydot_start_, a_start_ != &from.a,
                w_start_ != &from.w};
    }
    // A Taylor step from `from`; the start of a step from it (a_start_, v_start_, qdd_start_,
    // lambda_start_ and fresh_start_, which point into it): rescaled, corrected, or consistent
    // again after short steps. `from` is the accepted state, or a perturbed copy (the
    // sensitivities' differences).
    ga_status sliver_step(const State &from, double h);
    ga_status prepare_start(const State &from, double h, bool restart_short);
    // The acceleration-level solve of the start (init.cpp) at (t, q, v) with the step's own
    // matrix and scratch; the kept matrix is gone afterwards, and with mass_changed so is a
    // constant mass evaluated.
    ga_status start_accelerations(double t, const Vec &q, const Vec &v, Vec &qdd, Vec &lambda)
    {
        SaddleWorkspace w{S_, M_, J_, f_, c_, rq_};
        return acceleration_level(t, q, v, w, qdd, lambda);
    }
    void drop_step_matrix(bool mass_changed)
    {
        jacobian_valid_ = false;
        if (mass_changed)
            mass_valid_ = false;
    }
    // [I Phi_q^T; Phi_q 0] at (t, q) in the step's matrix (a callback's status, or
    // GA_ERR_SINGULAR without a message: the caller says what it projected), and its solves.
    ga_status factorize_tangent_projection(double t, const Vec &q);
    void solve_tangent_projection(const Vec &rq, const Vec &rl, Vec &d, Vec &dl)
    {
        S_.solve(rq, rl, d, dl);
    }
    double step_matrix_rcond() const { return S_.rcond(); }
    // Whether every tangent an exact matrix needs has a place on the sparse path.
    bool exact_tangents_fit() const
    {
        const bool damped = model.has_force() || model.cb.damping;
        return !(sparse_backend_ &&
                 ((!K_.zero() && K_.dense()) || (damped && !C_.zero() && C_.dense())));
    }
    // M, f, Phi_q and every tangent at the converged step x (the user's callbacks whatever the
    // tangent mode, or central differences), into the step's matrices; which tangents exist.
    ga_status exact_tangents(double t, const State &x, bool &K, bool &C, bool &Z);
    // The exact iteration matrix at the converged step x (those tangents, the coupling blocks
    // by central differences, the Schur complement on y), factorized: the next step's Newton
    // iteration starts with it.
    ga_status factorize_exact(const State &x, double h, bool &K, bool &C, bool &Z);
    // The coupling blocks at a recorded state x (its rate g first), by central differences.
    ga_status coupling_at(double t, const State &x);
    // Index 2: B = Phi_q(q_n) evaluated at (t, q) into the step's B; where the step's B and
    // eta_bar belong (the converged step's).
    ga_status evaluate_B(double t, const Vec &q) { return model.jacobian(t, q, B_); }
    double B_time() const { return b_t_; }
    const Vec &eta_bar() const { return eta_total_; }
    // The step's matrices as last evaluated: M, Phi_q, K_t, C_t, B, Z = d(Phi_q v + Phi_t)/dq,
    // and the first-order coupling blocks.
    const ModelMatrix &mass_matrix() const { return M_; }
    const ModelMatrix &jacobian_matrix() const { return J_; }
    const ModelMatrix &stiffness_matrix() const { return K_; }
    const ModelMatrix &damping_matrix() const { return C_; }
    const ModelMatrix &B_matrix() const { return B_; }
    const ModelMatrix &Z_matrix() const { return Z_; }
    const CouplingBlocks &coupling() const { return blocks_; }
    // g_q as Newton's increments see it: g_q T(xi) on a group space, g_q on R^n
    const Mat &coupling_q_step() const
    {
        return model.space.euclidean() ? blocks_.g_q : g_q_step_;
    }
    bool sparse() const { return sparse_backend_; }
    // Solves with the factorized step matrix, scaled as Newton's (index 3: rv, w and e unused),
    // and the first-order states' elimination after it: dy from gy, then d, dl (and w) less
    // their responses to dy.
    void solve_step_matrix(const Vec &rq, const Vec &rl, const Vec &rv, double h, Vec &d, Vec &w,
                           Vec &dl, Vec &e);
    void eliminate_first_order(const Vec &gy, Vec &dy, Vec &d, Vec &dl, Vec &w) const;
    // The report of the last attempt (attempt_step) and the reuse state an attempt began
    // with, given back (kReuseStateSize entries, as StepReport::reuse_before): a replay
    // attempts a recorded step as it was.
    const StepReport &last_report() const { return step_report_; }
    void restore_reuse(const double *reuse);
    // A replayed step accepted: the trial state is the state, at t exactly; no undo point.
    void accept_replayed(double t);
    // What a sweep of replays changes besides the state a checkpoint restores, and its
    // restoration.
    struct RunPoint {
        State previous;
        bool previous_valid, start_pending;
        long long state_id;
    };
    RunPoint run_point() const
    {
        return {previous_, previous_valid_, start_pending_, state_id_};
    }
    void restore_run_point(const RunPoint &point);
    // The forces read the first-order states of the accepted state (not a recorded one).
    void forces_see_accepted() { model.y_now = &accepted_.y; }
    // KeptMatrix: the live matrices set aside while a sweep recomputes segments in matrices of
    // their own, and taken back (stepper.cpp).
    void set_aside_matrix(KeptMatrix &kept);  // allocates the replay's matrices
    void take_back_matrix(KeptMatrix &kept);

private:
    void forget_setup();
    // A matrix of the step's layout (S_, P_, O_, a kept S)
    void setup_step_matrix(IterationMatrix &S, std::unique_ptr<LinearBackend> backend);
    void setup_index2_matrix(Index2Matrix &S2);

    ga_status setup();  // chooses the backend and allocates everything; throws std::bad_alloc
    ga_status setup_workspace();  // the part every formulation and option needs
    void setup_projection();
    void prefactor_index2();
    // sliver_allowed: a step over kShortStepRatio times shorter than the one before is a
    // Taylor step (sliver_step)
    StepPlan plan_step(double h, double tol, bool sliver_allowed) const;
    ga_status attempt_step(double h, double tol, bool sliver_allowed);
    ga_status regular_step(const StepPlan &plan);
    // A step this many times shorter than the one before is a Taylor step that ends like a
    // restart (sliver_step).
    static constexpr double kShortStepRatio = 100.0;
    ga_status newton(double h, double tol, bool refresh, bool &converged, bool &used_stale);
    ga_status residual(double t, const State &x);
    // first_order.cpp: the parts of a step that concern first-order states.
    void first_order_start(const State &from, double h);
    void predict_first_order(double h);
    ga_status first_order_matrix(double t, const State &x, bool central = false);
    // The mechanical update depends on dy: f_y is in the Newton system (Z = Sol(f_y) != 0).
    bool forces_see_y() const { return coupling_exact && model.cb.force_y != nullptr; }
    ga_status first_order_schur(double h, const NewtonCoefficients &c);
    void first_order_correction(const NewtonCoefficients &c, Vec &dw);
    void update_first_order(const NewtonCoefficients &c, double h, State &x, UpdateSizes &size);
    void finish_first_order(State &x);
    ga_status first_order_starting_values(const State &from, double h);
    double first_order_error_sum(double h, double scale, const StepController &control);
    static bool long_after_short(const State &from, double h)
    {
        return from.h_last > 0.0 && h > kShortStepRatio * from.h_last;
    }
    Vec eta_total_;       // index 2: the converged step's eta_bar (sum of its increments)
    ga_status factorize(double t, const State &x, double h, bool tangents_K, bool tangents_C,
                        bool tangent_Z, int iter);
    ga_status rebuild_matrix();  // checkpoint.cpp: the kept matrix again, from recipe_
    ga_status evaluate_mass(double t, const Vec &q);
    // the estimate from a (docs/algorithms.md sec. 1.5, (a) and (b)) of trial_, into e_q, e_v
    void estimate_from_a(double h, Vec &e_q, Vec &e_v) const;
    // noise_q, noise_v: absolute amounts of the estimates that are noise, added to the weights
    double weighted_error_norm(const State &s, const State &x, const Vec &eq, const Vec &ev,
                               double h, const StepController &control, double noise_q = 0.0,
                               double noise_v = 0.0);
    // init.cpp
    ga_status start(double t0, const double *q0, const double *v0);
    void restore_active(const std::vector<unsigned char> &before);
    ga_status project_positions(double t, Vec &q);
    ga_status project_velocities(double t, const Vec &q, Vec &v);
    ga_status correct_velocities(Vec &v, const char *what);
    ga_status consistent_accelerations(double t, const Vec &q, const Vec &v, Vec &qdd,
                                       Vec &lambda);
    ga_status acceleration_level(double t, const Vec &q, const Vec &v, SaddleWorkspace &w,
                                 Vec &qdd, Vec &lambda);
    ga_status starting_values(const State &from, double h);
    void explain_singular_saddle_point();
    ga_status select_active_constraints(double t, const Vec &q);
    const unsigned char *active_ptr() const { return active_.empty() ? nullptr : active_.data(); }

    int nq_, nv_, m_;  // equal when the space is R^n (configuration_space.hpp)
    StepDoors *doors_ = nullptr;  // the transaction's (attach)
    std::vector<unsigned char> active_;  // GA_REDUNDANT_DROP: constraints in use
    bool initialized_ = false;
    bool workspace_ready_ = false;
    bool sparse_backend_ = false;
    int last_newton_iters_ = 0;

    State accepted_;  // the last accepted step: never touched by a step that fails
    State trial_;     // the step being computed
    State previous_;  // the accepted step before (dense output)
    bool previous_valid_ = false;
    DenseOutput dense_{previous_, accepted_, previous_valid_, model.space};  // the last step
    bool start_pending_ = false;  // first step after ga_init (or a restart): corrected start

    // The start of the step being computed: a_n rescaled to h (docs/algorithms.md 1.2) and, in the
    // first step, the corrected a_0 and v_0 (sec. 3.4-3.5).
    Vec a_n_, v_n_;
    // A step far longer than the one before starts from consistent accelerations and
    // multipliers (as at ga_init): those of steps of 1e-8 in index 3 are known only to
    // eps / (beta h^2), of the order of themselves.
    Vec qdd_n_, lambda_n_;
    // The a_n, v_n and qdd_n the step starts from: accepted_'s own, or the adjusted ones above
    // (no copy of a vector the step only reads: at 100 000 chain links each costs 2.4 MB of
    // memory traffic).
    const Vec *a_start_ = nullptr, *v_start_ = nullptr, *qdd_start_ = nullptr,
              *lambda_start_ = nullptr;
    bool fresh_start_ = false;  // this step starts like a first one

    // Reuse of the factorized iteration matrix across iterations and steps.
    mutable bool jacobian_valid_ = false;
    mutable double theta_prev_ = -1.0;   // contraction rate seen with the current matrix
    mutable bool mass_valid_ = false;    // constant mass: M evaluated
    mutable int refresh_steps_left_ = 0; // steps to start with a fresh matrix
    mutable int reuse_backoff_ = 1;      // ... after the next failed attempt to reuse
    bool reuse_attempted_ = false;       // this step started with an old matrix
    double jacobian_h_ = 0.0;
    // GA_TANGENT_AUTO with a tangent callback missing: finite differences for it only once a
    // fresh matrix without it contracted slower than kDeferredTangentRate (or failed). The
    // choice is made again whenever the matrix is dropped.
    static constexpr double kDeferredTangentRate = 0.1;
    mutable bool fd_tangents_ = false;
    // A checkpoint of layout 2 was restored: the next step forgets the pivots (set_state).
    bool pivots_forgotten_ = false;
    void forget_pivots();  // of every sparse LU: the next factorizations choose them afresh
    // What rebuilds the kept iteration matrix bit for bit (checkpoint): the time, iterate and
    // h it was factorized at, the tangents it holds and, in index 2, the q_n of B = Phi_q(q_n).
    struct MatrixRecipe {
        double t = 0.0, h = 0.0, t_b = 0.0;
        bool K = false, C = false, Z = false;
        bool central = false;  // tangents by central differences (the sensitivities' matrix)
        Vec q, v, qdd, lambda, q_b;
        Vec y, ydot;  // first-order states
        Vec xi;       // group spaces: the step's increment whose T(xi) it took (0: none)
    } recipe_;
    double b_t_ = 0.0;            // where B_ was evaluated last (index 2)
    const Vec *b_q_ = nullptr;
    bool tangents_deferred_ = false;  // the last Newton iteration ran without them

    // Consistent output (output.cpp): its own saddle-point matrix and scratch, and the
    // accepted state its values belong to (state_id_ counts accepted states).
    ga_status consistent_output(double t, const Vec &q, const Vec &v,
                                const char *purpose = "output");
    IterationMatrix O_;
    ModelMatrix out_M_, out_J_;
    Vec out_f_, out_c_, out_r_, out_q_, out_v_, out_qdd_, out_lambda_;
    long long state_id_ = 0;
    mutable long long output_for_ = -1;
    mutable bool out_mass_valid_ = false;
    double out_sigma_ = 1.0;  // O_'s scaling of its first block row (acceleration_level)

    // Step workspace, sized once.
    ModelMatrix M_, J_, K_, C_, B_;  // B_: index-2, Phi_q(q_n)
    // On a group space: the step's increment xi (q = q_n (+) xi, sec. 14), and K_t T(xi),
    // Phi_q T(xi), Z T(xi) for the iteration matrix (empty on R^n); on the sparse path their
    // expanded patterns are those of the step's matrix at every state (T = I at xi = 0)
    Vec xi_;
    TangentProduct KT_, JT_, ZT_;
    Mat g_q_step_;  // g_q T(xi) of the first-order states (first_order_matrix)
    ModelMatrix Z_;                  // index-2: d(Phi_q v + Phi_t)/dq, layout of J_
    Vec f_, phi_, phi_v_, rq_, dq_, dw_, dlambda_, deta_, c_, qdd_tmp_, lambda_tmp_;
    Vec guard_q_, guard_v_;  // index-3 error estimate: the estimate from a (error_estimate.cpp)
    bool estimate_is_output_ = false;  // its accelerations are the consistent output's
    // resolution_check.cpp: the index-3 step's velocity constraint, and its largest ratio
    ga_status check_velocity_constraint(double h, double tol);
    Vec check_residual_, check_scale_, check_phi_t_;
    double velocity_residual_ = 0.0;
    IterationMatrix S_;
    IterationMatrix P_;  // [I Phi_q^T; Phi_q 0]: tangent projection of error estimates
    Index2Matrix S2_;
    ConvergenceTest convergence_;


    // First-order states (first_order.cpp): the coupling blocks (evaluated with the iteration
    // matrix); the responses Z of the mechanical solve to the columns of f_y (dq, dw, dlambda,
    // deta) and the Schur complement C = c1 I - g_y + G Z with its LU, valid for the kept
    // matrix, its h and (index 2) its step's B; the residual r^y = y' - g and scratch. w_n_ is
    // the w the step starts from when it is rescaled or corrected.
    CouplingBlocks blocks_;
    bool schur_valid_ = false;
    double schur_h_ = 0.0;
    Mat Zq_, Zw_, Zl_, Ze_, C1_, Cg_;
    Eigen::PartialPivLU<Mat> C1_lu_;
    Vec z_rhs_, z_zero_, z_d_, z_w_, z_l_, z_e_, z_y_;
    Vec rate_, ry_, gx_, dy_, w_n_, y_tmp_;  // gx_: G x0, or scratch of the start
    Vec ydot_n_;  // the start's y' as a fresh start's step uses it (first_order.cpp)
    Vec out_y_;  // y at an interpolated time, for consistent output
    const Vec *w_start_ = nullptr, *ydot_start_ = nullptr;
    bool adaptive_attempt_ = false;  // the step being attempted is an adaptive one
    StepReport step_report_;  // of the last attempt (attempt_step)
    double Cg_q_norm_ = 0.0, Cg_v_norm_ = 0.0;  // |C^-1 g_q|, |C^-1 g_v| (convergence test)
};

}  // namespace ga
