/* ga_check_derivatives: each derivative callback against central differences of what it
 * derives. Correct callbacks of the shipped scenes pass far below the tolerance; one wrong
 * entry (a sign, a factor) of each kind is named with both values; a constraint with a zero
 * gradient is named; the solver is not touched. The wrong callbacks are the correct ones with
 * one entry changed by hand: what they should be is known without the code under test. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"
#include "scene_catalog.h"
#include "scenes/slider_crank_motor.h"

static pendulum P = {1.3, 0.8, 9.81};
static int g_wrong; /* which callback lies: 0 none */

static int stiffness(double t, const double *q, const double *v, const double *qdd,
                     const double *lambda, double *K, void *u)
{
    const int rc = pendulum_stiffness(t, q, v, qdd, lambda, K, u);
    if (g_wrong == 1)
        K[3] = -K[3]; /* a sign */
    return rc;
}
static int jacobian(double t, const double *q, double *J, void *u)
{
    const int rc = pendulum_jacobian(t, q, J, u);
    if (g_wrong == 2)
        J[1] *= 2.0; /* Phi_q(0, 1): the factor 1/2 of Phi forgotten */
    return rc;
}
/* of the rheonomic constraint below: |v|^2 - d^2/dt^2 (L^2 / 2) */
static int accel(double t, const double *q, const double *v, double *out, void *u)
{
    (void)q;
    const pendulum *p = u;
    const double L = p->length * (1.0 + 0.1 * sin(t)), dL = p->length * 0.1 * cos(t),
                 ddL = -p->length * 0.1 * sin(t);
    out[0] = v[0] * v[0] + v[1] * v[1] - (dL * dL + L * ddL);
    if (g_wrong == 3)
        out[0] *= 0.5;
    return 0;
}
/* viscous damping f = -c v, C_t = c I */
static int damped_force(double t, const double *q, const double *v, double *f, void *u)
{
    const int rc = pendulum_force(t, q, v, f, u);
    f[0] -= 0.7 * v[0];
    f[1] -= 0.7 * v[1];
    return rc;
}
static int damping(double t, const double *q, const double *v, double *C, void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    C[0] = C[3] = g_wrong == 4 ? -0.7 : 0.7;
    C[1] = C[2] = 0.0;
    return 0;
}
/* a rheonomic constraint: the pendulum's length L(t) = L (1 + 0.1 sin t) */
static int moving_constraint(double t, const double *q, double *phi, void *u)
{
    const pendulum *p = u;
    const double L = p->length * (1.0 + 0.1 * sin(t));
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - L * L);
    return 0;
}
static int moving_dt(double t, const double *q, double *phi_t, void *u)
{
    (void)q;
    const pendulum *p = u;
    const double L = p->length * (1.0 + 0.1 * sin(t)), dL = p->length * 0.1 * cos(t);
    phi_t[0] = g_wrong == 5 ? L * dL : -L * dL;
    return 0;
}
/* df/dp for p = gravity */
static int force_p(double t, const double *q, const double *v, int j, double *f_p, void *u)
{
    (void)t, (void)q, (void)v, (void)j;
    const pendulum *p = u;
    f_p[0] = 0.0;
    f_p[1] = g_wrong == 6 ? p->mass : -p->mass;
    return 0;
}

static ga_solver *pendulum_checked(void)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, damped_force, moving_constraint,
                                      jacobian, &P),
                     GA_OK);
    return s;
}

static void state(double *q, double *v, double *qdd, double *lambda)
{
    const double L = P.length * (1.0 + 0.1 * sin(0.3));
    q[0] = L * sin(0.7), q[1] = -L * cos(0.7);
    v[0] = 1.1 * cos(0.7), v[1] = 1.1 * sin(0.7);
    qdd[0] = -0.4, qdd[1] = 0.9;
    *lambda = 2.5;
}

/* The pendulum's own callbacks (its rheonomic variant: Phi_q with Phi; the stiffness of the
 * fixed length is that of the moving one, Phi_qq being the identity either way) */
