// Consistent initial values (ALGORITHMS.md sec. 3): positions and velocities onto the
// constraint manifold by minimum-norm corrections, then qdd0 and lambda0 from the
// saddle-point system with the acceleration-level constraint, and a0 = qdd0 (eq. 3).
#include <algorithm>
#include <cmath>
#include <limits>

#include "solver.hpp"

namespace ga {

namespace {
constexpr int kMaxProjectionIterations = 50;
const double kEps = std::numeric_limits<double>::epsilon();

double max_abs(const ModelMatrix &A)
{
    return A.size() ? Eigen::Map<const Vec>(A.data(), A.size()).cwiseAbs().maxCoeff() : 0.0;
}

Eigen::Index argmax_abs(const Vec &x)
{
    Eigen::Index i = 0;
    if (x.size() > 0)
        x.cwiseAbs().maxCoeff(&i);
    return i;
}
}  // namespace

ga_status Solver::init(double t0, const double *q0, const double *v0)
{
    if (auto st = setup())
        return st;
    invalidate_jacobian();
    State &x = trial_;
    x.t = t0;
    x.h_last = 0.0;
    x.q = Eigen::Map<const Vec>(q0, n_);
    x.v = Eigen::Map<const Vec>(v0, n_);
    if (!x.q.allFinite() || !x.v.allFinite())
        return diag.fail(GA_ERR_ARG, "q0 or v0 contains NaN or Inf");

    if (m_ > 0) {
        if (auto st = project_positions(t0, x.q))
            return st;
        if (auto st = project_velocities(t0, x.q, x.v))
            return st;
    }

    // [M Phi_q^T; Phi_q 0] [qdd0; lambda0] = [f; -(Phi_qq(v,v) + 2 Phi_qt v + Phi_tt)].
    // The first block row is multiplied by sigma = max|Phi_q| / max|M| so that both blocks
    // have the same size; the unknown in the second block is then sigma lambda0.
    ga_status st = model.mass(t0, x.q, M_);
    if (!st)
        st = model.force(t0, x.q, x.v, f_);
    if (!st)
        st = model.jacobian(t0, x.q, J_);
    if (!st)
        st = model.constraint_accel(t0, x.q, x.v, c_);
    if (st) {
        diag.append(" (consistent initial accelerations at t0 = %.17g)", t0);
        return st;
    }
    mass_valid_ = model.constant_mass;
    double sigma = 1.0;
    const double mmax = max_abs(M_), jmax = max_abs(J_);
    if (mmax > 0.0 && jmax > 0.0)
        sigma = jmax / mmax;
    count(counters, GA_COUNT_FACTORIZATIONS);
    if (!S_.factorize_kkt(M_, sigma, J_))
        return diag.fail(GA_ERR_SINGULAR,
                         "saddle-point matrix [M Phi_q^T; Phi_q 0] is singular at t0 = %.17g "
                         "(rcond = %.3g): redundant constraints, or M singular on the null "
                         "space of Phi_q",
                         t0, S_.rcond());
    rq_ = -sigma * f_;
    S_.solve(rq_, c_, x.qdd, x.lambda);
    if (m_ > 0)
        x.lambda /= sigma;
    if (!x.qdd.allFinite() || !x.lambda.allFinite())
        return diag.fail(GA_ERR_NONFINITE, "initial accelerations or multipliers are not finite");
    x.a = x.qdd;  // eq. (3): a_0 = qdd_0

    accepted_.swap(trial_);
    initialized_ = true;
    return GA_OK;
}

ga_status Solver::project_positions(double t, Vec &q)
{
    if (auto st = model.constraint(t, q, phi_))
        return st;
    double norm = phi_.lpNorm<Eigen::Infinity>();
    if (norm <= init_tol)
        return GA_OK;
    if (init_mode == GA_INIT_REFUSE)
        return diag.fail(GA_ERR_INCONSISTENT,
                         "q0 violates the constraints: |Phi(q0)|_inf = %.3g (constraint %ld) > "
                         "init_tol = %.3g, and projection is off (GA_INIT_REFUSE)",
                         norm, static_cast<long>(argmax_abs(phi_)), init_tol);
    // Gauss-Newton for the minimum-norm correction:
    // [I Phi_q^T; Phi_q 0] [dq; mu] = -[0; Phi], until round-off.
    const double norm0 = norm;
    rq_.setZero();
    for (int it = 0; it < kMaxProjectionIterations; ++it) {
        if (auto st = model.jacobian(t, q, J_))
            return st;
        count(counters, GA_COUNT_FACTORIZATIONS);
        if (!S_.factorize_projection(J_))
            return diag.fail(GA_ERR_SINGULAR,
                             "cannot project q0: Phi_q is rank deficient (rcond of "
                             "[I Phi_q^T; Phi_q 0] = %.3g) at projection iteration %d",
                             S_.rcond(), it + 1);
        S_.solve(rq_, phi_, dq_, dlambda_);
        q += dq_;
        if (auto st = model.constraint(t, q, phi_))
            return st;
        const double previous = norm;
        norm = phi_.lpNorm<Eigen::Infinity>();
        if (!std::isfinite(norm) || norm > 1e6 * std::max(norm0, init_tol))
            break;  // diverging
        const bool roundoff = dq_.lpNorm<Eigen::Infinity>() <=
                              16.0 * kEps * std::max(q.lpNorm<Eigen::Infinity>(), 1.0);
        if (norm <= init_tol && (norm == 0.0 || roundoff || norm > 0.5 * previous))
            return GA_OK;
    }
    return diag.fail(GA_ERR_INCONSISTENT,
                     "projection of q0 onto Phi(q, t0) = 0 failed: |Phi|_inf = %.3g after the "
                     "Gauss-Newton iterations (init_tol = %.3g, |Phi(q0)|_inf = %.3g)",
                     norm, init_tol, norm0);
}

ga_status Solver::project_velocities(double t, const Vec &q, Vec &v)
{
    // Velocity constraint w = Phi_q v + Phi_t.
    if (auto st = model.jacobian(t, q, J_))
        return st;
    if (auto st = model.constraint_dt(t, q, c_))
        return st;
    phi_ = c_;
    J_.multiply_add(1.0, v, phi_);
    const double norm0 = phi_.lpNorm<Eigen::Infinity>();
    if (norm0 <= init_tol)
        return GA_OK;
    if (init_mode == GA_INIT_REFUSE)
        return diag.fail(GA_ERR_INCONSISTENT,
                         "v0 violates the velocity constraints: |Phi_q v0 + Phi_t|_inf = %.3g "
                         "(constraint %ld) > init_tol = %.3g, and projection is off "
                         "(GA_INIT_REFUSE)",
                         norm0, static_cast<long>(argmax_abs(phi_)), init_tol);
    // Linear: one minimum-norm correction, plus one pass of refinement for round-off.
    count(counters, GA_COUNT_FACTORIZATIONS);
    if (!S_.factorize_projection(J_))
        return diag.fail(GA_ERR_SINGULAR,
                         "cannot project v0: Phi_q is rank deficient (rcond of "
                         "[I Phi_q^T; Phi_q 0] = %.3g)",
                         S_.rcond());
    rq_.setZero();
    for (int pass = 0; pass < 2; ++pass) {
        S_.solve(rq_, phi_, dq_, dlambda_);
        v += dq_;
        phi_ = c_;
        J_.multiply_add(1.0, v, phi_);
    }
    const double norm = phi_.lpNorm<Eigen::Infinity>();
    if (!(norm <= init_tol))
        return diag.fail(GA_ERR_INCONSISTENT,
                         "projection of v0 failed: |Phi_q v + Phi_t|_inf = %.3g > init_tol = "
                         "%.3g",
                         norm, init_tol);
    return GA_OK;
}

}  // namespace ga
