#include "solver.hpp"

#include <cmath>
#include <limits>
#include <new>

namespace ga {

namespace {
constexpr double kStateMagic = 26465.0;  // 0x6761, "ga"
constexpr double kStateVersion = 1.0;
constexpr std::size_t kStateHeader = 6;  // magic, version, n, m, t, h_last

// Reuse of the iteration matrix after a change of h. Scaled, S_t depends on h only through
// gamma h C_t and beta h^2 K_t; the band is IDA's for its c_j (ALGORITHMS.md sec. 4.5):
// refactor when (h_old / h_new)^2 leaves [0.6, 5/3].
bool h_within_reuse_band(double h_matrix, double h)
{
    const double r = (h_matrix / h) * (h_matrix / h);
    return r >= 0.6 && r <= 5.0 / 3.0;
}

// Automatic choices of the linear algebra, from bench/linear_algebra (docs/performance.md):
// Eigen's LU beats Debian's reference LAPACK at every size measured (13 to 6400 unknowns), and
// KLU beats both on a declared pattern from 10 unknowns on (2x there, 1000x at 1280 links).
constexpr int kSparseMinSize = 10;
}  // namespace

void State::allocate(int n, int m)
{
    q.setZero(n);
    v.setZero(n);
    qdd.setZero(n);
    lambda.setZero(m);
    a.setZero(n);
}

void State::swap(State &other)
{
    std::swap(t, other.t);
    std::swap(h_last, other.h_last);
    q.swap(other.q);
    v.swap(other.v);
    qdd.swap(other.qdd);
    lambda.swap(other.lambda);
    a.swap(other.a);
}

Solver::Solver(int n, int m)
    : params(params_from_rho_inf(0.9)), model(n, m, counters, diag), n_(n), m_(m)
{
    accepted_.allocate(n, m);
    trial_.allocate(n, m);
    M_.set_dense(n, n);
    J_.set_dense(m, n);
    K_.set_dense(n, n);
    C_.set_dense(n, n);
}

ModelMatrix &Solver::matrix(ga_matrix which)
{
    switch (which) {
    case GA_MATRIX_MASS: return M_;
    case GA_MATRIX_JACOBIAN: return J_;
    case GA_MATRIX_STIFFNESS: return K_;
    default: return C_;
    }
}

ga_status Solver::setup()
{
    if (workspace_ready_)
        return GA_OK;
    // Which linear algebra: sparse needs declared patterns of M and Phi_q, and K_t, C_t either
    // declared (possibly empty), not needed, or neglected.
    const bool sparse_possible = !M_.dense() && (m_ == 0 || !J_.dense()) &&
                                 (!model.stiffness_needed(K_) || !K_.dense()) &&
                                 (!model.damping_needed(C_) || !C_.dense());
    bool sparse = false;
    switch (linear_solver) {
    case GA_LINEAR_SPARSE:
        if (!sparse_possible)
            return diag.fail(GA_ERR_ARG,
                             "the sparse solver needs the patterns of M and Phi_q, and of K_t "
                             "and C_t unless they are neglected (ga_set_pattern; an empty "
                             "pattern declares a zero matrix)");
        sparse = true;
        break;
    case GA_LINEAR_AUTO: sparse = sparse_possible && n_ + m_ >= kSparseMinSize; break;
    default: sparse = false;
    }
    std::unique_ptr<LinearBackend> backend;
    if (sparse) {
        backend = make_sparse_backend();
        if (!backend && linear_solver == GA_LINEAR_SPARSE)
            return diag.fail(GA_ERR_ARG, "galpha was built without KLU: no sparse solver");
    }
    if (!backend) {
        // The dense iteration matrix has (n + m)^2 entries; refuse sizes whose byte count
        // does not fit in the address space instead of letting the multiplication overflow.
        const double N = static_cast<double>(n_) + static_cast<double>(m_);
        if (N * N * sizeof(double) >
            static_cast<double>(std::numeric_limits<std::ptrdiff_t>::max()))
            throw std::bad_alloc();
        backend = make_dense_backend(linear_solver == GA_LINEAR_DENSE_LAPACK ? DenseKind::Lapack
                                                                             : DenseKind::Eigen);
    }
    M_.allocate();
    J_.allocate();
    K_.allocate();
    C_.allocate();
    f_.setZero(n_);
    phi_.setZero(m_);
    rq_.setZero(n_);
    dq_.setZero(n_);
    dlambda_.setZero(m_);
    c_.setZero(m_);
    model.allocate_workspace(M_, J_, K_, C_);
    S_.setup(std::move(backend), n_, m_, M_, J_, K_, C_);
    workspace_ready_ = true;
    return GA_OK;
}

ga_status Solver::evaluate_mass(double t, const Vec &q)
{
    if (model.constant_mass && mass_valid_)
        return GA_OK;
    if (auto st = model.mass(t, q, M_))
        return st;
    mass_valid_ = model.constant_mass;
    return GA_OK;
}

ga_status Solver::step(double h)
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
    } failed{counters};
    const ga_status st = attempt_step(h);
    if (st != GA_OK) {
        // Whatever went wrong, the next attempt starts from a fresh iteration matrix.
        invalidate_jacobian();
        return st;
    }
    accepted_.swap(trial_);  // commit
    failed.committed = true;
    count(counters, GA_COUNT_STEPS);
    return GA_OK;
}

