#include "model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ga {

namespace {
const double kEps = std::numeric_limits<double>::epsilon();

// Forward-difference increment: sqrt(eps) relative to the component, with 1 as the typical
// magnitude below which it is absolute (as SUNDIALS does with atol = 1). Returned as the exact
// difference (x + e) - x, so that the division uses the increment actually applied.
double fd_increment(double x)
{
    const double e = std::sqrt(kEps) * std::max(std::fabs(x), 1.0);
    const double xp = x + e;
    return xp - x;
}
}  // namespace

Model::Model(int n, int m, Counters &counters, Diagnostics &diag)
    : n_(n), m_(m), counters_(counters), diag_(diag)
{
}

void Model::allocate_workspace()
{
    q_pert_.setZero(n_);
    v_pert_.setZero(n_);
    f_pert_.setZero(n_);
    r_pert_.setZero(n_);
    phi_plus_.setZero(m_);
    phi_minus_.setZero(m_);
    g_plus_.setZero(m_);
    g_minus_.setZero(m_);
    M_pert_.setZero(n_, n_);
    J_pert_.setZero(m_, n_);
}

ga_status Model::callback_status(int rc, const char *name, double t)
{
    if (rc == 0)
        return GA_OK;
    if (rc > 0)
        return diag_.fail(GA_ERR_CALLBACK_RETRY,
                          "%s callback returned %d (recoverable) at t = %.17g", name, rc, t);
    return diag_.fail(GA_ERR_CALLBACK, "%s callback returned %d (fatal) at t = %.17g", name, rc,
                      t);
}

ga_status Model::check_finite(const double *x, Eigen::Index rows, Eigen::Index cols,
                              const char *what, double t)
{
    const Eigen::Index size = rows * cols;
    for (Eigen::Index k = 0; k < size; ++k) {
        if (!std::isfinite(x[k])) {
            if (cols == 1)
                return diag_.fail(GA_ERR_NONFINITE, "%s[%ld] = %g is not finite at t = %.17g",
                                  what, static_cast<long>(k), x[k], t);
            return diag_.fail(GA_ERR_NONFINITE, "%s(%ld,%ld) = %g is not finite at t = %.17g",
                              what, static_cast<long>(k % rows), static_cast<long>(k / rows),
                              x[k], t);
        }
    }
    return GA_OK;
}

ga_status Model::mass(double t, const Vec &q, Mat &M)
{
    count(counters_, GA_COUNT_MASS_EVALS);
    if (auto st = callback_status(cb.mass(t, q.data(), M.data(), cb.user), "mass", t))
        return st;
    return check_finite(M.data(), n_, n_, "mass matrix M", t);
}

ga_status Model::force(double t, const Vec &q, const Vec &v, Vec &f)
{
    if (!cb.force) {  // no applied forces: nothing to evaluate, nothing to count
        f.setZero();
        return GA_OK;
    }
    count(counters_, GA_COUNT_FORCE_EVALS);
    if (auto st = callback_status(cb.force(t, q.data(), v.data(), f.data(), cb.user), "force",
                                  t))
        return st;
    return check_finite(f.data(), n_, 1, "force f", t);
}

ga_status Model::constraint(double t, const Vec &q, Vec &phi)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_CONSTRAINT_EVALS);
    if (auto st = callback_status(cb.constraint(t, q.data(), phi.data(), cb.user), "constraint",
                                  t))
        return st;
    return check_finite(phi.data(), m_, 1, "constraint Phi", t);
}

ga_status Model::jacobian(double t, const Vec &q, Mat &Phi_q)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_JACOBIAN_EVALS);
    if (auto st = callback_status(cb.jacobian(t, q.data(), Phi_q.data(), cb.user), "jacobian",
                                  t))
        return st;
    return check_finite(Phi_q.data(), m_, n_, "constraint Jacobian Phi_q", t);
}

void Model::dynamics_residual(const Mat &M, const Vec &qdd, const Vec &f, const Mat &Phi_q,
                              const Vec &lambda, Vec &rq)
{
    rq.noalias() = M * qdd;
    rq -= f;
    if (lambda.size() > 0)
        rq.noalias() += Phi_q.transpose() * lambda;
}

