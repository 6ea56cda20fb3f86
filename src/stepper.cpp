#include "stepper.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

namespace ga {

namespace {

// Reuse of the iteration matrix after a change of h. Scaled, S_t depends on h only through
// gamma h C_t and beta h^2 K_t; the band is IDA's for its c_j (docs/algorithms.md sec. 4.5):
// refactor when (h_old / h_new)^2 leaves [0.6, 5/3].
bool h_within_reuse_band(double h_matrix, double h)
{
    const double r = (h_matrix / h) * (h_matrix / h);
    return r >= 0.6 && r <= 5.0 / 3.0;
}

// Automatic choices of the linear algebra, from bench/linear_algebra (docs/performance.md):
// among dense LUs, the unblocked kernel on small or mostly-zero matrices and Eigen's on full
// ones (both beat Debian's reference LAPACK at every size measured); KLU beats them all on a
// declared pattern from 10 unknowns on.
constexpr int kSparseMinSize = 10;

DenseKind dense_kind(ga_linear_solver choice)
{
    switch (choice) {
    case GA_LINEAR_DENSE_LAPACK:
        return DenseKind::Lapack;
    case GA_LINEAR_DENSE_EIGEN:
        return DenseKind::Eigen;
    case GA_LINEAR_DENSE_UNBLOCKED:
        return DenseKind::Unblocked;
    default:
        return DenseKind::Auto;
    }
}

// Algorithm 1, correction: q += dq, v += gamma' dw, qdd += beta' dw (eq. 7), lambda +=
// dlambda, with dw = dq except in the stabilized index-2 form, where v and qdd move with the
// Newmark part of the update only. The same pass takes the max-norms the stopping test reads
// and checks the increments: done as ten separate passes (updates, norms, checks), on a large
// model each streamed the vectors through the cache once more. Blocks of kBlock entries keep
// Eigen's vectorized kernels and a block's data in the L1 cache from one kernel to the next.
// A finite iterate plus finite increments can only overflow to infinity, which the max-norms
// show: the iterate needs no check of its own.
constexpr Eigen::Index kBlock = 512;

// On a group space the increment goes into the step's xi and q is q_n (+) xi (xi: null on
// R^n).
void apply_update(const ConfigurationSpace &space, const Vec &dq, const Vec &dw,
                  const Vec &dlambda, double gamma_prime, double beta_prime, State &x,
                  UpdateSizes &size, const Vec &q_n, Vec *xi)
{
    const bool separate_dw = &dw != &dq;
    double v_max = 0.0;
    size = UpdateSizes{};
    for (Eigen::Index i = 0; i < dq.size(); i += kBlock) {
        const Eigen::Index len = std::min(kBlock, dq.size() - i);
        const auto d = dq.segment(i, len), w = dw.segment(i, len);
        auto v = x.v.segment(i, len), qdd = x.qdd.segment(i, len);
        size.increments_finite = size.increments_finite && all_finite(d.data(), len) &&
                                 (!separate_dw || all_finite(w.data(), len));
        if (xi) {
            xi->segment(i, len) += d;
        } else {
            auto q = x.q.segment(i, len);
            space.increment(q, d);
            size.q = std::max(size.q, space.max_magnitude(q));
        }
        v += gamma_prime * w;
        qdd += beta_prime * w;
        size.dq = std::max(size.dq, d.cwiseAbs().maxCoeff());
        if (separate_dw)
            size.dw = std::max(size.dw, w.cwiseAbs().maxCoeff());
        v_max = std::max(v_max, v.cwiseAbs().maxCoeff());
        size.qdd = std::max(size.qdd, qdd.cwiseAbs().maxCoeff());
    }
    if (xi) {
        space.step_to(q_n, *xi, x.q);
        // (a finite xi can still give a NaN rotation: exp of an increment beyond 1e154
        // overflows |xi|^2; max_magnitude would pass the NaN by)
        size.q = all_finite(x.q) ? space.max_magnitude(x.q)
                                 : std::numeric_limits<double>::infinity();
    }
    if (!separate_dw)
        size.dw = size.dq;
    for (Eigen::Index i = 0; i < dlambda.size(); i += kBlock) {
        const Eigen::Index len = std::min(kBlock, dlambda.size() - i);
        const auto d = dlambda.segment(i, len);
        auto lambda = x.lambda.segment(i, len);
        size.increments_finite = size.increments_finite && all_finite(d.data(), len);
        lambda += d;
        size.dlambda = std::max(size.dlambda, d.cwiseAbs().maxCoeff());
        size.lambda = std::max(size.lambda, lambda.cwiseAbs().maxCoeff());
    }
    size.v = v_max;
    size.dw_is_dq = !separate_dw;
    size.iterate_finite = std::isfinite(size.q) && std::isfinite(v_max) &&
                          std::isfinite(size.qdd) && std::isfinite(size.lambda);
}
}  // namespace

void State::allocate(int nq, int nv, int m)
{
    q.setZero(nq);
    v.setZero(nv);
    qdd.setZero(nv);
    lambda.setZero(m);
    a.setZero(nv);
    a_prev.setZero(nv);
    c.setZero(nv);
    c_prev.setZero(nv);
    c_dt = 0.0;
    c_count = 0;
}

void State::allocate_first_order(int r)
{
    y.setZero(r);
    ydot.setZero(r);
    w.setZero(r);
    w_prev.setZero(r);
}

void State::swap(State &other)
{
    std::swap(t, other.t);
    std::swap(h_last, other.h_last);
    std::swap(sliver_span, other.sliver_span);
    q.swap(other.q);
    v.swap(other.v);
    qdd.swap(other.qdd);
    lambda.swap(other.lambda);
    a.swap(other.a);
    a_prev.swap(other.a_prev);
    c.swap(other.c);
    c_prev.swap(other.c_prev);
    std::swap(c_dt, other.c_dt);
    std::swap(c_count, other.c_count);
    y.swap(other.y);
    ydot.swap(other.ydot);
    w.swap(other.w);
    w_prev.swap(other.w_prev);
}

Stepper::Stepper(const ConfigurationSpace &space, int m)
    : params(params_from_rho_inf(0.9)), params1(first_order_params_from_rho_inf(0.9)),
      model(space, m, counters, diag), nq_(static_cast<int>(space.nq())),
      nv_(static_cast<int>(space.nv())), m_(m)
{
    if (!space.euclidean())
        xi_.setZero(nv_);
    accepted_.allocate(nq_, nv_, m);
    trial_.allocate(nq_, nv_, m);
    previous_.allocate(nq_, nv_, m);
    a_n_.setZero(nv_);
    v_n_.setZero(nv_);
    qdd_n_.setZero(nv_);
    lambda_n_.setZero(m);
    for (Vec *x : {&recipe_.q, &recipe_.q_b})
        x->setZero(nq_);
    for (Vec *x : {&recipe_.v, &recipe_.qdd})
        x->setZero(nv_);
    if (!space.euclidean())
        recipe_.xi.setZero(nv_);
    recipe_.lambda.setZero(m);
    M_.set_dense(nv_, nv_);
    J_.set_dense(m, nv_);
    K_.set_dense(nv_, nv_);
    C_.set_dense(nv_, nv_);
}

ModelMatrix &Stepper::matrix(ga_matrix which)
{
    switch (which) {
    case GA_MATRIX_MASS: return M_;
    case GA_MATRIX_JACOBIAN: return J_;
    case GA_MATRIX_STIFFNESS: return K_;
    default: return C_;
    }
}

ga_status Stepper::setup()
{
    // The parts that options call for are set up each once; after running out of memory half
    // way, a retry builds what is missing (the workspace was marked ready before the index-2
    // system existed, and every step then failed).
    const bool index2_missing = formulation == GA_INDEX2_STABILIZED && !S2_.ready();
    const bool output_missing = output == GA_OUTPUT_CONSISTENT && !O_.ready();
    if (workspace_ready_ && !index2_missing && !output_missing)
        return GA_OK;
    if (!workspace_ready_)
        if (auto st = setup_workspace())
            return st;
    if (index2_missing)
        setup_index2();
    if (output_missing)
        setup_output();
    // The factors' storage after every setup, so that it does not add to their peak.
    S_.reserve_factors();
    return GA_OK;
}

// Sparse needs declared patterns of M and Phi_q, and K_t, C_t either declared (possibly
// empty), not needed, or neglected.
bool Stepper::sparse_possible() const
{
    return !M_.dense() && (m_ == 0 || !J_.dense()) &&
           (!model.stiffness_needed(K_) || !K_.dense()) &&
           (!model.damping_needed(C_) || !C_.dense());
}

bool Stepper::sparse_wanted() const
{
    switch (linear_solver) {
    case GA_LINEAR_SPARSE: return sparse_possible();
    case GA_LINEAR_AUTO: return sparse_possible() && nv_ + m_ >= kSparseMinSize;
    default: return false;
    }
}

ga_status Stepper::setup_workspace()
{
    if (linear_solver == GA_LINEAR_SPARSE && !sparse_possible())
        return diag.fail(GA_ERR_ARG,
                         "the sparse solver needs the patterns of M and Phi_q, and of K_t "
                         "and C_t unless they are neglected (ga_set_pattern; an empty "
                         "pattern declares a zero matrix)");
    const bool sparse = sparse_wanted();
    std::unique_ptr<LinearBackend> backend;
    if (sparse) {
        backend = make_sparse_backend();
        if (!backend && linear_solver == GA_LINEAR_SPARSE)
            return diag.fail(GA_ERR_ARG, "galpha was built without KLU: no sparse solver");
    }
    if (!backend) {
        // The dense iteration matrix has (n + m)^2 entries; refuse sizes whose byte count
        // does not fit in the address space instead of letting the multiplication overflow.
        const double N = static_cast<double>(nv_) + static_cast<double>(m_);
        if (N * N * sizeof(double) >
            static_cast<double>(std::numeric_limits<std::ptrdiff_t>::max()))
            throw std::bad_alloc();
        backend = make_dense_backend(dense_kind(linear_solver));
    }
    M_.allocate();
    J_.allocate();
    if (!model.space.euclidean()) {
        if (!sparse || !K_.dense())  // (sparse: a dense K_t is one that is not needed)
            KT_.setup(K_, model.space);
        JT_.setup(J_, model.space);
        ZT_.setup(J_, model.space);
    }
    // On the sparse path a tangent without a pattern is one that is not needed (neglected, or
    // C_t without forces): no dense n x n for it (1.5 GB at n = 10^4).
    if (!sparse || !K_.dense())
        K_.allocate();
    if (!sparse || !C_.dense())
        C_.allocate();
    B_.copy_layout(J_);
    Z_.copy_layout(J_);
    f_.setZero(nv_);
    // dense output's q and v, whatever the output mode (on a group space ga_interpolate
    // writes q block by block into a vector of its size)
    out_q_.setZero(nq_);
    out_v_.setZero(nv_);
    phi_.setZero(m_);
    phi_v_.setZero(m_);
    rq_.setZero(nv_);
    dq_.setZero(nv_);
    dw_.setZero(nv_);
    dlambda_.setZero(m_);
    deta_.setZero(m_);
    c_.setZero(m_);
    qdd_tmp_.setZero(nv_);
    guard_q_.setZero(nv_);
    guard_v_.setZero(nv_);
    check_residual_.setZero(m_);
    check_scale_.setZero(m_);
    check_phi_t_.setZero(m_);
    lambda_tmp_.setZero(m_);
    eta_total_.setZero(m_);
    doors_->on_setup();
    if (r() > 0) {
        const int r1 = r();
        blocks_.allocate(nv_, r1);
        if (!model.space.euclidean())
            g_q_step_.setZero(r1, nv_);
        for (Mat *Z : {&Zq_, &Zw_})
            Z->setZero(nv_, r1);
        for (Mat *Z : {&Zl_, &Ze_})
            Z->setZero(m_, r1);
        C1_.setZero(r1, r1);
        Cg_.setZero(r1, nv_);
        C1_lu_ = Eigen::PartialPivLU<Mat>(r1);
        for (Vec *x : {&z_rhs_, &z_d_, &z_w_})
            x->setZero(nv_);
        for (Vec *x : {&z_zero_, &z_l_, &z_e_})
            x->setZero(m_);
        for (Vec *x : {&rate_, &ry_, &gx_, &dy_, &w_n_, &ydot_n_, &y_tmp_, &z_y_})
            x->setZero(r1);
        schur_valid_ = false;
    }
    model.allocate_workspace(M_, J_, K_, C_);
    sparse_backend_ = sparse && backend;
    if (redundancy == GA_REDUNDANT_DROP)
        active_.assign(m_, 1);
    setup_step_matrix(S_, std::move(backend));
    workspace_ready_ = true;
    return GA_OK;
}

// A matrix of the step's layout: on the sparse path of a group space, with the expanded
// patterns of K_t T and Phi_q T (its lower block), which its other uses fill with K_t, Phi_q.
void Stepper::setup_step_matrix(IterationMatrix &S, std::unique_ptr<LinearBackend> backend)
{
    const bool expanded = sparse_backend_ && !model.space.euclidean();
    S.setup(std::move(backend), nv_, m_, M_, J_, expanded && !K_.dense() ? KT_.out() : K_, C_,
            active_ptr(), expanded ? &JT_.out() : nullptr);
}

void Stepper::forget_setup()
{
    workspace_ready_ = false;
    sparse_backend_ = false;
    S_ = IterationMatrix{};
    P_ = IterationMatrix{};
    O_ = IterationMatrix{};
    S2_.reset();
    invalidate_jacobian();
}

// A second step matrix like S_ (and S2_) for the adjoint sweep's recomputed segments; the
// live ones, with the first-order blocks factorized into them, go into `kept` meanwhile.
void Stepper::set_aside_matrix(KeptMatrix &kept)
{
    auto backend = sparse_backend_ ? make_sparse_backend()
                                   : make_dense_backend(dense_kind(linear_solver));
    backend->analysis_from(S_.backend());  // the same pattern: its ordering
    setup_step_matrix(kept.S, std::move(backend));
    kept.S.reserve_factors();
    if (S2_.ready()) {
        setup_index2_matrix(kept.S2);
        kept.S2.reserve_factors();
    }
    kept.blocks = blocks_;
    // nothing above changed the solver; from here on nothing allocates
    std::swap(S_, kept.S);
    if (kept.S2.ready())
        std::swap(S2_, kept.S2);
}

void Stepper::take_back_matrix(KeptMatrix &kept)
{
    std::swap(S_, kept.S);
    if (kept.S2.ready())
        std::swap(S2_, kept.S2);
    std::swap(blocks_, kept.blocks);
}

// The stabilized index-2 system, dense or sparse like S_: set up with the workspace when that
// formulation is chosen, or when it is chosen later (ga_set_formulation), never in a step.
void Stepper::setup_index2()
{
    if (!S2_.ready()) {
        setup_index2_matrix(S2_);
        S2_.reserve_factors();
    }
    if (initialized_)
        prefactor_index2();
}

// The index-2 system in the step's layout: on the sparse path of a group space with the
// expanded patterns of K_t T and Phi_q T (setup_step_matrix).
void Stepper::setup_index2_matrix(Index2Matrix &S2)
{
    const bool expanded = sparse_backend_ && !model.space.euclidean();
    S2.setup(nv_, m_, sparse_backend_, dense_kind(linear_solver), M_, J_,
             expanded && !K_.dense() ? KT_.out() : K_, C_, expanded ? &JT_.out() : nullptr,
             active_ptr());
}

// The sparse LU picks its pivots in its first numeric factorization; for the sparse index-2
// system that happens here, with the matrices of the current state, and not in the first
// step (which then only refactorizes). Without C_t and K_t the matrix does not depend on h.
// A failure here is no error: the step factorizes afresh.
void Stepper::prefactor_index2()
{
    if (!S2_.sparse())
        return;
    count(counters, GA_COUNT_FACTORIZATIONS);
    const ModelMatrix *J_low = nullptr;
    if (!model.space.euclidean() && m_ > 0) {  // its lower block in the expanded layout, T = I
        JT_.apply(J_, nullptr, model.space);
        J_low = &JT_.out();
    }
    S2_.factorize(M_, nullptr, nullptr, J_, J_, nullptr, params, 1.0, J_low);
}

// The projection of error estimates (adaptive mode only): set up at the first adaptive call,
// so that fixed-step runs do not pay for a second factorization workspace.
void Stepper::setup_projection()
{
    if (m_ > 0 && !P_.ready()) {
        auto backend =
            sparse_backend_ ? make_sparse_backend() : make_dense_backend(DenseKind::Auto);
        backend->analysis_from(S_.backend());  // the same pattern: its ordering
        setup_step_matrix(P_, std::move(backend));
        P_.reserve_factors();
    }
}

ga_status Stepper::evaluate_mass(double t, const Vec &q)
{
    if (model.constant_mass && mass_valid_)
        return GA_OK;
    if (auto st = model.mass(t, q, M_))
        return st;
    mass_valid_ = model.constant_mass;
    return GA_OK;
}

void Stepper::forget_pivots()
{
    S_.forget_pivots();
    S2_.forget_pivots();
    P_.forget_pivots();
    O_.forget_pivots();
    pivots_forgotten_ = false;
}

void Stepper::undo_step(bool previous_valid, bool start_pending)
{
    previous_.swap(trial_);  // commit's swaps, backwards
    accepted_.swap(trial_);
    doors_->on_undo();
    previous_valid_ = previous_valid;
    start_pending_ = start_pending;
    ++state_id_;  // no output computed for the undone state is taken for this one
    output_for_ = -1;
    count(counters, GA_COUNT_STEPS, -1);
    count(counters, GA_COUNT_FAILED_STEPS);
    invalidate_jacobian();
}

void Stepper::commit(bool land_on, double t_land)
{
    accepted_.swap(trial_);    // the new step becomes the state ...
    previous_.swap(trial_);    // ... and the old one the start of the interval for dense output
    if (land_on)
        accepted_.t = t_land;  // exactly, not t_n + h rounded
    doors_->on_commit();  // (before the counters: the adjoint's checkpoints hold them)
    previous_valid_ = true;
    start_pending_ = false;
    ++state_id_;
    count(counters, GA_COUNT_STEPS);
}

// What the attempt of a step from accepted_ is to be; reads, changes nothing.
StepPlan Stepper::plan_step(double h, double tol, bool sliver_allowed) const
{
    const State &s = accepted_;
    StepPlan plan;
    plan.h = h;
    plan.tol = tol;
    plan.sliver_allowed = sliver_allowed;
    const double short_limit = s.h_last / kShortStepRatio;
    const bool short_step = s.h_last > 0.0 && h < short_limit;
    if (sliver_allowed && short_step && s.sliver_span + h <= short_limit) {
        plan.kind = StepPlan::Sliver;
        return plan;
    }
    // Short steps beyond a sliver's span are the caller's new step size: Algorithm 1 again,
    // started afresh from the consistent state the slivers left (Taylor steps do not last).
    plan.restart_short = short_step && s.sliver_span > 0.0;
    plan.fresh = start_pending_ || long_after_short(s, h) || plan.restart_short;
    return plan;
}

// One attempt of a step from accepted_ into trial_ (accepted_ is only read): the plan, the
// report of how it begins, what the sensitivities do before it, then the step.
ga_status Stepper::attempt_step(double h, double tol, bool sliver_allowed)
{
    if (formulation == GA_INDEX2_STABILIZED && !S2_.ready())
        return diag.fail(GA_ERR_INTERNAL, "the stabilized index-2 system was not set up");
    const StepPlan plan = plan_step(h, tol, sliver_allowed);
    StepReport &report = step_report_;
    report.plan = plan;
    report.adaptive = adaptive_attempt_;
    const double reuse_state[kReuseStateSize] = {
        jacobian_valid_ ? 1.0 : 0.0, theta_prev_, static_cast<double>(refresh_steps_left_),
        static_cast<double>(reuse_backoff_), fd_tangents_ ? 1.0 : 0.0};
    std::copy_n(reuse_state, kReuseStateSize, report.reuse_before);
    if (pivots_forgotten_)  // after a layout-2 checkpoint: pivots as a new solver picks them
        forget_pivots();
    if (auto st = doors_->before_attempt(plan))
        return st;
    return plan.kind == StepPlan::Sliver ? sliver_step(accepted_, h) : regular_step(plan);
}

// Algorithm 1 (or its index-2 form) from accepted_ into trial_.
ga_status Stepper::regular_step(const StepPlan &plan)
{
    const double h = plan.h, tol = plan.tol;
    const State &s = accepted_;
    const bool restart_short = plan.restart_short;
    if (auto st = prepare_start(accepted_, h, restart_short))
        return st;

    // After a reused matrix was too slow, the next steps start with a fresh one; how many
    // doubles with every failed attempt to reuse (up to 32) and resets when reuse works.
    const bool skip_reuse = refresh_steps_left_ > 0;
    if (skip_reuse)
        --refresh_steps_left_;
    bool refresh = reuse == GA_REUSE_NEVER || !jacobian_valid_ || skip_reuse ||
                   !h_within_reuse_band(jacobian_h_, h);
    reuse_attempted_ = !refresh;
    bool converged = false, used_stale = false;
    last_newton_iters_ = 0;
    // Each attempt starts from the predictor. A matrix found singular at an iterate the
    // iteration moved to (beyond its first update) means that attempt diverged there; the
    // next one, more careful, may not.
    // Should every attempt fail so, the first one's message is the one reported.
    ga_status st = GA_OK;
    bool diverged = false;
    char first_failure[Diagnostics::kSize] = "";
    const auto attempt = [&](bool fresh) {
        st = newton(h, tol, fresh, converged, used_stale);
        if (st == GA_ERR_SINGULAR && (diverged || last_newton_iters_ > 1)) {
            if (!diverged)
                diag.copy_to(first_failure);
            diverged = true;
            converged = false;
            return true;
        }
        return st == GA_OK;
    };
    if (!attempt(refresh))
        return st;
    if (!converged && used_stale) {
        // Modified Newton failed with an old matrix: the same step again, from the predictor,
        // with a matrix evaluated now (as IDA and Chrono do) before giving up.
        if (!attempt(true))
            return st;
    }
    if (!converged && tangents_deferred_) {
        // The simplified iteration failed or was too slow: again with the missing tangents.
        fd_tangents_ = true;
        if (!attempt(true))
            return st;
    }
    // Then full Newton (a matrix at every iterate): modified Newton must not give up on a
    // step that Algorithm 1 as printed solves (Andrews at h = 1e-3, index 2: the kept matrix
    // let the iteration wander into a singular configuration). The fallbacks of a run in
    // full Newton are all among these.
    const ga_reuse_mode planned_reuse = reuse;
    const Restore<ga_reuse_mode> keep_reuse(reuse);
    const Restore<ga_predictor> keep_predictor(predictor);
    if (!converged && reuse == GA_REUSE_AUTO) {
        reuse = GA_REUSE_NEVER;
        const bool go_on = attempt(true);
        reuse = planned_reuse;
        if (!go_on)
            return st;
    }
    if (!converged && predictor == GA_PREDICTOR_EXTRAPOLATE) {
        // An extrapolation through a rough a_n (after abrupt changes of h, or without
        // rescaling) can start Newton outside its basin: once more from a_{n+1} = a_n.
        predictor = GA_PREDICTOR_CONSTANT_A;
        reuse = GA_REUSE_NEVER;
        const bool go_on = attempt(true);
        predictor = GA_PREDICTOR_EXTRAPOLATE;
        reuse = planned_reuse;
        if (!go_on)
            return st;
    }
    if (!converged && diverged) {
        diag.restore(first_failure);
        return GA_ERR_SINGULAR;
    }
    if (!converged)
        return diag.fail(GA_ERR_NEWTON,
                         "Newton iteration did not converge in %d iterations in the step from "
                         "t = %.17g with h = %g (last increment / tolerance = %.3g)",
                         max_iter, s.t, h, convergence_.ratio());
    diag.clear();  // an attempt before the one that converged may have left a message
    State &x = trial_;  // finite: every Newton update checked it
    const Params &p = params;
    // Algorithm 1, last line: a_{n+1} from eq. (3) with the converged qdd_{n+1}; a_n kept for
    // the error estimate of the next step (one pass for both)
    const Vec &a_n = *a_start_, &qdd_n = *qdd_start_;
    for (Eigen::Index i = 0; i < nv_; ++i) {
        x.a[i] = (p.alpha_f * qdd_n[i] - p.alpha_m * a_n[i] + (1.0 - p.alpha_f) * x.qdd[i]) /
                 (1.0 - p.alpha_m);
        x.a_prev[i] = a_n[i];
    }
    if (r() > 0)
        finish_first_order(x);
    x.t = s.t + h;
    x.h_last = h;
    x.sliver_span = 0.0;
    x.c_count = 0;  // an adaptive step's error estimate computes them (error_norm)
    if (convergence_.rate() >= 0.0)
        theta_prev_ = convergence_.rate();
    return check_velocity_constraint(h, tol);
}

ga_status Stepper::prepare_start(const State &from, double h, bool restart_short)
{
    const State &s = from;
    // The start of the step. a_n carries the shift delta_alpha h_last; rescaled to the h of
    // this step the scheme stays second order under any sequence of step sizes (docs/algorithms.md
    // sec. 1.2): a_n <- qdd_n + (h / h_last) (a_n - qdd_n).
    a_start_ = &s.a;
    v_start_ = &s.v;
    qdd_start_ = &s.qdd;
    lambda_start_ = &s.lambda;
    const bool long_after_short = Stepper::long_after_short(s, h);
    fresh_start_ = start_pending_ || long_after_short || restart_short;
    model.y_now = &s.y;  // the forces the start's own evaluations see
    if (long_after_short) {
        if (auto st = consistent_accelerations(s.t, s.q, s.v, qdd_n_, lambda_n_)) {
            diag.append(" (start of a step %g times longer than the one before)", h / s.h_last);
            return st;
        }
        qdd_start_ = &qdd_n_;
        lambda_start_ = &lambda_n_;
    }
    if (fresh_start_ && corrected_start) {
        if (auto st = starting_values(s, h))  // sets a_start_ and, in index 3, v_start_
            return st;
    } else if (fresh_start_) {
        a_start_ = qdd_start_;
    } else if (rescale_a && s.h_last > 0.0 && h != s.h_last) {
        a_n_ = s.qdd + (h / s.h_last) * (s.a - s.qdd);
        a_start_ = &a_n_;
    }
    if (r() > 0) {
        if (fresh_start_)
            if (auto st = first_order_starting_values(s, h))
                return st;
        first_order_start(s, h);
    }
    return GA_OK;
}

// A step far shorter than the one before it (a sliver that lands on an output time) is not
// solved from the discrete equations: they determine its accelerations badly. In index 3 the
// position constraint makes a_{n+1} absorb the O(h_last^2) velocity-constraint residual left
// by the steps before, an impulse of size O(h_last^2 / h), and the round-off of Phi over
// beta h^2; in index 2 they are fixed only to eps |v| / (gamma h). Through a, the next steps
// carried that on (a sliver of 1e-8 after steps of 1e-3 put the index-3 pendulum 1.5 off its
// path). Instead: a Taylor step q + h v + h^2/2 qdd, v + h qdd (local errors O(h^3) and
// O(h^2) in the third derivative, with h at most 1e-2 of the step before), v projected onto
// the velocity constraint, and qdd, lambda from the acceleration-level equations at its end,
// as at ga_init; the recursion for a then goes on as if the sliver had not been taken.
ga_status Stepper::sliver_step(const State &from, double h)
{
    const State &s = from;
    State &x = trial_;
    x.t = s.t + h;
    model.space.taylor(s.q, s.v, s.qdd, h, x.q);
    x.v = s.v + h * s.qdd;
    if (!all_finite(x.q) || !all_finite(x.v))
        return diag.fail(GA_ERR_NONFINITE,
                         "the short step from t = %.17g with h = %g is not finite", s.t, h);
    // The velocities onto the velocity constraint, as at ga_init: in index 3 they carry an
    // O(h_last^2) normal part, which a further short step would again take as an impulse.
    ga_status st = m_ > 0 ? model.jacobian(x.t, x.q, J_) : GA_OK;
    if (!st && m_ > 0)
        st = model.constraint_dt(x.t, x.q, c_);
    if (!st && m_ > 0) {
        phi_ = c_;
        J_.multiply_add(1.0, x.v, phi_);
        st = correct_velocities(x.v, "the velocities");
    }
    if (!st && r() > 0) {  // y by its own Taylor step (local error O(h^2), h tiny)
        x.y = s.y + h * s.ydot;
        model.y_now = &x.y;
        st = model.rate(x.t, x.q, x.v, x.y, x.ydot);
    }
    if (!st)
        st = consistent_accelerations(x.t, x.q, x.v, x.qdd, x.lambda);
    if (st) {
        diag.append(" (short step from t = %.17g, h = %g: %g times shorter than the one before)",
                    s.t, h, s.h_last / h);
        return st;
    }
    // The recursion for a goes on as if the sliver had not been taken: a and a_prev keep
    // their offsets from qdd (the shift delta_alpha h_last qddd that the next step rescales),
    // and h_last stays the size of the step before, so that a further sliver is one too.
    qdd_tmp_ = x.qdd - s.qdd;
    x.a = s.a + qdd_tmp_;
    x.a_prev = s.a_prev + qdd_tmp_;
    if (r() > 0) {
        x.w = s.w + (x.ydot - s.ydot);
        x.w_prev = s.w_prev + (x.ydot - s.ydot);
    }
    x.h_last = s.h_last;
    x.sliver_span = s.sliver_span + h;
    x.c = x.qdd;  // consistent; the one before is a sliver away, too close to difference
    x.c_count = 1;
    a_start_ = &x.a;  // for the error estimate of adaptive steps: none from this step
    w_start_ = &x.w;  // (likewise for the first-order states)
    ydot_start_ = &s.ydot;
    last_newton_iters_ = 0;
    // No iteration: the test's verdicts (diverged, which the error estimate reads) are not
    // those of an earlier step's Newton, which a restored checkpoint does not carry.
    convergence_.reset(-1.0);
    return GA_OK;
}

// Residuals r^q (eq. 1, not weighted) into rq_ and r^lambda = Phi (eq. 2) into phi_ at (t, x),
// leaving M_, f_ and J_ evaluated there.
ga_status Stepper::residual(double t, const State &x)
{
    model.y_now = &x.y;
    ga_status st = evaluate_mass(t, x.q);
    if (!st)
        st = model.force(t, x.q, x.v, f_, Model::Check::Deferred);
    if (!st)
        st = model.constraint(t, x.q, phi_);
    if (!st)
        st = model.jacobian(t, x.q, J_, Model::Check::Deferred);
    if (st)
        return st;
    if (r() > 0) {  // r^y = y' - g(t, q, v, y)
        if ((st = model.rate(t, x.q, x.v, x.y, rate_)))
            return st;
        ry_ = x.ydot - rate_;
    }
    Model::dynamics_residual(M_, x.qdd, f_, J_, x.lambda, rq_);
    count(counters, GA_COUNT_RESIDUALS);
    // f and Phi_q are checked through r^q, which every entry of both enters (a NaN or an Inf
    // makes a NaN or an Inf of every product and sum it enters); x is finite.
    if (!all_finite(rq_)) {
        if ((st = model.check_deferred(t, f_, J_)))
            return st;
        return diag.fail(GA_ERR_NONFINITE,
                         "residual r^q = M qdd - f + Phi_q^T lambda overflows at t = %.17g", t);
    }
    return GA_OK;
}

// Rebuild and factorize the iteration matrix at the iterate x at time t (M_, J_, the tangents
// and in index 2 B_ evaluated there by the caller), and remember where (checkpoints).
ga_status Stepper::exact_tangents(double t, const State &x, bool &K, bool &C, bool &Z)
{
    ga_status st = residual(t, x);
    const Restore<ga_tangent_mode> keep_mode(model.tangent_mode);
    model.tangent_mode = GA_TANGENT_AUTO;
    K = !K_.zero() && K_.size() > 0;
    C = !C_.zero() && C_.size() > 0 && (model.has_force() || model.cb.damping);
    Z = formulation == GA_INDEX2_STABILIZED && m_ > 0;
    if (!st && K)
        st = model.stiffness(t, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_, true);
    if (!st && C)
        st = model.damping(t, x.q, x.v, f_, C_, true);
    if (!st && Z)
        st = model.velocity_constraint_tangent(t, x.q, x.v, J_, Z_, true);
    return st;
}

ga_status Stepper::factorize_exact(const State &x, double h, bool &K, bool &C, bool &Z)
{
    const double t = x.t;
    ga_status st = exact_tangents(t, x, K, C, Z);
    if (!st && r() > 0)  // the coupling blocks likewise, and the Schur complement on y
        st = first_order_matrix(t, x, true);
    if (!st)
        st = factorize(t, x, h, K, C, Z, 0);
    recipe_.central = !st;
    if (!st && r() > 0)
        st = first_order_schur(h, newton_coefficients(params, h));
    return st;
}

ga_status Stepper::coupling_at(double t, const State &x)
{
    if (auto st = model.rate(t, x.q, x.v, x.y, rate_))
        return st;
    return first_order_matrix(t, x, true);
}

ga_status Stepper::factorize_tangent_projection(double t, const Vec &q)
{
    if (auto st = model.jacobian(t, q, J_))
        return st;
    count(counters, GA_COUNT_FACTORIZATIONS);
    jacobian_valid_ = false;  // S_ holds another matrix now
    return S_.factorize_projection(J_) ? GA_OK : GA_ERR_SINGULAR;
}

void Stepper::solve_step_matrix(const Vec &rq, const Vec &rl, const Vec &rv, double h, Vec &d,
                                Vec &w, Vec &dl, Vec &e)
{
    if (formulation == GA_INDEX2_STABILIZED)
        S2_.solve(rq, rl, rv, params, h, B_, d, w, dl, e);
    else
        S_.solve(rq, rl, d, dl, step_row_scale(params, h, scaling));
}

void Stepper::eliminate_first_order(const Vec &gy, Vec &dy, Vec &d, Vec &dl, Vec &w) const
{
    dy = C1_lu_.solve(gy);
    if (forces_see_y()) {
        d.noalias() -= Zq_ * dy;
        dl.noalias() -= Zl_ * dy;
        if (formulation == GA_INDEX2_STABILIZED)
            w.noalias() -= Zw_ * dy;
    }
}

void Stepper::restore_reuse(const double *reuse)
{
    if (reuse[0] == 0.0)
        invalidate_jacobian();
    theta_prev_ = reuse[1];
    refresh_steps_left_ = static_cast<int>(reuse[2]);
    reuse_backoff_ = static_cast<int>(reuse[3]);
    fd_tangents_ = reuse[4] != 0.0;
}

void Stepper::accept_replayed(double t)
{
    accepted_.swap(trial_);
    accepted_.t = t;
    start_pending_ = false;
}

void Stepper::restore_run_point(const RunPoint &point)
{
    previous_ = point.previous;
    previous_valid_ = point.previous_valid;
    start_pending_ = point.start_pending;
    model.y_now = &accepted_.y;
    state_id_ = point.state_id;
    output_for_ = -1;  // (its buffers may hold a recomputed step's output now)
}

ga_status Stepper::factorize(double t, const State &x, double h, bool tangents_K,
                            bool tangents_C, bool tangent_Z, int iter)
{
    count(counters, GA_COUNT_FACTORIZATIONS);
    jacobian_valid_ = false;
    const ModelMatrix *C = tangents_C ? &C_ : nullptr, *K = tangents_K ? &K_ : nullptr;
    const ModelMatrix *J_low = nullptr, *Z = tangent_Z ? &Z_ : nullptr;
    if (!model.space.euclidean() && (&x == &trial_ || sparse_backend_)) {
        // q = q_n o exp(xi): the q-columns of K_t and of the constraint rows take T(xi) as a
        // right factor, Phi_q^T stays (sec. 14). (At the accepted state xi = 0, T = I: the
        // dense path takes the matrices as they are, the sparse one in its expanded layout.)
        const Vec *xi = &x == &trial_ ? &xi_ : nullptr;
        if (K) {
            KT_.apply(K_, xi, model.space);
            K = &KT_.out();
        }
        if (m_ > 0) {
            JT_.apply(J_, xi, model.space);
            J_low = &JT_.out();
        }
        if (Z) {  // index 2: the velocity constraint's curvature, through q as well
            ZT_.apply(Z_, xi, model.space);
            if (!Z_.dense())
                ZT_.add_bracket(J_, x.v, xi, model.space);
            Z = &ZT_.out();
        }
    }
    const bool ok = formulation == GA_INDEX2_STABILIZED
                        ? S2_.factorize(M_, C, K, J_, B_, Z, params, h, J_low)
                        : S_.factorize_step(M_, C, K, J_, params, h, scaling, J_low);
    if (!ok) {
        diag.fail(GA_ERR_SINGULAR,
                  "iteration matrix S_t%s is singular (rcond = %.3g) in Newton iteration %d of "
                  "the step from t = %.17g with h = %g",
                  formulation == GA_INDEX2_STABILIZED ? " (stabilized index-2)"
                  : scaling                           ? " (scaled, eq. 10)"
                                                      : " (unscaled)",
                  last_rcond(), iter, accepted_.t, h);
        // Beyond the first iteration the matrix is that of an iterate Newton moved to, which
        // a diverging iteration (h too large for the motion) can carry into a singular
        // configuration that the model never passes through.
        if (iter > 1)
            diag.append(", at an iterate the iteration moved to (last increment / tolerance "
                        "= %.3g): if the iteration was diverging, a smaller h may help",
                        convergence_.ratio());
        return GA_ERR_SINGULAR;
    }
    jacobian_valid_ = true;
    schur_valid_ = false;  // first-order states: Z and C belong to a matrix
    jacobian_h_ = h;
    theta_prev_ = -1.0;
    convergence_.matrix_changed();
    MatrixRecipe &r = recipe_;
    r.t = t;
    r.h = h;
    r.K = tangents_K;
    r.C = tangents_C;
    r.Z = tangent_Z;
    r.central = false;  // (factorize_exact says otherwise after its factorization)
    r.q = x.q;
    r.v = x.v;
    r.qdd = x.qdd;
    r.lambda = x.lambda;
    if (!model.space.euclidean()) {  // a rebuild takes the same T (checkpoint.cpp)
        if (&x == &trial_)
            r.xi = xi_;
        else
            r.xi.setZero();
    }
    if (this->r() > 0) {
        r.y = x.y;
        r.ydot = x.ydot;
    }
    if (formulation == GA_INDEX2_STABILIZED && m_ > 0) {
        r.t_b = b_t_;
        if (b_q_ != &r.q_b)
            r.q_b = *b_q_;
    }
    return GA_OK;
}

// Predictor and Newton iteration of Algorithm 1 (or of its stabilized index-2 variant). With
// `refresh` the iteration matrix is rebuilt before the first solve; otherwise the
// factorization of an earlier step is reused (modified Newton) and rebuilt only if the
// iteration contracts too slowly.
ga_status Stepper::newton(double h, double tol, bool refresh, bool &converged, bool &used_stale)
{
    const Params &p = params;
    const NewtonCoefficients c = newton_coefficients(p, h);  // eq. (6)
    const double row_scale = step_row_scale(p, h, scaling);
    const bool index2 = formulation == GA_INDEX2_STABILIZED;
    const State &s = accepted_;
    const Vec &a_n = *a_start_, &v_n = *v_start_;
    State &x = trial_;
    const double t1 = s.t + h;

    // Predictor (Algorithm 1, lines 1-7). The paper starts from qdd_{n+1} = 0, lambda = 0;
    // the others start from a_{n+1} = a_n, or from qdd extrapolated linearly; lambda_n.
    // All iterate to the same solution. One pass over the vectors, in blocks: at 100 000
    // chain links they do not stay in the cache from one pass to the next.
    const double delta_alpha = p.alpha_m - p.alpha_f;
    enum { Zero, Extrapolate, ConstantA } start = ConstantA;
    if (predictor == GA_PREDICTOR_ZERO)
        start = Zero;
    else if (predictor == GA_PREDICTOR_EXTRAPOLATE && delta_alpha != 0.0 && s.h_last > 0.0 &&
             !fresh_start_)  // a_n - qdd_n of the steps before says nothing about this one
        start = Extrapolate;
    // a_n - qdd_n = delta_alpha h_last qddd + O(h^2) (docs/algorithms.md sec. 0), hence
    // qdd(t_n + h) = qdd_n + (h / h_last) (a_n - qdd_n) / delta_alpha + O(h^2).
    const double slope = start == Extrapolate ? h / (s.h_last * delta_alpha) : 0.0;
    bool finite = true;
    const bool group = !model.space.euclidean();
    for (Eigen::Index i = 0; i < nv_; i += kBlock) {  // blocks in L1: one trip to memory
        const Eigen::Index len = std::min(kBlock, nv_ - i);
        const auto qdd_n = qdd_start_->segment(i, len), an = a_n.segment(i, len);
        auto qdd = x.qdd.segment(i, len), a = x.a.segment(i, len), v = x.v.segment(i, len);
        if (start == Zero)
            qdd.setZero();
        else if (start == Extrapolate)
            qdd = qdd_n + slope * (s.a.segment(i, len) - qdd_n);
        else
            qdd = (an - p.alpha_f * qdd_n) / (1.0 - p.alpha_f);
        a = (p.alpha_f * qdd_n - p.alpha_m * an + (1.0 - p.alpha_f) * qdd) / (1.0 - p.alpha_m);
        if (group) {  // q from xi below
            auto xi = xi_.segment(i, len);
            ConfigurationSpace::newmark_increment(xi, v_n.segment(i, len), an, a, h, p.beta);
            finite = finite && all_finite(xi.data(), len);
        } else {
            auto q = x.q.segment(i, len);
            model.space.newmark(q, s.q.segment(i, len), v_n.segment(i, len), an, a, h,
                                p.beta);  // (4)
            finite = finite && all_finite(q.data(), len);
        }
        v = v_n.segment(i, len) + h * ((1.0 - p.gamma) * an + p.gamma * a);            // eq. (5)
        finite = finite && all_finite(v.data(), len) && all_finite(qdd.data(), len);
    }
    if (group) {
        model.space.step_to(s.q, xi_, x.q);  // eq. (4) on the group: q_n o exp(xi)
        finite = finite && all_finite(x.q);
    }
    if (start == Zero)
        x.lambda.setZero();
    else
        x.lambda = *lambda_start_;  // finite, as every accepted state
    // The iteration starts from a finite iterate (the updates keep it so or report it): a
    // predictor can overflow where the accepted state is huge or h is.
    if (r() > 0) {
        predict_first_order(h);
        finite = finite && all_finite(x.y) && all_finite(x.ydot);
    }
    if (!finite)
        return diag.fail(GA_ERR_NONFINITE,
                         "predicted Newton iterate is not finite in the step from t = %.17g "
                         "with h = %g",
                         s.t, h);
    if (index2)
        eta_total_.setZero();  // the predictor's eta_bar (the step's report: sensitivities read it)
    if (index2 && m_ > 0) {
        // B = Phi_q(q_n): the direction of the position correction -h B^T eta (sec. 2.1)
        if (auto st = model.jacobian(s.t, s.q, B_))
            return st;
        b_t_ = s.t;
        b_q_ = &s.q;
        schur_valid_ = false;  // Z of the first-order states is that of the solve with B
    }

    // Tangents the user gives are always in the matrix. Missing ones (GA_TANGENT_AUTO) cost
    // finite differences, a residual per column group at every refactorization: they are
    // left out (simplified Newton) until the iteration shows that they matter.
    bool tangents_K = model.stiffness_needed(K_);
    bool tangents_C = model.damping_needed(C_);
    tangents_deferred_ = false;
    if (model.tangent_mode == GA_TANGENT_AUTO && !fd_tangents_ &&
        ((tangents_K && !model.cb.stiffness) || (tangents_C && !model.cb.damping))) {
        tangents_deferred_ = true;
        tangents_K = tangents_K && model.cb.stiffness;
        tangents_C = tangents_C && model.cb.damping;
    }
    convergence_.reset(refresh ? -1.0 : theta_prev_);
    converged = false;
    used_stale = false;
    bool refresh_done = false;
    for (int iter = 1; iter <= max_iter && !converged; ++iter) {
        last_newton_iters_ = iter;
        ga_status st = residual(t1, x);
        if (!st && index2 && m_ > 0) {
            // the velocity constraint Phi_q v + Phi_t
            st = model.constraint_dt(t1, x.q, phi_v_);
            J_.multiply_add(1.0, x.v, phi_v_);
        }
        if (!st && refresh && tangents_K)
            st = model.stiffness(t1, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_);
        if (!st && refresh && tangents_C)
            st = model.damping(t1, x.q, x.v, f_, C_);
        // index 2: the curvature of the velocity constraint, a tangent like K_t
        const bool tangent_Z = index2 && m_ > 0 && model.uses_tangents();
        if (!st && refresh && tangent_Z)
            st = model.velocity_constraint_tangent(t1, x.q, x.v, J_, Z_);
        if (!st && refresh && r() > 0)
            st = first_order_matrix(t1, x);
        if (!st && refresh) {
            st = factorize(t1, x, h, tangents_K, tangents_C, tangent_Z, iter);
            refresh = false;
            refresh_done = true;
        } else if (!st) {
            used_stale = true;
        }
        if (st) {
            if (st != GA_ERR_SINGULAR)
                diag.append(" (Newton iteration %d of the step from t = %.17g with h = %g)",
                            iter, s.t, h);
            return st;
        }
        // [dq; dlambda] = -S_t^{-1} [r^q; r^lambda], in the scaled form (9)-(10)
        if (r() > 0 && (!schur_valid_ || schur_h_ != h)) {  // first-order states
            if (auto st2 = first_order_schur(h, c)) {
                diag.append(" (Newton iteration %d)", iter);
                return st2;
            }
        }
        const Vec *dw = &dq_;
        if (index2) {
            // dw_: the Newmark part of the update, dq + B^T deta
            S2_.solve(rq_, phi_, phi_v_, p, h, B_, dq_, dw_, dlambda_, deta_);
            dw = &dw_;
            eta_total_ += deta_;
        } else {
            S_.solve(rq_, phi_, dq_, dlambda_, row_scale);
        }
        if (r() > 0)
            first_order_correction(c, index2 ? dw_ : dq_);
        count(counters, GA_COUNT_NEWTON_ITERS);
        UpdateSizes size;
        apply_update(model.space, dq_, *dw, dlambda_, c.gamma_prime, c.beta_prime, x, size, s.q,
                     model.space.euclidean() ? nullptr : &xi_);
        if (r() > 0)
            update_first_order(c, h, x, size);
        if (!size.increments_finite || !size.iterate_finite)
            return diag.fail(GA_ERR_NONFINITE,
                             "Newton %s is not finite in iteration %d of the step from "
                             "t = %.17g with h = %g",
                             size.increments_finite ? "iterate" : "increment", iter, s.t, h);
        const auto verdict = convergence_.check(tol, size, c.beta_prime, c.gamma_prime);
        converged = verdict == ConvergenceTest::Verdict::Converged;
        if (!converged && tangents_deferred_ && refresh_done && !convergence_.at_roundoff() &&
            convergence_.iterations_with_matrix() >= 2 &&
            !(convergence_.rate() <= kDeferredTangentRate)) {
            // A fresh matrix without the missing tangents contracts too slowly: from now on
            // they come by finite differences. The step starts again from the predictor
            // (attempt_step): the iterate may have diverged far enough that continuing from
            // it would cost the step its precision.
            fd_tangents_ = true;
            return GA_OK;
        }
        if (verdict == ConvergenceTest::Verdict::Slow && used_stale && reuse_attempted_ &&
            !refresh_done) {
            reuse_backoff_ = std::min(2 * reuse_backoff_, 32);
            refresh_steps_left_ = reuse_backoff_;
        } else if (converged && reuse_attempted_ && !refresh_done) {
            reuse_backoff_ = 1;  // the old matrix did the whole step: keep reusing
        }
        // Too slow with an old matrix: rebuild it at the current iterate. Full Newton
        // (GA_REUSE_NEVER, Algorithm 1 as printed) rebuilds at every iteration.
        if (reuse == GA_REUSE_NEVER || (verdict == ConvergenceTest::Verdict::Slow && used_stale))
            refresh = true;
    }
    return GA_OK;
}

ga_status Stepper::tangent_options_changed()
{
    // The sparse path was chosen with tangents that need no pattern (not needed then); a
    // tangent needed now has no place in its matrix.
    if (sparse_backend_ && ((model.stiffness_needed(K_) && K_.dense()) ||
                            (model.damping_needed(C_) && C_.dense())))
        return diag.fail(GA_ERR_ARG,
                         "the sparse path was set up without a pattern of %s, which these "
                         "options need: declare it before ga_init (an empty pattern declares a "
                         "zero matrix)",
                         model.stiffness_needed(K_) && K_.dense() ? "K_t" : "C_t");
    invalidate_jacobian();
    if (workspace_ready_)
        model.prepare_differences(M_, K_, C_);  // may throw std::bad_alloc (GA_ERR_NOMEM)
    return GA_OK;
}

double Stepper::last_rcond() const
{
    return formulation == GA_INDEX2_STABILIZED ? S2_.rcond() : S_.rcond();
}

const char *Stepper::linear_backend() const
{
    if (workspace_ready_ && formulation == GA_INDEX2_STABILIZED)
        return S2_.name();
    return S_.backend_name();
}

ga_status Stepper::unavoidable_work(double h)
{
    if (formulation != GA_INDEX3)  // the index-3 step's work
        return GA_ERR_ARG;
    const State &x = accepted_;
    const double t = x.t + h;
    ga_status st = residual(t, x);
    if (st)
        return st;
    if (!jacobian_valid_) {
        const bool K = model.stiffness_needed(K_), C = model.damping_needed(C_);
        if (K && (st = model.stiffness(t, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_)))
            return st;
        if (C && (st = model.damping(t, x.q, x.v, f_, C_)))
            return st;
        if ((st = factorize(t, x, h, K, C, false, 0)))
            return st;
    }
    S_.solve(rq_, phi_, dq_, dlambda_, step_row_scale(params, h, scaling));
    return GA_OK;
}

}  // namespace ga
