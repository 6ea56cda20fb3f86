/* Unconstrained linear oscillators (m = 0) against their exact solutions:
 * q'' = -w^2 q (undamped) and q'' = -2 z w q' - w^2 q (damped, exercises C_t). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>

#include <galpha.h>

#include "helpers.h"

typedef struct oscillator {
    double mass, omega, zeta;
} oscillator;

static int osc_mass(double t, const double *q, double *M, void *user)
{
    (void)t;
    (void)q;
    M[0] = ((const oscillator *)user)->mass;
    return 0;
}

static int osc_force(double t, const double *q, const double *v, double *f, void *user)
{
    const oscillator *o = user;
    (void)t;
    f[0] = -o->mass * (o->omega * o->omega * q[0] + 2.0 * o->zeta * o->omega * v[0]);
    return 0;
}

/* Exact solution from q(0) = 1, v(0) = 0 (underdamped). */
static void exact(const oscillator *o, double t, double *q, double *v, double *a)
{
    const double w = o->omega, z = o->zeta, wd = w * sqrt(1.0 - z * z);
    const double e = exp(-z * w * t), c = cos(wd * t), s = sin(wd * t);
    const double B = z * w / wd;
    *q = e * (c + B * s);
    *v = e * (-z * w * (c + B * s) + (-wd * s + B * wd * c));
    *a = -2.0 * z * w * (*v) - w * w * (*q);
}

static void run(const oscillator *o, double h, double t_end, double *err)
{
    ga_solver *s = NULL;
    double q = 1.0, v = 0.0, qdd, qe, ve, ae;
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, osc_mass, osc_force, NULL, NULL, (void *)o), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-13, 10), GA_OK);
    assert_int_equal(ga_init(s, 0.0, &q, &v), GA_OK);
    const long n = lround(t_end / h);
    for (long i = 0; i < n; ++i)
        assert_int_equal(ga_step(s, h), GA_OK);
    assert_int_equal(ga_get_q(s, &q), GA_OK);
    assert_int_equal(ga_get_v(s, &v), GA_OK);
    assert_int_equal(ga_get_qdd(s, &qdd), GA_OK);
    assert_int_equal(ga_get_lambda(s, NULL), GA_OK); /* m = 0: nothing to copy */
    exact(o, t_end, &qe, &ve, &ae);
    err[0] = fabs(q - qe);
    err[1] = fabs(v - ve);
    err[2] = fabs(qdd - ae);
    ga_free(s);
}

static void check(const oscillator *o, const char *label)
{
    enum { K = 5 };
    double hs[K], e[3][K];
    for (int k = 0; k < K; ++k) {
        double err[3];
        hs[k] = 0.02 / (double)(1 << k);
        /* t = 2.3 is not a turning point: there the error in q would be second order in the
         * phase error */
        run(o, hs[k], 2.3, err);
        for (int j = 0; j < 3; ++j)
            e[j][k] = err[j];
        printf("  %s h = %-8.5g |e_q| = %.3e |e_v| = %.3e |e_qdd| = %.3e\n", label, hs[k],
               err[0], err[1], err[2]);
    }
    for (int j = 0; j < 3; ++j) {
        const double p = fit_order(hs, e[j], K);
        printf("  %s order of %s: %.3f\n", label, j == 0 ? "q" : j == 1 ? "v" : "qdd", p);
        assert_true(p > 1.9 && p < 2.1);
    }
    /* Accuracy, not only order: at h = T/400 the error is a small fraction of the amplitude. */
    assert_true(e[0][K - 1] < 2e-3);
}

static void undamped_oscillator_matches_cosine(void **state)
{
    (void)state;
    const oscillator o = {2.0, 2.0 * M_PI, 0.0};
    check(&o, "undamped");
}

static void damped_oscillator_matches_exact_solution(void **state)
{
    (void)state;
    const oscillator o = {0.5, 2.0 * M_PI, 0.1};
    check(&o, "damped  ");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(undamped_oscillator_matches_cosine),
        cmocka_unit_test(damped_oscillator_matches_exact_solution),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