ga_status Model::stiffness(double t, const Vec &q, const Vec &v, const Vec &qdd,
                           const Vec &lambda, const Vec &rq, Mat &K)
{
    count(counters_, GA_COUNT_STIFFNESS_EVALS);
    if (cb.stiffness && tangent_mode == GA_TANGENT_AUTO) {
        if (auto st = callback_status(cb.stiffness(t, q.data(), v.data(), qdd.data(),
                                                   lambda.data(), K.data(), cb.user),
                                      "stiffness", t))
            return st;
        return check_finite(K.data(), n_, n_, "tangent stiffness K_t", t);
    }
    // Column j of d r^q/dq by a forward difference; includes the derivatives of M(q) qdd and
    // of Phi_q(q)^T lambda, which structural codes often drop.
    q_pert_ = q;
    for (int j = 0; j < n_; ++j) {
        const double e = fd_increment(q[j]);
        q_pert_[j] = q[j] + e;
        if (auto st = mass(t, q_pert_, M_pert_))
            return st;
        if (auto st = force(t, q_pert_, v, f_pert_))
            return st;
        if (auto st = jacobian(t, q_pert_, J_pert_))
            return st;
        dynamics_residual(M_pert_, qdd, f_pert_, J_pert_, lambda, r_pert_);
        K.col(j) = (r_pert_ - rq) / e;
        q_pert_[j] = q[j];
    }
    return GA_OK;
}

ga_status Model::damping(double t, const Vec &q, const Vec &v, const Vec &f, Mat &C)
{
    count(counters_, GA_COUNT_DAMPING_EVALS);
    if (cb.damping && tangent_mode == GA_TANGENT_AUTO) {
        if (auto st = callback_status(cb.damping(t, q.data(), v.data(), C.data(), cb.user),
                                      "damping", t))
            return st;
        return check_finite(C.data(), n_, n_, "tangent damping C_t", t);
    }
    if (!cb.force) {
        C.setZero();
        return GA_OK;
    }
    v_pert_ = v;
    for (int j = 0; j < n_; ++j) {
        const double e = fd_increment(v[j]);
        v_pert_[j] = v[j] + e;
        if (auto st = force(t, q, v_pert_, f_pert_))
            return st;
        C.col(j) = -(f_pert_ - f) / e;
        v_pert_[j] = v[j];
    }
    return GA_OK;
}

ga_status Model::constraint_dt(double t, const Vec &q, Vec &out)
{
    if (m_ == 0)
        return GA_OK;
    // Central difference in t. For constraints that do not depend on t both evaluations are
    // identical and Phi_t = 0 exactly.
    const double d = std::cbrt(kEps) * std::max(std::fabs(t), 1.0);
    if (auto st = constraint(t + d, q, phi_plus_))
        return st;
    if (auto st = constraint(t - d, q, phi_minus_))
        return st;
    out = (phi_plus_ - phi_minus_) / (2.0 * d);
    return GA_OK;
}

ga_status Model::constraint_accel(double t, const Vec &q, const Vec &v, Vec &out)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_ACCEL_EVALS);
    if (cb.constraint_accel) {
        if (auto st = callback_status(cb.constraint_accel(t, q.data(), v.data(), out.data(),
                                                          cb.user),
                                      "constraint_accel", t))
            return st;
        return check_finite(out.data(), m_, 1, "constraint acceleration term", t);
    }
    // Along the path s -> (q + s v, t + s) the velocity constraint is
    // g(s) = Phi_q v + Phi_t, and g'(0) = Phi_qq(v, v) + 2 Phi_qt v + Phi_tt. Central
    // difference of g, with an increment that moves q by ~cbrt(eps) relative to its size.
    const double qscale = std::max(q.lpNorm<Eigen::Infinity>(), 1.0);
    const double vscale = std::max(v.lpNorm<Eigen::Infinity>(), 1.0);
    const double s = std::cbrt(kEps) * qscale / vscale;
    for (int side = 0; side < 2; ++side) {
        const double sig = side == 0 ? s : -s;
        Vec &g = side == 0 ? g_plus_ : g_minus_;
        q_pert_ = q + sig * v;
        if (auto st = jacobian(t + sig, q_pert_, J_pert_))
            return st;
        if (auto st = constraint_dt(t + sig, q_pert_, g))
            return st;
        g.noalias() += J_pert_ * v;
    }
    out = (g_plus_ - g_minus_) / (2.0 * s);
    return GA_OK;
}

}  // namespace ga
