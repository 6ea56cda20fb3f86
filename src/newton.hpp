// The Newton stopping test of galpha (docs/algorithms.md sec. 4.6: increments, not residuals).
//
// After each Newton update, with dq the position increment, dw the increment that moves the
// accelerations (qdd += beta' dw, v += gamma' dw; dw = dq except in the stabilized index-2
// form) and dlambda the multiplier increment, each quantity's update is measured against the
// tolerance in its own units (max-norms over the vectors):
//
//     e_q = |dq| / (tol |q|),   e_a = |beta' dw| / (tol |qdd|),   e_l = |dlambda| / (tol |lambda|)
//
// and each has its own contraction rate theta_k = e_k / e_k(previous update): the quantities
// converge at different rates with an old matrix (in the index-2 form its accelerations can
// stall while its multipliers contract by 1e-5), so a rate taken from the largest of them
// would be that of whichever dominates, not of the one that is left. The step is converged
// when every quantity is
//   - within the tolerance, e_k <= 1, or
//   - predicted within it by its own rate, e_k theta_k / (1 - theta_k) <= 1 (in the first
//     update with a reused matrix, theta from the previous step, as SUNDIALS IDA does) --
//     unless a matrix factorized in this step has already seen the iteration diverge: then a
//     rate is one ratio of a chaotic sequence (a 20-iteration divergence on a 30 000-link
//     chain ended on one drop of 3e-5 and was taken as converged, far from any root), or
//   - at its round-off floor and no longer improving: its increment is within the floor and
//     either stagnates (theta_k >= 1/2: what is left is noise) or was computed with a matrix
//     factorized in this step near the current q (one Newton update with the current matrix
//     at fixed q solves the equations, linear in lambda and qdd once q stays), or
//   - in the stabilized index-2 form, stagnating (theta_k >= 1/2) with a matrix factorized in
//     this step near the current q, q at its floor and the Newmark increment within q's floor
//     (accelerations), or q and the accelerations so (multipliers): on an ill-conditioned
//     system (a 100 000-link chain) the solve resolves lambda and w only to what it makes of
//     the residual's round-off, above the floors from v, and the iteration would never end.
// First-order states (docs/algorithms.md sec. 9) are two more quantities of the same kind:
// e_y = |dy| / (tol |y|) and e_y' = |c1 dy| / (tol |y'|), floor 64 ulps of |y| (times c1), where
// |y| and |y'| include what q's own size makes of them through the coupling (first_order.cpp); with
// none (r = 0) both are 0 and at their floor, and the test is the one before them.
// Floors: positions 64 ulps of |q|; accelerations beta' times the floor of dw (that of q in
// index 3, where qdd is known only to eps |q| / (beta h^2), paper sec. 3.3; 64 ulps of |v|
// over gamma' in index 2, where v is fixed by the velocity constraint); multipliers the
// relative floor of the accelerations. Stopping at a floor only when the iteration stagnates
// matters for small h: a floor is a bound, and an update within it can still be far above
// the noise (an index-3 velocity moves by gamma' dq).
// Verdict Slow: a quantity not at its floor does not contract (theta_k >= 1), or at its rate
// cannot reach the tolerance within a budget of 4 iterations with one matrix (the criterion of
// SciPy's Radau, with IDA's maxcor): a reused matrix should be rebuilt now.
#pragma once

#include <array>

#include "types.hpp"

namespace ga {

// The max-norms of one Newton update and of the iterate it produced: all the stopping test
// reads. The solver takes them in the pass that applies the update.
struct UpdateSizes {
    double dq = 0.0, dw = 0.0, dlambda = 0.0;           // increments
    double q = 0.0, v = 0.0, qdd = 0.0, lambda = 0.0;   // the updated iterate
    double dy = 0.0, y = 0.0, ydot = 0.0, c1 = 0.0;     // first-order states: |dy|, scales of
                                                        // y and y' (first_order.cpp), c1
    bool dw_is_dq = true;  // index 3: the accelerations move with the positions
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
        previous_.fill(-1.0);
        theta_prev_ = theta_prev;
        rate_ = -1.0;
        previous_dq_at_roundoff_ = false;
        with_matrix_ = 0;
        fresh_matrix_ = false;
        diverged_ = false;
        moved_since_matrix_ = 0.0;
    }
    // The iteration matrix was rebuilt: rates across the change mean nothing.
    void matrix_changed()
    {
        previous_.fill(-1.0);
        theta_prev_ = -1.0;
        with_matrix_ = 0;
        fresh_matrix_ = true;
        moved_since_matrix_ = 0.0;
    }

    Verdict check(double tol, const UpdateSizes &size, double beta_prime, double gamma_prime);

    double ratio() const { return ratio_; }  // largest e_k of the last update
    // largest contraction rate measured in the last update, over the quantities above their
    // floors (< 0: none yet)
    double rate() const { return rate_; }
    int iterations_with_matrix() const { return with_matrix_; }
    // a matrix factorized in this step saw an increment grow (see check)
    bool diverged() const { return diverged_; }
    // the last position increment was within its round-off floor
    bool at_roundoff() const { return previous_dq_at_roundoff_; }

private:
    int iteration_ = 0;
    double ratio_ = 0.0, theta_prev_ = -1.0, rate_ = -1.0;
    std::array<double, 5> previous_{{-1.0, -1.0, -1.0, -1.0, -1.0}};  // e_q, e_a, e_l, e_y, e_y'
    bool previous_dq_at_roundoff_ = false;
    int with_matrix_ = 0;  // iterations with the current matrix in this step
    bool fresh_matrix_ = false;        // the matrix was factorized in this step
    bool diverged_ = false;            // a matrix of this step saw an increment grow
    double moved_since_matrix_ = 0.0;  // sum of |dq| / (tol |q|) since then
};

}  // namespace ga