static void correct_callbacks_pass(void **s_)
{
    (void)s_;
    g_wrong = 0;
    ga_solver *s = pendulum_checked();
    assert_int_equal(ga_set_tangents(s, stiffness, damping), GA_OK);
    assert_int_equal(ga_set_constraint_dt(s, moving_dt), GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, accel), GA_OK);
    double q[2], v[2], qdd[2], lambda, worst = -1.0;
    state(q, v, qdd, &lambda);
    assert_int_equal(ga_check_derivatives(s, 0.3, q, v, qdd, &lambda, NULL, 1e-6, &worst),
                     GA_OK);
    printf("  pendulum (rheonomic, damped): worst relative difference %.1e\n", worst);
    assert_true(worst >= 0.0 && worst < 1e-8);
    ga_free(s);
    /* every shipped scene's callbacks, at its start */
    for (int sc_i = 0; sc_i < kCatalogScenes; ++sc_i) {
        catalog_scene sc = catalog_make(sc_i);
        ga_solver *c = catalog_solver(&sc);
        const ga_status st =
            ga_check_derivatives(c, 0.0, sc.q0, sc.v0, NULL, NULL, NULL, 1e-6, &worst);
        if (st != GA_OK)
            print_error("%s: %s\n", sc.name, ga_last_error(c));
        assert_int_equal(st, GA_OK);
        printf("  %-18s worst relative difference %.1e\n", sc.name, worst);
        ga_free(c);
    }
}

/* One wrong entry of each kind: named, with both values. */
static void a_wrong_entry_is_named(void **s_)
{
    (void)s_;
    static const char *const names[] = {"", "K_t(1, 1)", "Phi_q(0, 1)",
                                        "constraint acceleration term(0, 0)", "C_t(",
                                        "Phi_t(0, 0)", "df/dp(1, 0)"};
    for (g_wrong = 1; g_wrong <= 6; ++g_wrong) {
        ga_solver *s = pendulum_checked();
        assert_int_equal(ga_set_tangents(s, stiffness, damping), GA_OK);
        assert_int_equal(ga_set_constraint_accel(s, accel), GA_OK);
        assert_int_equal(ga_set_constraint_dt(s, moving_dt), GA_OK);
        assert_int_equal(ga_set_sensitivity(s, 1, &P.gravity, NULL, GA_DEPENDS_FORCE), GA_OK);
        assert_int_equal(ga_set_parameter_derivatives(s, force_p, NULL), GA_OK);
        double q[2], v[2], qdd[2], lambda, worst = 0.0;
        state(q, v, qdd, &lambda);
        const double g_before = P.gravity;
        const ga_status st =
            ga_check_derivatives(s, 0.3, q, v, qdd, &lambda, NULL, 1e-6, &worst);
        assert_true(P.gravity == g_before); /* the parameter put back */
        printf("  wrong %d: %s\n", g_wrong, ga_last_error(s));
        assert_int_equal(st, GA_ERR_DERIVATIVE);
        assert_non_null(strstr(ga_last_error(s), names[g_wrong]));
        assert_non_null(strstr(ga_last_error(s), "by the callback"));
        assert_true(worst > 0.1);
        ga_free(s);
    }
    g_wrong = 0;
}

/* At q = 0 the pendulum's Phi = (|q|^2 - L^2) / 2 has the gradient q = 0: named, by the check
 * and by the singular start (which called it "redundant"). */
static void a_zero_gradient_is_named(void **s_)
{
    (void)s_;
    g_wrong = 0;
    ga_solver *s = pendulum_checked();
    const double q[2] = {0.0, 0.0}, v[2] = {0.0, 0.0};
    assert_int_equal(ga_check_derivatives(s, 0.0, q, v, NULL, NULL, NULL, 1e-6, NULL),
                     GA_ERR_DERIVATIVE);
    assert_non_null(strstr(ga_last_error(s), "constraint 0 has a zero gradient"));
    assert_int_equal(ga_set_init_mode(s, GA_INIT_REFUSE, 10.0), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "constraint 0 has a zero gradient"));
    assert_null(strstr(ga_last_error(s), "redundant"));
    ga_free(s);
}

