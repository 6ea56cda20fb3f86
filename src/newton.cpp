#include "newton.hpp"

#include <algorithm>
#include <cmath>
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

// A rate measured in a previous step is trusted no further than this: quadratic convergence
// seen once says little about a reused matrix.
constexpr double kMinTrustedRate = 0.05;
// Iterations one matrix is given to converge before it counts as too slow.
constexpr int kIterationBudget = 4;
}  // namespace

ConvergenceTest::Verdict ConvergenceTest::check(double tol, const UpdateSizes &size,
                                                double beta_prime)
{
    ++iteration_;
    ++with_matrix_;
    const double dq_norm = size.dq, q_norm = size.q;
    double eta = std::max(relative(dq_norm, tol, q_norm),
                          relative(beta_prime * size.dw, tol, size.qdd));
    eta = std::max(eta, relative(size.dlambda, tol, size.lambda));  // 0 without constraints
    ratio_ = eta;

    double theta = -1.0;
    // A rate needs two finite ratios: an increment of a quantity that was exactly zero has an
    // infinite ratio, and eta / inf = 0 would claim convergence after any second increment.
    const bool measured = previous_ratio_ > 0.0 && std::isfinite(previous_ratio_);
    if (measured) {
        theta = eta / previous_ratio_;
        rate_ = theta;
    } else if (theta_prev_ >= 0.0) {
        theta = std::max(theta_prev_, kMinTrustedRate);
    }
    previous_ratio_ = eta;

    if (eta <= 1.0)
        return Verdict::Converged;
    if (theta >= 0.0 && theta < 1.0 && eta * theta / (1.0 - theta) <= 1.0)
        return Verdict::Converged;

    // Round-off exit: positions no longer move. With q fixed the equations are linear in
    // lambda (qdd follows q, eq. 7), so the update that found q in place has corrected lambda
    // as far as the matrix's Phi_q^T is that of the current q: at once if the matrix is of
    // this step and q has moved within the tolerance since (the accelerations' increment dw
    // at round-off too, for the index-2 form, where it differs from dq); otherwise after a
    // second such increment.
    const double ulps = 64.0 * std::numeric_limits<double>::epsilon();
    const double roundoff = ulps * q_norm;
    const bool dq_at_roundoff = dq_norm <= roundoff;
    moved_since_matrix_ += relative(dq_norm, tol, q_norm);
    // "within the tolerance" is within round-off where the tolerance is below it
    const double moved_limit = std::max(1.0, ulps / tol);
    const bool matrix_current =
        fresh_matrix_ && moved_since_matrix_ <= moved_limit && size.dw <= roundoff;
    const bool stop = dq_at_roundoff && (previous_dq_at_roundoff_ || matrix_current);
    previous_dq_at_roundoff_ = dq_at_roundoff;
    if (stop)
        return Verdict::Converged;
    if (!dq_at_roundoff) {
        if (with_matrix_ >= kIterationBudget)
            return Verdict::Slow;
        if (theta >= 1.0)
            return Verdict::Slow;
        // error predicted after the iterations left in the budget (from a measured rate)
        if (measured && theta > 0.0 &&
            eta * std::pow(theta, kIterationBudget - with_matrix_) / (1.0 - theta) > 1.0)
            return Verdict::Slow;
    }
    return Verdict::Continue;
}

}  // namespace ga
