#include "solver.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <new>

namespace ga {

namespace {
constexpr double kStateMagic = 26465.0;  // 0x6761, "ga"
constexpr double kStateVersion = 1.0;
constexpr std::size_t kStateHeader = 6;  // magic, version, n, m, t, h_last

bool all_finite(const Vec &x) { return x.allFinite(); }
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
}

void Solver::allocate_workspace()
{
    if (workspace_ready_)
        return;
    // The dense iteration matrix has (n + m)^2 entries; refuse sizes whose byte count does
    // not fit in the address space instead of letting the multiplication overflow.
    const double N = static_cast<double>(n_) + static_cast<double>(m_);
    if (N * N * sizeof(double) > static_cast<double>(std::numeric_limits<std::ptrdiff_t>::max()))
        throw std::bad_alloc();
    M_.setZero(n_, n_);
    C_.setZero(n_, n_);
    K_.setZero(n_, n_);
    Phi_q_.setZero(m_, n_);
    f_.setZero(n_);
    phi_.setZero(m_);
    rq_.setZero(n_);
    dq_.setZero(n_);
    dlambda_.setZero(m_);
    c_.setZero(m_);
    S_.allocate(n_, m_);
    model.allocate_workspace();
    workspace_ready_ = true;
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
    if (st != GA_OK)
        return st;
    accepted_.swap(trial_);  // commit
    failed.committed = true;
    count(counters, GA_COUNT_STEPS);
    return GA_OK;
}

// One step of Algorithm 1 from accepted_ into trial_. accepted_ is only read.
ga_status Solver::attempt_step(double h)
{
    const Params &p = params;
    const NewtonCoefficients c = newton_coefficients(p, h);  // eq. (6)
    const State &s = accepted_;
    State &x = trial_;
    const double t1 = s.t + h;

    // Predictor (Algorithm 1, lines 1-7). The paper starts from qdd_{n+1} = 0, lambda = 0;
    // the default starts from a_{n+1} = a_n, lambda_{n+1} = lambda_n, i.e. the qdd_{n+1} that
    // eq. (3) maps to a_{n+1} = a_n. Both iterate to the same solution.
    if (predictor == GA_PREDICTOR_ZERO) {
        x.qdd.setZero();
        x.lambda.setZero();
    } else {
        x.qdd = (s.a - p.alpha_f * s.qdd) / (1.0 - p.alpha_f);
        x.lambda = s.lambda;
    }
    x.a = (p.alpha_f * s.qdd - p.alpha_m * s.a + (1.0 - p.alpha_f) * x.qdd) / (1.0 - p.alpha_m);
    x.q = s.q + h * s.v + (h * h) * ((0.5 - p.beta) * s.a + p.beta * x.a);  // eq. (4)
    x.v = s.v + h * ((1.0 - p.gamma) * s.a + p.gamma * x.a);               // eq. (5)

    const bool tangents = model.uses_tangents();
    convergence_.reset();
    last_newton_iters_ = 0;
    bool converged = false;
    int iter = 0;
    while (!converged && iter < max_iter) {
        last_newton_iters_ = ++iter;
        ga_status st = model.mass(t1, x.q, M_);
        if (!st)
            st = model.force(t1, x.q, x.v, f_);
        if (!st)
            st = model.constraint(t1, x.q, phi_);
        if (!st)
            st = model.jacobian(t1, x.q, Phi_q_);
        if (!st) {
            // Residuals r^q (eq. 1, not weighted) and r^lambda = Phi (eq. 2).
            Model::dynamics_residual(M_, x.qdd, f_, Phi_q_, x.lambda, rq_);
            count(counters, GA_COUNT_RESIDUALS);
        }
        if (!st && tangents)
            st = model.stiffness(t1, x.q, x.v, x.qdd, x.lambda, rq_, K_);
        if (!st && tangents)
            st = model.damping(t1, x.q, x.v, f_, C_);
        if (st) {
            diag.append(" (Newton iteration %d of the step from t = %.17g with h = %g)", iter,
                        s.t, h);
            return st;
        }

        // [dq; dlambda] = -S_t^{-1} [r^q; r^lambda], solved in the scaled form (9)-(10).
        count(counters, GA_COUNT_FACTORIZATIONS);
        if (!S_.factorize_step(M_, tangents ? &C_ : nullptr, tangents ? &K_ : nullptr, Phi_q_, p,
                               h, scaling))
            return diag.fail(GA_ERR_SINGULAR,
                             "iteration matrix S_t%s is singular (rcond = %.3g) in Newton "
                             "iteration %d of the step from t = %.17g with h = %g",
                             scaling ? " (scaled, eq. 10)" : " (unscaled)", S_.rcond(), iter,
                             s.t, h);
        S_.solve(rq_, phi_, dq_, dlambda_);
        count(counters, GA_COUNT_NEWTON_ITERS);
        if (!all_finite(dq_) || !all_finite(dlambda_))
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
        converged = convergence_.converged(newton_tol, dq_, c.beta_prime, dlambda_, x.q, x.qdd,
                                           x.lambda);
    }
    if (!converged)
        return diag.fail(GA_ERR_NEWTON,
                         "Newton iteration did not converge in %d iterations in the step from "
                         "t = %.17g with h = %g (last increment / tolerance = %.3g)",
                         max_iter, s.t, h, convergence_.ratio());
    if (!all_finite(x.q) || !all_finite(x.v) || !all_finite(x.qdd) || !all_finite(x.lambda))
        return diag.fail(GA_ERR_NONFINITE, "step from t = %.17g with h = %g produced a "
                         "non-finite state", s.t, h);

    // Algorithm 1, last line: a_{n+1} from eq. (3) with the converged qdd_{n+1}.
    x.a = (p.alpha_f * s.qdd - p.alpha_m * s.a + (1.0 - p.alpha_f) * x.qdd) / (1.0 - p.alpha_m);
    x.t = t1;
    x.h_last = h;
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
    allocate_workspace();
    State &s = accepted_;
    s.t = buf[4];
    s.h_last = buf[5];
    const double *p = buf + kStateHeader;
    for (Vec *x : {&s.q, &s.v, &s.qdd, &s.lambda, &s.a}) {
        *x = Eigen::Map<const Vec>(p, x->size());
        p += x->size();
    }
    initialized_ = true;
    return GA_OK;
}

}  // namespace ga