// One step of Algorithm 1 from accepted_ into trial_. accepted_ is only read.
ga_status Solver::attempt_step(double h)
{
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
    if (auto st = newton(h, refresh, converged, used_stale))
        return st;
    if (!converged && used_stale) {
        // Modified Newton failed with an old matrix: the same step again, from the predictor,
        // with a matrix evaluated now (as IDA and Chrono do) before giving up.
        if (auto st = newton(h, true, converged, used_stale))
            return st;
    }
    if (!converged)
        return diag.fail(GA_ERR_NEWTON,
                         "Newton iteration did not converge in %d iterations in the step from "
                         "t = %.17g with h = %g (last increment / tolerance = %.3g)",
                         max_iter, accepted_.t, h, convergence_.ratio());
    const State &s = accepted_;
    State &x = trial_;
    if (!x.q.allFinite() || !x.v.allFinite() || !x.qdd.allFinite() || !x.lambda.allFinite())
        return diag.fail(GA_ERR_NONFINITE, "step from t = %.17g with h = %g produced a "
                         "non-finite state", s.t, h);
    const Params &p = params;
    // Algorithm 1, last line: a_{n+1} from eq. (3) with the converged qdd_{n+1}.
    x.a = (p.alpha_f * s.qdd - p.alpha_m * s.a + (1.0 - p.alpha_f) * x.qdd) / (1.0 - p.alpha_m);
    x.t = s.t + h;
    x.h_last = h;
    if (convergence_.rate() >= 0.0)
        theta_prev_ = convergence_.rate();
    return GA_OK;
}

