// The Newton stopping test (src/newton.hpp), fed update sizes directly: the round-off exit.
// The numbers are those of a chain of 10 000 links at h = 1e-3, tol = 1e-10 (|q| = 1e4): after
// the first update the positions are converged, but the multipliers keep moving by ~4e5 tol
// |lambda|, the round-off of accelerations known to eps |q| / (beta h^2). Whether one update
// at round-off ends the step depends on where the matrix comes from (newton.hpp's comment).
#include <cmath>
#include <limits>

#include "newton.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

using ga::ConvergenceTest;
using ga::UpdateSizes;
using Verdict = ConvergenceTest::Verdict;

constexpr double kTol = 1e-10, kBetaPrime = 3.3e6, kGammaPrime = 2.0e3, kQ = 1e4, kQdd = 10.0, kLambda = 1e5;
constexpr double kUlp = std::numeric_limits<double>::epsilon();

// An update of positions by dq (the accelerations move by beta' dq) and multipliers by dl.
UpdateSizes update(double dq, double dl)
{
    UpdateSizes u;
    u.dq = u.dw = dq;
    u.dlambda = dl;
    u.q = kQ;
    u.qdd = kQdd;
    u.lambda = kLambda;
    return u;
}

// first update from the predictor: positions off by 5e-3 tol |q|, multipliers by 3e9 tol
const UpdateSizes kFirst = update(5e-3 * kTol * kQ, 3e9 * kTol * kLambda);
// then at round-off: positions by 1 ulp of |q|, multipliers by 4e5 tol |lambda|
const UpdateSizes kAtRoundoff = update(kUlp * kQ, 4e5 * kTol * kLambda);

void fresh_matrix_ends_at_the_first_roundoff_update(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();  // factorized in this step, at the predictor
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    // the rate (4e5 / 3e9) predicts an error of 53 tol: not converged by the rate test, but
    // at round-off with the matrix of this step
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Converged);
}

void old_matrix_at_roundoff_asks_for_a_fresh_one(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);  // a matrix of an earlier step: its Phi_q is not that of this q
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    // iterating at round-off with it would feed the round-off of q through the old Phi_q into
    // v and qdd: rebuild it instead ...
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Slow);
    // ... and one update with the matrix of the current q ends the step
    c.matrix_changed();
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Converged);
}

void fresh_matrix_far_from_the_iterate_needs_a_second(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    // the first update moved q by 3 tol |q| after the factorization
    assert_true(c.check(kTol, update(3.0 * kTol * kQ, 3e9 * kTol * kLambda), kBetaPrime, kGammaPrime) ==
                Verdict::Continue);
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Continue);
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Converged);
}

void tolerance_below_roundoff_moves_within_roundoff(void **state)
{
    (void)state;
    // tol = 1e-16, below 64 ulps: "q has moved within the tolerance since the factorization"
    // means within round-off then (full Newton: a matrix at every iterate, whose own update
    // is the only move)
    constexpr double tol = 1e-16;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, update(10.0 * kUlp * kQ, 3e9 * kTol * kLambda), kBetaPrime, kGammaPrime) ==
                Verdict::Converged);
    // a move beyond round-off since the factorization: a second update at round-off needed
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, update(1e3 * kUlp * kQ, 3e9 * kTol * kLambda), kBetaPrime, kGammaPrime) ==
                Verdict::Continue);
    assert_true(c.check(tol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Continue);
    assert_true(c.check(tol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Converged);
}

void index2_waits_for_its_newmark_increment(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    UpdateSizes u = kAtRoundoff;
    u.dw_is_dq = false;
    u.v = 1.0;
    u.dw = 1e3 * kUlp * kQ;  // the accelerations' increment still above round-off
    assert_true(c.check(kTol, u, kBetaPrime, kGammaPrime) != Verdict::Converged);
}

void a_new_step_forgets_the_fresh_matrix(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    c.reset(-1.0);  // next step, same matrix
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    assert_true(c.check(kTol, kAtRoundoff, kBetaPrime, kGammaPrime) == Verdict::Slow);
}

// The stabilized index-2 form with an old matrix (pendulum at h = 1e-5): the multipliers
// contract by 1e-5 per update while the accelerations do not move less. A rate taken over the
// largest ratio (the multipliers' first, then the accelerations') claimed convergence; each
// quantity's own rate does not.
void each_quantity_converges_at_its_own_rate(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    UpdateSizes u = update(0.0, 0.0);
    u.dw_is_dq = false;
    u.q = 0.84, u.v = 2.0, u.qdd = 6.9, u.lambda = 5.5;
    const double beta_prime = 4e10, gamma_prime = 2e5;
    // positions above their floor, so that only the rates decide
    u.dq = 1e-13, u.dw = 2.8e-18, u.dlambda = 1.1e-4;  // e: 1.2e-3, 163, 2e5
    assert_true(c.check(kTol, u, beta_prime, gamma_prime) == Verdict::Continue);
    // largest ratio 211 after 2e5: "rate" 1e-3, predicted error 0.2; but the accelerations'
    // own rate is 1.3
    u.dq = 5e-14, u.dw = 3.64e-18, u.dlambda = 6.6e-10;  // e: 6e-4, 211, 1.2
    assert_true(c.check(kTol, u, beta_prime, gamma_prime) == Verdict::Slow);
}

// A chain of 30 000 links, adaptive at rtol 1e-3 (Newton tolerance 1.58e-6, h = 2e-4): full
// Newton diverged for 19 iterations, a matrix at every other one, with the iterate running
// away to |q| ~ 2e6 (an angle turned by a million radians). The 20th update then fell by
// 3e-5 after a fresh factorization; that one ratio predicted convergence and the runaway
// iterate was accepted. After a divergence with a matrix of this step, rates are not trusted.
UpdateSizes runaway(double dq, double q, double qdd, double dl, double l)
{
    UpdateSizes u = update(dq, dl);
    u.q = q;
    u.qdd = qdd;
    u.lambda = l;
    return u;
}

void a_diverged_iteration_does_not_converge_by_one_rate(void **state)
{
    (void)state;
    constexpr double tol = 1.58e-6, beta_prime = 9.0e7, gamma_prime = 1.0e4;
    const UpdateSizes grown = runaway(3.98e5, 1.88e6, 1.87e14, 3.39e17, 3.36e17),
                      grew_again = runaway(2.99e6, 2.81e6, 2.77e14, 5.08e18, 4.75e18),
                      after_refresh = runaway(2.81e6, 1.88e6, 1.87e14, 4.79e18, 4.45e16),
                      one_drop = runaway(165.0, 1.88e6, 1.87e14, 1.47e14, 4.47e16);
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, grown, beta_prime, gamma_prime) == Verdict::Continue);
    assert_true(c.check(tol, grew_again, beta_prime, gamma_prime) == Verdict::Slow);  // x5
    c.matrix_changed();
    assert_true(c.check(tol, after_refresh, beta_prime, gamma_prime) == Verdict::Continue);
    // e = 55 (positions), 2 081 (multipliers): above the tolerance, whatever the ratio says
    assert_true(c.check(tol, one_drop, beta_prime, gamma_prime) != Verdict::Converged);

    // The same drop in a step that never diverged is a rate (3e-5) to be trusted.
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, after_refresh, beta_prime, gamma_prime) == Verdict::Continue);
    assert_true(c.check(tol, one_drop, beta_prime, gamma_prime) == Verdict::Converged);
}

