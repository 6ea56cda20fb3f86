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
// An increment within its floor that shrank by less than this factor is noise.
constexpr double kStagnation = 0.5;
// A rate is kept below this: a quantity that became exactly zero after a nonzero increment
// has an infinite ratio, and the rate is carried to the next step and into checkpoints.
constexpr double kMaxRate = 1e6;
// The round-off floor of the positions, in ulps of |q|.
constexpr double kFloorUlps = 64.0;
}  // namespace

ConvergenceTest::Verdict ConvergenceTest::check(double tol, const UpdateSizes &size,
                                                double beta_prime, double gamma_prime)
{
    ++iteration_;
    ++with_matrix_;
    enum { Q, A, L, Y, YD, K };
    const std::array<double, K> e = {relative(size.dq, tol, size.q),
                                     relative(beta_prime * size.dw, tol, size.qdd),
                                     relative(size.dlambda, tol, size.lambda),
                                     relative(size.dy, tol, size.y),
                                     relative(size.c1 * size.dy, tol, size.ydot)};
    ratio_ = std::max({e[Q], e[A], e[L], e[Y], e[YD]});

    // Round-off floors (newton.hpp).
    const double ulps = kFloorUlps * std::numeric_limits<double>::epsilon();
    const double q_floor = ulps * size.q;
    const double dw_floor = size.dw_is_dq         ? q_floor
                            : gamma_prime > 0.0 ? ulps * size.v / gamma_prime
                                                : 0.0;
    const double relative_qdd_floor = size.qdd > 0.0 ? beta_prime * dw_floor / size.qdd : 0.0;
    const bool y_at_floor = size.dy <= ulps * size.y;
    const std::array<bool, K> at_floor = {size.dq <= q_floor, size.dw <= dw_floor,
                                          size.dlambda <= relative_qdd_floor * size.lambda,
                                          y_at_floor, y_at_floor};

    // One update at the floor with a matrix factorized in this step at an iterate within the
    // tolerance (within round-off where the tolerance is below it) of the current one: it
    // solved the equations, linear in lambda and qdd once q stays.
    moved_since_matrix_ += e[Q];
    const double moved_limit = std::max(1.0, ulps / tol);
    const bool near_matrix = fresh_matrix_ && moved_since_matrix_ <= moved_limit;
    const bool matrix_current = near_matrix && at_floor[Q] && at_floor[A] && at_floor[Y];
    // Index 2 on an ill-conditioned system (a 100 000-link chain): w and lambda are known
    // only to what the solve makes of the residual's round-off, above their floors from v.
    // With q at its floor and a matrix of this q, an increment that stagnates there is noise
    // if w moves q no more than q's own round-off (the index-3 floor of the accelerations).
    const bool w_within_q_floor = size.dw <= q_floor;
    const std::array<bool, K> stalled_floor = {
        false, near_matrix && at_floor[Q] && w_within_q_floor,
        near_matrix && at_floor[Q] && (at_floor[A] || w_within_q_floor) && at_floor[Y], false,
        false};

    previous_dq_at_roundoff_ = at_floor[Q];
    if (matrix_current) {
        previous_ = e;
        return Verdict::Converged;
    }

    std::array<double, K> theta;
    std::array<bool, K> measured, done;
    double rate = -1.0;
    bool converged = true;
    for (int k = 0; k < K; ++k) {
        // A rate needs two finite ratios: an increment of a quantity that was exactly zero
        // has an infinite ratio, and e / inf = 0 would claim convergence.
        measured[k] = previous_[k] > 0.0 && std::isfinite(previous_[k]);
        theta[k] = measured[k]        ? e[k] / previous_[k]
                   : theta_prev_ >= 0 ? std::max(theta_prev_, kMinTrustedRate)
                                      : -1.0;
        const bool noise =
            (at_floor[k] || stalled_floor[k]) && measured[k] && theta[k] >= kStagnation;
        if (measured[k] && !at_floor[k] && !noise) {
            rate = std::max(rate, std::min(theta[k], kMaxRate));
            if (fresh_matrix_ && theta[k] >= 1.0)
                diverged_ = true;
        }
        const bool within = e[k] <= 1.0;
        const bool predicted = !diverged_ && theta[k] >= 0.0 && theta[k] < 1.0 &&
                               e[k] * theta[k] / (1.0 - theta[k]) <= 1.0;
        done[k] = within || predicted || noise;
        converged = converged && done[k];
    }
    previous_ = e;
    if (rate >= 0.0)
        rate_ = rate;
    if (converged)
        return Verdict::Converged;

    // Positions at their floor with a matrix of an earlier step, and something else not yet
    // converged: iterating on would feed the round-off of q through the old Phi_q into v and
    // qdd at every update (gamma' and beta' times it). A matrix of the current q ends the step
    // in one update instead.
    if (at_floor[Q] && !fresh_matrix_)
        return Verdict::Slow;
    // Not converged: is this matrix too slow for what is left above the floors?
    for (int k = 0; k < K; ++k) {
        if (done[k] || at_floor[k])
            continue;
        if (with_matrix_ >= kIterationBudget || theta[k] >= 1.0)
            return Verdict::Slow;
        // error predicted after the iterations left in the budget (from a measured rate)
        if (measured[k] && theta[k] > 0.0 &&
            e[k] * std::pow(theta[k], kIterationBudget - with_matrix_) / (1.0 - theta[k]) > 1.0)
            return Verdict::Slow;
    }
    return Verdict::Continue;
}

}  // namespace ga