// Predictor and Newton iteration of Algorithm 1. With `refresh` the iteration matrix is
// rebuilt before the first solve; otherwise the factorization of an earlier step is reused
// (modified Newton) and rebuilt only if the iteration contracts too slowly.
ga_status Solver::newton(double h, bool refresh, bool &converged, bool &used_stale)
{
    const Params &p = params;
    const NewtonCoefficients c = newton_coefficients(p, h);  // eq. (6)
    const double row_scale = step_row_scale(p, h, scaling);
    const State &s = accepted_;
    State &x = trial_;
    const double t1 = s.t + h;

    // Predictor (Algorithm 1, lines 1-7). The paper starts from qdd_{n+1} = 0, lambda = 0;
    // the default starts from a_{n+1} = a_n, lambda_{n+1} = lambda_n, i.e. the qdd_{n+1} that
    // eq. (3) maps to a_{n+1} = a_n. Both iterate to the same solution.
    const double delta_alpha = p.alpha_m - p.alpha_f;
    if (predictor == GA_PREDICTOR_ZERO) {
        x.qdd.setZero();
        x.lambda.setZero();
    } else if (predictor == GA_PREDICTOR_EXTRAPOLATE && delta_alpha != 0.0 && s.h_last > 0.0) {
        // a_n - qdd_n = delta_alpha h_last qddd + O(h^2) (ALGORITHMS.md sec. 0), hence
        // qdd(t_n + h) = qdd_n + (h / h_last) (a_n - qdd_n) / delta_alpha + O(h^2).
        x.qdd = s.qdd + (h / (s.h_last * delta_alpha)) * (s.a - s.qdd);
        x.lambda = s.lambda;
    } else {
        x.qdd = (s.a - p.alpha_f * s.qdd) / (1.0 - p.alpha_f);
        x.lambda = s.lambda;
    }
    x.a = (p.alpha_f * s.qdd - p.alpha_m * s.a + (1.0 - p.alpha_f) * x.qdd) / (1.0 - p.alpha_m);
    x.q = s.q + h * s.v + (h * h) * ((0.5 - p.beta) * s.a + p.beta * x.a);  // eq. (4)
    x.v = s.v + h * ((1.0 - p.gamma) * s.a + p.gamma * x.a);               // eq. (5)

    const bool tangents_K = model.stiffness_needed(K_);
    const bool tangents_C = model.damping_needed(C_);
    convergence_.reset(refresh ? -1.0 : theta_prev_);
    converged = false;
    used_stale = false;
    bool refresh_done = false;
    for (int iter = 1; iter <= max_iter && !converged; ++iter) {
        last_newton_iters_ = iter;
        ga_status st = evaluate_mass(t1, x.q);
        if (!st)
            st = model.force(t1, x.q, x.v, f_);
        if (!st)
            st = model.constraint(t1, x.q, phi_);
        if (!st)
            st = model.jacobian(t1, x.q, J_);
        if (!st) {
            // Residuals r^q (eq. 1, not weighted) and r^lambda = Phi (eq. 2).
            Model::dynamics_residual(M_, x.qdd, f_, J_, x.lambda, rq_);
            count(counters, GA_COUNT_RESIDUALS);
        }
        if (!st && refresh && tangents_K)
            st = model.stiffness(t1, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_);
        if (!st && refresh && tangents_C)
            st = model.damping(t1, x.q, x.v, f_, C_);
        if (st) {
            diag.append(" (Newton iteration %d of the step from t = %.17g with h = %g)", iter,
                        s.t, h);
            return st;
        }
        if (refresh) {
            // S_t at the current iterate, in the scaled form (9)-(10).
            count(counters, GA_COUNT_FACTORIZATIONS);
            jacobian_valid_ = false;
            if (!S_.factorize_step(M_, tangents_C ? &C_ : nullptr, tangents_K ? &K_ : nullptr,
                                   J_, p, h, scaling))
                return diag.fail(GA_ERR_SINGULAR,
                                 "iteration matrix S_t%s is singular (rcond = %.3g) in Newton "
                                 "iteration %d of the step from t = %.17g with h = %g",
                                 scaling ? " (scaled, eq. 10)" : " (unscaled)", S_.rcond(), iter,
                                 s.t, h);
            jacobian_valid_ = true;
            jacobian_h_ = h;
            theta_prev_ = -1.0;
            convergence_.matrix_changed();
            refresh = false;
            refresh_done = true;
        } else {
            used_stale = true;
        }
        // [dq; dlambda] = -S_t^{-1} [r^q; r^lambda]
        S_.solve(rq_, phi_, dq_, dlambda_, row_scale);
        count(counters, GA_COUNT_NEWTON_ITERS);
        if (!dq_.allFinite() || !dlambda_.allFinite())
            return diag.fail(GA_ERR_NONFINITE,
                             "Newton increment is not finite in iteration %d of the step from "
                             "t = %.17g with h = %g",
                             iter, s.t, h);

        // Algorithm 1, correction: q += dq, v += gamma' dq, qdd += beta' dq (eq. 7),
        // lambda += dlambda.
        x.q += dq_;
        x.v += c.gamma_prime * dq_;
        x.qdd += c.beta_prime * dq_;
        x.lambda += dlambda_;
        const auto verdict = convergence_.check(newton_tol, dq_, c.beta_prime, dlambda_, x.q,
                                                x.qdd, x.lambda);
        converged = verdict == ConvergenceTest::Verdict::Converged;
        // Too slow with an old matrix: rebuild it at the current iterate. Full Newton
        // (GA_REUSE_NEVER, Algorithm 1 as printed) rebuilds at every iteration.
        if (verdict == ConvergenceTest::Verdict::Slow && used_stale && reuse_attempted_ &&
            !refresh_done) {
            reuse_backoff_ = std::min(2 * reuse_backoff_, 32);
            refresh_steps_left_ = reuse_backoff_;
        } else if (converged && reuse_attempted_ && !refresh_done) {
            reuse_backoff_ = 1;  // the old matrix did the whole step: keep reusing
        }
        if (reuse == GA_REUSE_NEVER || (verdict == ConvergenceTest::Verdict::Slow && used_stale))
            refresh = true;
    }
    return GA_OK;
}

