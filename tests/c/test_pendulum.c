/* Second-order convergence of q, v, qdd and lambda on the planar pendulum in Cartesian
 * coordinates (n = 2, m = 1), against an independent RK4 solution of the angle equation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <galpha.h>

#include "helpers.h"

static const pendulum P = {1.0, 1.0, 9.81};
static const double THETA0 = 1.0, OMEGA0 = 0.5, T_END = 1.0;

typedef struct run_result {
    double q[2], v[2], qdd[2], lambda;
    long long iters, steps;
} run_result;

typedef struct run_options {
    double rho_inf;
    ga_tangent_mode tangent_mode;
    ga_predictor predictor;
    int exact_tangent;
} run_options;

static run_result run(double h, run_options o)
{
    pendulum p = P;
    run_result r;
    double q[2], v[2];
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    pendulum_state(&p, THETA0, OMEGA0, q, v);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &p),
                     GA_OK);
    if (o.exact_tangent)
        assert_int_equal(ga_set_tangents(s, pendulum_stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, o.tangent_mode), GA_OK);
    assert_int_equal(ga_set_predictor(s, o.predictor), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, o.rho_inf), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 20), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    const long n = lround(T_END / h);
    for (long i = 0; i < n; ++i)
        assert_int_equal(ga_step(s, h), GA_OK);
    double t;
    ga_get_t(s, &t);
    assert_true(fabs(t - T_END) < 1e-12);
    ga_get_q(s, r.q);
    ga_get_v(s, r.v);
    ga_get_qdd(s, r.qdd);
    ga_get_lambda(s, &r.lambda);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &r.iters);
    ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
    ga_free(s);
    return r;
}

static void check_orders(run_options o, const char *label)
{
    enum { K = 5 };
    const pendulum_exact ex = pendulum_reference(&P, THETA0, OMEGA0, T_END, 200000);
    double hs[K], eq[K], ev[K], ea[K], el[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 0.01 / (double)(1 << k);
        const run_result r = run(hs[k], o);
        eq[k] = max_abs_diff(r.q, ex.q, 2);
        ev[k] = max_abs_diff(r.v, ex.v, 2);
        ea[k] = max_abs_diff(r.qdd, ex.qdd, 2);
        el[k] = fabs(r.lambda - ex.lambda);
        printf("  %-26s h = %-9.6g |e_q| = %.3e |e_v| = %.3e |e_qdd| = %.3e |e_lambda| = %.3e "
               "(%.2f Newton it/step)\n",
               label, hs[k], eq[k], ev[k], ea[k], el[k], (double)r.iters / (double)r.steps);
    }
    const double oq = fit_order(hs, eq, K), ov = fit_order(hs, ev, K);
    const double oa = fit_order(hs, ea, K), ol = fit_order(hs, el, K);
    printf("  %-26s measured orders: q %.3f  v %.3f  qdd %.3f  lambda %.3f\n", label, oq, ov, oa,
           ol);
    assert_true(oq >= 1.9 && oq <= 2.1);
    assert_true(ov >= 1.9 && ov <= 2.1);
    assert_true(oa >= 1.9 && oa <= 2.1);
    assert_true(ol >= 1.9 && ol <= 2.1);
}

static void order_two_in_q_v_qdd_lambda(void **state)
{
    (void)state;
    check_orders((run_options){0.9, GA_TANGENT_AUTO, GA_PREDICTOR_CONSTANT_A, 0},
                 "rho=0.9 FD tangent");
}

static void order_two_with_paper_parameters_and_predictor(void **state)
{
    (void)state;
    check_orders((run_options){0.7, GA_TANGENT_AUTO, GA_PREDICTOR_ZERO, 1},
                 "rho=0.7 exact K, zero pred");
}

/* Exact, finite-difference and neglected tangents, and both predictors, iterate to the same
 * step solution: they differ only in the path of the Newton iteration. */
static void tangent_modes_and_predictors_agree(void **state)
{
    (void)state;
    const double h = 2.5e-3;
    const run_result fd = run(h, (run_options){0.9, GA_TANGENT_FD, GA_PREDICTOR_CONSTANT_A, 1});
    const run_result ex = run(h, (run_options){0.9, GA_TANGENT_AUTO, GA_PREDICTOR_CONSTANT_A, 1});
    const run_result no =
        run(h, (run_options){0.9, GA_TANGENT_NEGLECT, GA_PREDICTOR_CONSTANT_A, 0});
    const run_result zp = run(h, (run_options){0.9, GA_TANGENT_AUTO, GA_PREDICTOR_ZERO, 1});
    const run_result *others[] = {&ex, &no, &zp};
    for (int i = 0; i < 3; ++i) {
        assert_true(max_abs_diff(fd.q, others[i]->q, 2) < 1e-10);
        assert_true(max_abs_diff(fd.v, others[i]->v, 2) < 1e-8);
        assert_true(max_abs_diff(fd.qdd, others[i]->qdd, 2) < 1e-6);
        assert_true(fabs(fd.lambda - others[i]->lambda) < 1e-6);
    }
    printf("  Newton iterations per step: exact K %.2f, FD K %.2f, neglected K %.2f, "
           "zero predictor %.2f\n",
           (double)ex.iters / ex.steps, (double)fd.iters / fd.steps,
           (double)no.iters / no.steps, (double)zp.iters / zp.steps);
    /* simplified Newton converges linearly: it must not need fewer iterations */
    assert_true(no.iters >= ex.iters);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(order_two_in_q_v_qdd_lambda),
        cmocka_unit_test(order_two_with_paper_parameters_and_predictor),
        cmocka_unit_test(tangent_modes_and_predictors_agree),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
