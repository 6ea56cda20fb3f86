// The Newton stopping test of galpha (ALGORITHMS.md sec. 4.6: increments, not residuals).
//
// After each Newton update, with dq the position increment (and beta' dq the acceleration
// increment, eq. 7) and dlambda the multiplier increment, the step is converged when
//
//     ratio = max( |dq|/(tol |q|), |beta' dq|/(tol |qdd|), |dlambda|/(tol |lambda|) ) <= 1
//
// (max-norms over the vectors), or when the iteration has reached round-off: two successive
// position increments within a few ulps of |q|. Every quantity is measured in its own units,
// so the test means the same for every h; the round-off exit is needed because index-3
// accelerations and multipliers are only determined to ~eps |q| / (beta h^2) (paper, sec. 3.3),
// which exceeds tol |lambda| once h is small enough.
#pragma once

#include "types.hpp"

namespace ga {

class ConvergenceTest {
public:
    void reset()
    {
        iteration_ = 0;
        ratio_ = 0.0;
        previous_dq_at_roundoff_ = false;
    }

    // Returns true when converged after the update with these increments (q, qdd, lambda
    // already updated).
    bool converged(double tol, const Vec &dq, double beta_prime, const Vec &dlambda,
                   const Vec &q, const Vec &qdd, const Vec &lambda);

    double ratio() const { return ratio_; }  // last ratio, for messages

private:
    int iteration_ = 0;
    double ratio_ = 0.0;
    bool previous_dq_at_roundoff_ = false;
};

}  // namespace ga