/* The solver is not touched: a run's checkpoint stays, a new solver stays open to patterns. */
static void the_solver_is_not_touched(void **s_)
{
    (void)s_;
    g_wrong = 0;
    ga_solver *s = pendulum_checked();
    assert_int_equal(ga_set_tangents(s, stiffness, damping), GA_OK);
    double q[2], v[2], qdd[2], lambda;
    state(q, v, qdd, &lambda);
    assert_int_equal(ga_check_derivatives(s, 0.3, q, v, qdd, &lambda, NULL, 1e-6, NULL), GA_OK);
    const int diag[2] = {0, 1};
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 2, diag, diag), GA_OK);
    ga_free(s);
    s = pendulum_checked();
    assert_int_equal(ga_init(s, 0.3, q, v), GA_OK);
    for (int k = 0; k < 5; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double before[128], after[128];
    assert_true(len <= 128);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    assert_int_equal(ga_check_derivatives(s, 1.0, q, v, NULL, NULL, NULL, 1e-6, NULL), GA_OK);
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_memory_equal(before, after, sizeof(double) * len);
    /* refusals */
    assert_int_equal(ga_check_derivatives(s, 1.0, NULL, v, NULL, NULL, NULL, 1e-6, NULL),
                     GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "q or v is NULL"));
    assert_int_equal(ga_check_derivatives(s, 1.0, q, v, NULL, NULL, NULL, 0.0, NULL),
                     GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "tol"));
    const double bad[2] = {NAN, 0.0};
    assert_int_equal(ga_check_derivatives(s, 1.0, bad, v, NULL, NULL, NULL, 1e-6, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_check_derivatives(NULL, 1.0, q, v, NULL, NULL, NULL, 1e-6, NULL),
                     GA_ERR_ARG);
    ga_free(s);
    ga_solver *bare = NULL;
    assert_int_equal(ga_create(2, 1, &bare), GA_OK);
    assert_int_equal(ga_check_derivatives(bare, 0.0, q, v, NULL, NULL, NULL, 1e-6, NULL),
                     GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(bare), "ga_set_callbacks"));
    ga_free(bare);
    assert_string_equal(ga_strerror(GA_ERR_DERIVATIVE),
                        "a derivative callback disagrees with finite differences");
}

/* The motor-driven slider-crank: its coupling callback (g_q, g_v, g_y, f_y of the current
 * and the controller's integral), checked; one entry of g_y made wrong, named. */
static int g_motor_wrong;
static int wrong_coupling(double t, const double *q, const double *v, const double *y,
                          double *g_q, double *g_v, double *g_y, double *f_y, void *u)
{
    const int rc = scm_coupling(t, q, v, y, g_q, g_v, g_y, f_y, u);
    if (g_motor_wrong)
        g_y[0] = -g_y[0];
    return rc;
}
static void first_order_coupling_is_checked(void **s_)
{
    (void)s_;
    sc_motor mp = sc_motor_default();
    for (g_motor_wrong = 0; g_motor_wrong < 2; ++g_motor_wrong) {
        ga_solver *s = NULL;
        assert_int_equal(ga_create(SC_N, SC_M, &s), GA_OK);
        assert_int_equal(scm_declare(s, &mp), GA_OK);
        assert_int_equal(ga_set_coupling(s, wrong_coupling), GA_OK);
        double q[SC_N], v[SC_N], y[SCM_R] = {0.3, -0.2}, worst = 0.0;
        sc_initial(&mp.crank, 1.0, q, v);
        const ga_status st = ga_check_derivatives(s, 0.1, q, v, NULL, NULL, y, 1e-6, &worst);
        printf("  motor scene, coupling %s: %s (worst %.1e)\n",
               g_motor_wrong ? "with g_y(0, 0) flipped" : "as shipped",
               st ? ga_last_error(s) : "agrees", worst);
        if (g_motor_wrong) {
            assert_int_equal(st, GA_ERR_DERIVATIVE);
            assert_non_null(strstr(ga_last_error(s), "g_y(0, 0)"));
        } else {
            assert_int_equal(st, GA_OK);
            assert_true(worst < 1e-6);
        }
        ga_free(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(correct_callbacks_pass),
        cmocka_unit_test(a_wrong_entry_is_named),
        cmocka_unit_test(a_zero_gradient_is_named),
        cmocka_unit_test(the_solver_is_not_touched),
        cmocka_unit_test(first_order_coupling_is_checked),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
