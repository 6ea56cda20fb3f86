// The Newton stopping test of galpha (ALGORITHMS.md sec. 4.6: increments, not residuals).
//
// After each Newton update, with dq the position increment (and beta' dq the acceleration
// increment, eq. 7) and dlambda the multiplier increment, the size of the update relative to
// the tolerance is
//
//     eta = max( |dq|/(tol |q|), |beta' dq|/(tol |qdd|), |dlambda|/(tol |lambda|) )
//
// (max-norms over the vectors): every quantity is measured in its own units, so the test means
// the same for every h. The step is converged when
//   - eta <= 1, or
//   - the error left after the update, estimated from the contraction rate theta as
//     eta theta / (1 - theta), is <= 1 (theta from the last two increments; in the first
//     iteration with a reused matrix, from the previous step, as SUNDIALS IDA does), or
//   - the iteration has reached round-off: two successive position increments within a few
//     ulps of |q|, or one if the matrix was factorized in this step at an iterate within
//     tol |q| of the current one (within round-off where tol is below it). This exit is
//     needed because index-3 accelerations and multipliers are only determined to
//     ~eps |q| / (beta h^2) (paper, sec. 3.3), which exceeds tol |lambda| once h is small
//     enough or |q| large (a chain of 10 000 links at h = 1e-3 and tol = 1e-10: increments
//     of lambda stay at ~4e5 tol |lambda|).
//     Why one can suffice: an increment that leaves q in place was computed from a residual
//     at (nearly) the final q, where the equations are linear in lambda; the update solved
//     them with the matrix's Phi_q^T, exact up to the change of Phi_q since the
//     factorization. With a matrix of this step that change is within the tolerance, so a
//     further iteration would only add round-off of the same size (measured: the third
//     increment equals the second to 1 %).
// Verdict Slow: at the measured rate the iteration cannot reach the tolerance within a budget
// of 4 iterations with one matrix (the criterion of SciPy's Radau, with IDA's maxcor), so a
// reused matrix should be rebuilt now rather than iterated on.
#pragma once

#include "types.hpp"

namespace ga {

// The max-norms of one Newton update and of the iterate it produced: all the stopping test
// reads. The solver takes them in the pass that applies the update.
struct UpdateSizes {
    double dq = 0.0, dw = 0.0, dlambda = 0.0;  // increments (dw: see ConvergenceTest::check)
    double q = 0.0, qdd = 0.0, lambda = 0.0;   // the updated iterate
    bool increments_finite = true, iterate_finite = true;
};

class ConvergenceTest {
public:
    enum class Verdict { Converged, Continue, Slow };

    // theta_prev: contraction rate seen in the previous step with the same matrix (< 0: none).
    void reset(double theta_prev)
    {
        iteration_ = 0;
        ratio_ = 0.0;
        previous_ratio_ = -1.0;
        theta_prev_ = theta_prev;
        rate_ = -1.0;
        previous_dq_at_roundoff_ = false;
        with_matrix_ = 0;
        fresh_matrix_ = false;
        moved_since_matrix_ = 0.0;
    }
    // The iteration matrix was rebuilt: rates across the change mean nothing.
    void matrix_changed()
    {
        previous_ratio_ = -1.0;
        theta_prev_ = -1.0;
        with_matrix_ = 0;
        fresh_matrix_ = true;
        moved_since_matrix_ = 0.0;
    }

    // size.dq: of the position increment; size.dw: of the increment that moves the
    // accelerations (qdd += beta' dw; the same vector as dq except in the stabilized index-2
    // formulation).
    Verdict check(double tol, const UpdateSizes &size, double beta_prime);

    double ratio() const { return ratio_; }  // eta of the last update
    double rate() const { return rate_; }    // last measured theta (< 0: none yet)
    int iterations_with_matrix() const { return with_matrix_; }
    // the last position increment was within a few ulps of |q|: rates measure noise
    bool at_roundoff() const { return previous_dq_at_roundoff_; }

private:
    int iteration_ = 0;
    double ratio_ = 0.0, previous_ratio_ = -1.0, theta_prev_ = -1.0, rate_ = -1.0;
    bool previous_dq_at_roundoff_ = false;
    int with_matrix_ = 0;  // iterations with the current matrix in this step
    bool fresh_matrix_ = false;        // the matrix was factorized in this step
    double moved_since_matrix_ = 0.0;  // sum of |dq| / (tol |q|) since then
};

}  // namespace ga
