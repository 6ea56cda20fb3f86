/* The slider-crank driven by a DC motor under a PI speed controller (examples/scenes/
 * slider_crank_motor.h; current and integral as first-order states): order 2 in q, v, qdd,
 * lambda, y, y' against RK4 on the index-1 form with the states (index1_rk4_y, no galpha code),
 * in both formulations; Newton with the exact coupling blocks converges quadratically (a
 * tighter Newton tolerance costs almost no iteration more), and without them it does not. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "helpers.h"
#include "scenes/index1_rk4.h"
#include "scenes/slider_crank_motor.h"

static sc_motor g_motor;

static ga_solver *motor_solver(int formulation)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(SC_N, SC_M, &s), GA_OK);
    assert_int_equal(scm_declare(s, &g_motor), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    return s;
}

static void start(ga_solver *s)
{
    double q[SC_N], v[SC_N];
    const double y[SCM_R] = {0.0, 0.0};
    sc_initial(&g_motor.crank, M_PI / 2, q, v);
    assert_int_equal(ga_init_y(s, 0.0, q, v, y), GA_OK);
}

enum { kQ, kV, kA, kL, kY, kYD, kQuantities };
static const char *const kNames[kQuantities] = {"q", "v", "qdd", "lambda", "y", "y'"};
static const double kT = 0.2; /* through the speed ramp, with the current's fastest change */

static double max_diff(const double *a, const double *b, int n)
{
    double e = 0.0;
    for (int i = 0; i < n; ++i)
        e = fmax(e, fabs(a[i] - b[i]));
    return e;
}

static void order_two_against_runge_kutta(void **state)
{
    (void)state;
    g_motor = sc_motor_default();
    /* the reference: RK4 with h = 2.5e-6 (its error ~ (h / 4 ms)^4 far below galpha's) */
    double rq[SC_N], rv[SC_N], ra[SC_N], rl[SC_M], ry[SCM_R] = {0.0, 0.0}, ryd[SCM_R];
    sc_initial(&g_motor.crank, M_PI / 2, rq, rv);
    const rk4_model model = {SC_N, SC_M, sc_mass, NULL, sc_jacobian, sc_constraint_accel, &g_motor};
    const rk4_first_order states = {SCM_R, scm_force, scm_rate};
    assert_int_equal(index1_rk4_y(&model, &states, 0.0, kT, 80000, rq, rv, ry, ra, rl, ryd), 0);

    const int steps[] = {400, 800, 1600, 3200};
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double h[4], e[kQuantities][4];
        for (int k = 0; k < 4; ++k) {
            ga_solver *s = motor_solver(formulation);
            start(s);
            for (int i = 0; i < steps[k]; ++i) {
                const ga_status st = ga_step(s, kT / steps[k]);
                if (st != GA_OK)
                    print_error("step %d of %d: %s\n", i, steps[k], ga_last_error(s));
                assert_int_equal(st, GA_OK);
            }
            double q[SC_N], v[SC_N], a[SC_N], l[SC_M], y[SCM_R], yd[SCM_R];
            assert_int_equal(ga_get_q(s, q), GA_OK);
            assert_int_equal(ga_get_v(s, v), GA_OK);
            assert_int_equal(ga_get_qdd(s, a), GA_OK);
            assert_int_equal(ga_get_lambda(s, l), GA_OK);
            assert_int_equal(ga_get_y(s, y, yd), GA_OK);
            h[k] = kT / steps[k];
            e[kQ][k] = max_diff(q, rq, SC_N);
            e[kV][k] = max_diff(v, rv, SC_N);
            e[kA][k] = max_diff(a, ra, SC_N);
            e[kL][k] = max_diff(l, rl, SC_M);
            e[kY][k] = max_diff(y, ry, SCM_R);
            e[kYD][k] = max_diff(yd, ryd, SCM_R);
            ga_free(s);
        }
        for (int j = 0; j < kQuantities; ++j) {
            const double p = fit_order(h, e[j], 4);
            print_message("%s %-7s errors %.2e ... %.2e  order %.3f\n",
                          formulation == GA_INDEX3 ? "index 3" : "index 2", kNames[j], e[j][0],
                          e[j][3], p);
            assert_true(p > 1.9 && p < 2.1);
        }
    }
}

/* Newton iterations per step with full Newton (a matrix at every iterate, exact K_t) at three
 * Newton tolerances: quadratic convergence squares the increment at every iteration, so going
 * from 1e-4 to 1e-10 costs at most one more iteration per step; with the coupling blocks left
 * out (only g_y in the matrix) the iteration contracts linearly and needs several. */