ga_status Solver::unavoidable_work(double h)
{
    const State &x = accepted_;
    const double t = x.t + h;
    ga_status st = evaluate_mass(t, x.q);
    if (!st)
        st = model.force(t, x.q, x.v, f_);
    if (!st)
        st = model.constraint(t, x.q, phi_);
    if (!st)
        st = model.jacobian(t, x.q, J_);
    if (st)
        return st;
    Model::dynamics_residual(M_, x.qdd, f_, J_, x.lambda, rq_);
    if (!jacobian_valid_) {
        const bool K = model.stiffness_needed(K_), C = model.damping_needed(C_);
        if (K && (st = model.stiffness(t, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_)))
            return st;
        if (C && (st = model.damping(t, x.q, x.v, f_, C_)))
            return st;
        if (!S_.factorize_step(M_, C ? &C_ : nullptr, K ? &K_ : nullptr, J_, params, h, scaling))
            return GA_ERR_SINGULAR;
        jacobian_valid_ = true;
        jacobian_h_ = h;
    }
    S_.solve(rq_, phi_, dq_, dlambda_, step_row_scale(params, h, scaling));
    return GA_OK;
}

std::size_t Solver::state_size() const
{
    return kStateHeader + 4 * static_cast<std::size_t>(n_) + static_cast<std::size_t>(m_);
}

void Solver::get_state(double *buf) const
{
    const State &s = accepted_;
    buf[0] = kStateMagic;
    buf[1] = kStateVersion;
    buf[2] = n_;
    buf[3] = m_;
    buf[4] = s.t;
    buf[5] = s.h_last;
    double *p = buf + kStateHeader;
    for (const Vec *x : {&s.q, &s.v, &s.qdd, &s.lambda, &s.a}) {
        Eigen::Map<Vec>(p, x->size()) = *x;
        p += x->size();
    }
    invalidate_jacobian();
}

ga_status Solver::set_state(const double *buf, std::size_t len)
{
    if (len != state_size())
        return diag.fail(GA_ERR_ARG, "checkpoint has %zu doubles, this solver needs %zu", len,
                         state_size());
    if (buf[0] != kStateMagic || buf[1] != kStateVersion)
        return diag.fail(GA_ERR_ARG, "not a galpha checkpoint (magic %g, layout version %g)",
                         buf[0], buf[1]);
    if (buf[2] != n_ || buf[3] != m_)
        return diag.fail(GA_ERR_ARG, "checkpoint is for n = %g, m = %g; this solver has n = %d, "
                         "m = %d", buf[2], buf[3], n_, m_);
    for (std::size_t k = 4; k < len; ++k)
        if (!std::isfinite(buf[k]))
            return diag.fail(GA_ERR_ARG, "checkpoint entry %zu is not finite", k);
    if (!model.ready())
        return diag.fail(GA_ERR_STATE, "ga_set_state needs the callbacks (ga_set_callbacks)");
    if (auto st = setup())
        return st;
    State &s = accepted_;
    s.t = buf[4];
    s.h_last = buf[5];
    const double *p = buf + kStateHeader;
    for (Vec *x : {&s.q, &s.v, &s.qdd, &s.lambda, &s.a}) {
        *x = Eigen::Map<const Vec>(p, x->size());
        p += x->size();
    }
    invalidate_jacobian();
    initialized_ = true;
    return GA_OK;
}

}  // namespace ga
