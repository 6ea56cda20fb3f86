/* The paper's slider-crank (sec. 5.1): 10 coordinates, 8 constraints, singular M. Order 2 in
 * the crank angle and a multiplier against an independent reference (RK4 on the index-1 form
 * with a step 1/60 of galpha's finest), constraint residuals at the Newton tolerance's scale,
 * and the energy balance. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>

#include "helpers.h"
#include "scene_run.h"
#include "scenes/index1_rk4.h"
#include "scenes/slider_crank.h"

static slider_crank P;
static double Q0[SC_N], V0[SC_N];

/* T + V - T_motor (theta1 - theta1(0)): conserved by the exact motion */
static double energy(const double *q, const double *v)
{
    double M[SC_N * SC_N], T = 0.0;
    sc_mass(0.0, q, M, &P);
    for (int i = 0; i < SC_N; ++i)
        T += 0.5 * M[i + SC_N * i] * v[i] * v[i];
    const double s = q[SC_X4] - q[SC_X3] - P.rest_length;
    return T + 0.5 * P.k * s * s - P.torque * (q[SC_TH1] - Q0[SC_TH1]);
}

static scene make_scene(void)
{
    P = slider_crank_paper();
    sc_initial(&P, M_PI / 2, Q0, V0);
    scene sc = {SC_N, SC_M, sc_mass, sc_force, sc_constraint, sc_jacobian, sc_stiffness,
                sc_constraint_accel, &P, Q0, V0, energy};
    return sc;
}

/* The RK4 reference is only an oracle if its own error is orders below the smallest galpha
 * error asserted against it below: halving its step must not move it. */
static void reference_integrator_is_resolved(void **state)
{
    (void)state;
    (void)make_scene();
    rk4_model md = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &P};
    double q1[SC_N], v1[SC_N], l1[SC_M], q2[SC_N], v2[SC_N], l2[SC_M];
    memcpy(q1, Q0, sizeof q1);
    memcpy(v1, V0, sizeof v1);
    memcpy(q2, Q0, sizeof q2);
    memcpy(v2, V0, sizeof v2);
    assert_int_equal(index1_rk4(&md, 0.0, 1.0, 100000, q1, v1, NULL, l1), 0);
    assert_int_equal(index1_rk4(&md, 0.0, 1.0, 200000, q2, v2, NULL, l2), 0);
    const double dth = fabs(q1[SC_TH1] - q2[SC_TH1]) / fabs(q2[SC_TH1]);
    const double dl = fabs(l1[0] - l2[0]) / fabs(l2[0]);
    printf("  RK4 100000 vs 200000 steps: theta1 %.2e, lambda1 %.2e\n", dth, dl);
    assert_true(dth < 1e-10);
    assert_true(dl < 1e-9);
}

static void order_two_in_crank_angle_and_multiplier(void **state)
{
    (void)state;
    enum { K = 5 };
    const scene sc = make_scene();
    const double tol = 1e-10;
    /* independent reference at t = 1 */
    double q[SC_N], v[SC_N], lam[SC_M], qdd[SC_N];
    memcpy(q, Q0, sizeof q);
    memcpy(v, V0, sizeof v);
    rk4_model md = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &P};
    assert_int_equal(index1_rk4(&md, 0.0, 1.0, 200000, q, v, qdd, lam), 0);
    double hs[K], eth[K], el[K], ex4[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 5e-3 / (double)(1 << k);
        const scene_result r = run_scene(&sc, hs[k], 1.0, 0.7, tol, GA_TANGENT_AUTO);
        assert_int_equal(r.status, GA_OK);
        eth[k] = fabs(r.q[SC_TH1] - q[SC_TH1]) / fabs(q[SC_TH1]);
        ex4[k] = fabs(r.q[SC_X4] - q[SC_X4]) / fabs(q[SC_X4]);
        el[k] = fabs(r.lambda[0] - lam[0]) / fabs(lam[0]);
        printf("  h = %-9.6g rel. error theta1 %.3e  x4 %.3e  lambda1 %.3e  max|Phi| %.1e  "
               "max|E - E0| %.2e  Newton it/step %.2f\n",
               hs[k], eth[k], ex4[k], el[k], r.max_phi, r.energy_drift,
               (double)r.iters / (double)r.steps);
        /* constraints hold at the scale of the Newton tolerance at every accepted step */
        assert_true(r.max_phi <= tol * r.max_q);
    }
    const double o_th = fit_order(hs, eth, K), o_l = fit_order(hs, el, K);
    printf("  slider-crank: order theta1 %.3f, x4 %.3f, lambda1 %.3f (theta1(1) = %.6f, "
           "lambda1(1) = %.6f)\n",
           o_th, fit_order(hs, ex4, K), o_l, q[SC_TH1], lam[0]);
    assert_true(o_th >= 1.8 && o_th <= 2.2);
    assert_true(o_l >= 1.8 && o_l <= 2.2);
    assert_true(eth[K - 1] < 1e-4);
}

/* The energy balance drifts only at the level of the integration error: its maximum over
 * [0, 1] falls with order 2 in h. */
static void energy_balance_at_integration_error_level(void **state)
{
    (void)state;
    enum { K = 4 };
    const scene sc = make_scene();
    double hs[K], de[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 5e-3 / (double)(1 << k);
        de[k] = run_scene(&sc, hs[k], 1.0, 0.7, 1e-10, GA_TANGENT_AUTO).energy_drift;
    }
    const double o = fit_order(hs, de, K);
    printf("  energy drift: %.2e at h = 5e-3 ... %.2e at h = %.3g, order %.2f\n", de[0],
           de[K - 1], hs[K - 1], o);
    assert_true(o >= 1.8);
}

/* Analytic and finite-difference tangents give the same steps. */
static void exact_and_fd_tangents_agree(void **state)
{
    (void)state;
    const scene sc = make_scene();
    const scene_result a = run_scene(&sc, 5e-3, 1.0, 0.7, 1e-10, GA_TANGENT_AUTO);
    const scene_result b = run_scene(&sc, 5e-3, 1.0, 0.7, 1e-10, GA_TANGENT_FD);
    assert_int_equal(a.status, GA_OK);
    assert_int_equal(b.status, GA_OK);
    assert_true(max_abs_diff(a.q, b.q, SC_N) < 1e-9);
    assert_true(max_abs_diff(a.lambda, b.lambda, SC_M) < 1e-6 * fabs(a.lambda[0]));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(reference_integrator_is_resolved),
        cmocka_unit_test(order_two_in_crank_angle_and_multiplier),
        cmocka_unit_test(energy_balance_at_integration_error_level),
        cmocka_unit_test(exact_and_fd_tangents_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