static double iterations_per_step(int exact, double tol)
{
    ga_solver *s = motor_solver(GA_INDEX3);
    assert_int_equal(ga_set_tangents(s, sc_stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_coupling(s, scm_coupling), GA_OK);
    assert_int_equal(ga_set_coupling_exact(s, exact), GA_OK);
    assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
    assert_int_equal(ga_set_newton(s, tol, 60), GA_OK);
    start(s);
    const int N = 500;
    for (int i = 0; i < N; ++i) {
        const ga_status st = ga_step(s, 1e-3);
        if (st != GA_OK)
            print_error("exact %d, tol %g, step %d: %s\n", exact, tol, i, ga_last_error(s));
        assert_int_equal(st, GA_OK);
    }
    long long iters = 0;
    assert_int_equal(ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters), GA_OK);
    ga_free(s);
    return (double)iters / N;
}

static void newton_quadratic_with_the_coupling_blocks(void **state)
{
    (void)state;
    g_motor = sc_motor_default();
    const double tols[3] = {1e-4, 1e-7, 1e-10};
    double exact[3], loose[3];
    for (int k = 0; k < 3; ++k) {
        exact[k] = iterations_per_step(1, tols[k]);
        loose[k] = iterations_per_step(0, tols[k]);
        print_message("Newton tolerance %.0e: %.2f iterations per step with the coupling "
                      "blocks, %.2f without\n",
                      tols[k], exact[k], loose[k]);
    }
    assert_true(exact[2] - exact[0] <= 1.0);
    assert_true(loose[2] - loose[0] >= 2.0);
    assert_true(loose[2] >= 2.0 * exact[2]);
}

/* Declared coupling patterns (g_q zero, g_v nonzero in the column of the crank speed only):
 * the finite differences of the blocks cost one rate call for g_q and g_v instead of 2 n, and
 * the run is the one with dense differences (the columns left out are exactly zero in those). */
static void coupling_patterns_cut_the_rate_calls(void **state)
{
    (void)state;
    g_motor = sc_motor_default();
    double y[2][SCM_R], q[2][SC_N];
    long long rates[2], blocks[2];
    for (int declared = 0; declared < 2; ++declared) {
        ga_solver *s = motor_solver(GA_INDEX3);
        if (declared) {
            const int rows[2] = {SCM_I, SCM_Z}, cols[2] = {SC_TH1, SC_TH1};
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_Q, 0, NULL, NULL), GA_OK);
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_V, 2, rows, cols), GA_OK);
            assert_int_equal(ga_set_coupling_pattern(s, 2, 0, NULL, NULL), GA_ERR_ARG);
            const int bad = SC_N;
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_V, 1, rows, &bad),
                             GA_ERR_ARG);
        }
        start(s);
        if (declared)
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_Q, 0, NULL, NULL),
                             GA_ERR_STATE);
        for (int i = 0; i < 200; ++i)
            assert_int_equal(ga_step(s, 1e-3), GA_OK);
        assert_int_equal(ga_get_y(s, y[declared], NULL), GA_OK);
        assert_int_equal(ga_get_q(s, q[declared]), GA_OK);
        assert_int_equal(ga_get_counter(s, GA_COUNT_RATE_EVALS, &rates[declared]), GA_OK);
        assert_int_equal(ga_get_counter(s, GA_COUNT_COUPLING_EVALS, &blocks[declared]), GA_OK);
        ga_free(s);
    }
    print_message("rate calls: %lld with dense differences, %lld with patterns (%lld and %lld "
                  "coupling evaluations); y differs by %.1e\n",
                  rates[0], rates[1], blocks[0], blocks[1],
                  fmax(fabs(y[0][0] - y[1][0]), fabs(y[0][1] - y[1][1])));
    /* the same run: the same coupling evaluations, each 2 n - 1 rate calls cheaper (g_q none,
     * g_v one group instead of 2 n columns; g_y by r calls either way) */
    assert_true(blocks[0] == blocks[1] && blocks[0] > 0);
    assert_true(rates[0] - rates[1] == blocks[0] * (2 * SC_N - 1));
    assert_memory_equal(y[0], y[1], sizeof y[0]);
    assert_memory_equal(q[0], q[1], sizeof q[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(order_two_against_runge_kutta),
        cmocka_unit_test(newton_quadratic_with_the_coupling_blocks),
        cmocka_unit_test(coupling_patterns_cut_the_rate_calls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