// The stabilized index-2 chain of 100 000 links (h = 1e-3, tolerance 1e-10, the step from
// t = 0.003): after two updates the increments repeat, with the same matrix and with a fresh
// one at every iterate, the multipliers at 6e-8 of their size and the Newmark increment at
// 3e-15 -- what the solve of this ill-conditioned system resolves, far above the floors that
// v's round-off gives. The step failed after 20 iterations; it is converged by the stagnation.
UpdateSizes chain_update(double dq, double dw, double dl)
{
    UpdateSizes u = update(dq, dl);
    u.dw = dw;
    u.dw_is_dq = false;
    u.q = 1.0e5;
    u.v = 4.968e-2;
    u.qdd = 12.35;
    u.lambda = 397.3;
    return u;
}

void index2_stops_where_its_solve_stagnates(void **state)
{
    (void)state;
    constexpr double tol = 1e-10, beta_prime = 3.971e6, gamma_prime = 1.995e3;
    const UpdateSizes fresh = chain_update(2.010e-12, 3.865e-15, 2.472e-5),
                      again = chain_update(2.010e-12, 3.312e-15, 2.475e-5);
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, fresh, beta_prime, gamma_prime) == Verdict::Continue);
    assert_true(c.check(tol, again, beta_prime, gamma_prime) == Verdict::Converged);

    // The same ratios with a Newmark increment that moves q by more than its round-off
    // (the q floor is 1.4e-9 here): not noise, the iteration must go on.
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(tol, chain_update(2.010e-12, 3.865e-8, 2.472e-5), beta_prime,
                        gamma_prime) == Verdict::Continue);
    assert_true(c.check(tol, chain_update(2.010e-12, 3.312e-8, 2.475e-5), beta_prime,
                        gamma_prime) != Verdict::Converged);

    // ... or with the matrix of an earlier step, whose slow rate may be its age: a fresh one.
    c.reset(-1.0);
    assert_true(c.check(tol, fresh, beta_prime, gamma_prime) != Verdict::Converged);
    assert_true(c.check(tol, again, beta_prime, gamma_prime) == Verdict::Slow);
}

// A quantity that became exactly zero after a nonzero increment has an infinite ratio to its
// tolerance; the rate the step hands on (to the next step, and into checkpoints, which refuse
// what is not finite: found by libFuzzer) stays finite, and still says "too slow".
void a_rate_stays_finite(void **state)
{
    (void)state;
    ConvergenceTest c;
    c.reset(-1.0);
    c.matrix_changed();
    assert_true(c.check(kTol, kFirst, kBetaPrime, kGammaPrime) == Verdict::Continue);
    UpdateSizes zero = update(1e-3 * kTol * kQ, 1e3 * kTol * kLambda);
    zero.lambda = 0.0;
    assert_true(c.check(kTol, zero, kBetaPrime, kGammaPrime) != Verdict::Converged);
    assert_true(std::isfinite(c.rate()) && c.rate() >= 1.0);
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(fresh_matrix_ends_at_the_first_roundoff_update),
        cmocka_unit_test(old_matrix_at_roundoff_asks_for_a_fresh_one),
        cmocka_unit_test(each_quantity_converges_at_its_own_rate),
        cmocka_unit_test(fresh_matrix_far_from_the_iterate_needs_a_second),
        cmocka_unit_test(tolerance_below_roundoff_moves_within_roundoff),
        cmocka_unit_test(index2_waits_for_its_newmark_increment),
        cmocka_unit_test(a_new_step_forgets_the_fresh_matrix),
        cmocka_unit_test(a_diverged_iteration_does_not_converge_by_one_rate),
        cmocka_unit_test(index2_stops_where_its_solve_stagnates),
        cmocka_unit_test(a_rate_stays_finite),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
