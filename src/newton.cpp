#include "newton.hpp"

#include <algorithm>
#include <limits>

namespace ga {

namespace {
// |increment| / (tol |value|), with 0/0 = 0 (an exactly zero quantity that does not move).
double relative(double increment, double tol, double value)
{
    if (increment == 0.0)
        return 0.0;
    const double denom = tol * value;
    if (denom <= 0.0)
        return std::numeric_limits<double>::infinity();
    return increment / denom;
}
}  // namespace

bool ConvergenceTest::converged(double tol, const Vec &dq, double beta_prime,
                                const Vec &dlambda, const Vec &q, const Vec &qdd,
                                const Vec &lambda)
{
    ++iteration_;
    const double dq_norm = dq.lpNorm<Eigen::Infinity>();
    const double q_norm = q.lpNorm<Eigen::Infinity>();
    double r = std::max(relative(dq_norm, tol, q_norm),
                        relative(beta_prime * dq_norm, tol, qdd.lpNorm<Eigen::Infinity>()));
    if (dlambda.size() > 0)
        r = std::max(r, relative(dlambda.lpNorm<Eigen::Infinity>(), tol,
                                 lambda.lpNorm<Eigen::Infinity>()));
    ratio_ = r;
    if (r <= 1.0)
        return true;

    // Round-off exit: positions no longer move. With q fixed the equations are linear in qdd
    // and lambda, so the iteration after the first such increment has already corrected them.
    const double roundoff = 64.0 * std::numeric_limits<double>::epsilon() * q_norm;
    const bool at_roundoff = dq_norm <= roundoff;
    const bool stop = at_roundoff && previous_dq_at_roundoff_;
    previous_dq_at_roundoff_ = at_roundoff;
    return stop;
}

}  // namespace ga
