// Static equilibrium of a large model on the saddle-point factorization (docs/algorithms.md
// sec. 15, "Large models"): Newton on (r, Phi) = 0 bordered by the constraints,
//     [K_t  Phi_q^T] [dq      ]   [ f  ]
//     [Phi_q   0   ] [lambda+ ] = [-Phi],
// with the backtracking line search of the dense path. The dense path's null space would be
// n x n; here nothing is, so redundant constraints make S singular and are refused.
#include <algorithm>
#include <cmath>
#include <limits>

#include "at_rest.hpp"
#include "operating_point.hpp"
#include "saddle_at_rest.hpp"

namespace ga {

ga_status static_equilibrium_saddle(Stepper &kernel, double t, double *q_io, double *lambda_out,
                                    double tol, int max_iter)
{
    SaddleAtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    Vec q = Eigen::Map<const Vec>(q_io, n);
    if (!all_finite(q))
        return at.diag().fail(GA_ERR_ARG, "ga_static_equilibrium: q is not finite");
    Vec lambda, r, rhs(n + m);
    const auto evaluate = [&](const Vec &x) -> ga_status {
        if (auto st = at.force(x))
            return st;
        if (auto st = at.jacobian(x))
            return st;
        return at.constraint(x);
    };
    if (auto st = evaluate(q))
        return st;
    if (auto st = at.mass(q))
        return st;
    if (!at.balancing_multipliers(lambda))
        return at.diag().fail(GA_ERR_SINGULAR,
                              "ga_static_equilibrium: [M, Phi_q^T; Phi_q, 0] is singular at the "
                              "start (redundant constraints, which the sparse path does not "
                              "drop, or a free direction without mass)");
    const auto merit = [&] { return r.squaredNorm() + (m > 0 ? at.phi.squaredNorm() : 0.0); };
    at.residual(lambda, r);
    double m0 = merit(), last_step = 0.0;
    // a root to round-off, as on the dense path (operating_point.cpp)
    const auto at_roundoff = [&] {
        const double eps = std::numeric_limits<double>::epsilon();
        const double elastic = at.max_abs_stiffness() * std::max(1.0, rest::max_abs(q));
        const double fscale =
            std::max({at.max_abs_f(), at.max_abs_constraint_force(lambda), elastic});
        return rest::max_abs(r) <= 8.0 * eps * fscale &&
               (m == 0 || rest::max_abs(at.phi) <= 8.0 * eps * std::max(1.0, rest::max_abs(q)));
    };
    const auto accept = [&]() -> ga_status {
        if (auto st = at.mass(q))
            return st;
        if (!at.balancing_multipliers(lambda))  // the multipliers at the root itself
            return at.diag().fail(GA_ERR_SINGULAR, "ga_static_equilibrium: [M, Phi_q^T; "
                                                   "Phi_q, 0] is singular at the equilibrium");
        Eigen::Map<Vec>(q_io, n) = q;
        if (lambda_out && m > 0)
            Eigen::Map<Vec>(lambda_out, m) = lambda;
        return GA_OK;
    };
    Vec qn(n), ln;
    for (int it = 1; it <= max_iter; ++it) {
        if (auto st = at.stiffness(q, lambda))
            return st;
        if (at_roundoff())
            return accept();
        if (!at.factorize(0.0, 1.0))
            return at.diag().fail(
                GA_ERR_SINGULAR,
                "ga_static_equilibrium: [K_t, Phi_q^T; Phi_q, 0] is singular at iteration %d: a "
                "limit point, a motion no force restrains, or redundant constraints (which "
                "the sparse path does not drop)",
                it);
        rhs.head(n) = at.f;
        if (m > 0)
            rhs.tail(m) = -at.phi;
        at.solve(rhs);
        const Vec dq = rhs.head(n);
        const Vec dl = rhs.tail(m) - lambda;
        if (!all_finite(dq) || !all_finite(dl))
            return at.diag().fail(GA_ERR_NONFINITE,
                                  "ga_static_equilibrium: the Newton increment is not finite "
                                  "at iteration %d",
                                  it);
        // within tol by Newton's own estimate: converged, as on the dense path
        const bool within_tol = rest::max_abs(dq) <= tol * std::max(1.0, rest::max_abs(q));
        double alpha = 1.0, m1 = 0.0;
        for (;;) {
            kernel.model.space.shifted(q, alpha, dq, qn);
            ln = lambda + alpha * dl;
            if (auto st = evaluate(qn))
                return st;
            at.residual(ln, r);
            m1 = merit();
            if (m1 <= (1.0 - 1e-4 * alpha) * m0 || m1 == 0.0)
                break;
            alpha *= 0.5;
            if (alpha < 1.0 / 1024.0) {
                if (auto st = evaluate(q))  // back to q for the round-off test
                    return st;
                at.residual(lambda, r);
                if (within_tol || at_roundoff())
                    return accept();
                return at.diag().fail(
                    GA_ERR_NEWTON,
                    "ga_static_equilibrium: no equilibrium in reach: at iteration %d no step "
                    "along Newton's direction down to 1/1024 of it reduces the residual (%.3g; "
                    "the stiffness may change sign on the way: a limit point)",
                    it, std::sqrt(m0));
            }
        }
        last_step = alpha * rest::max_abs(dq);
        q = qn;
        lambda = ln;
        m0 = m1;
        if (alpha == 1.0 && last_step <= tol * std::max(1.0, rest::max_abs(q)))
            return accept();
    }
    if (auto st = evaluate(q))
        return st;
    at.residual(lambda, r);
    if (auto st = at.stiffness(q, lambda))
        return st;
    if (at_roundoff())
        return accept();
    return at.diag().fail(GA_ERR_NEWTON,
                          "ga_static_equilibrium: no equilibrium in %d iterations (last step "
                          "%.3g, residual %.3g)",
                          max_iter, last_step, std::sqrt(m0));
}

}  // namespace ga
