/* Adjoint checkpointing (ga_set_adjoint_checkpoints): the record keeps one segment of steps and
 * a checkpoint of the solver after every interval-th step; the sweep computes each earlier
 * segment again from its checkpoint. Against the full record of the same run: the same J and
 * dJ/dp bit for bit, fixed and adaptive steps (the recomputed steps are the recorded ones:
 * each begins with the kept matrix and reuse state its original began with), pendulum,
 * slider-crank, sparse chain, index 3 and 2, with and without forward sensitivities, segments
 * of 1, 7 and 64 steps; the run goes on after the sweep as if it had not happened (state,
 * dense output, events); a run longer than interval * count steps fails the step that does
 * not fit and changes nothing; refusals. */
#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "scene_catalog.h"

static int g_n, g_m, g_np;

/* |v|^2 / 2 + lambda_0^2 + q_0, running or terminal */
static int cost(double t, const double *q, const double *v, const double *qdd,
                const double *lambda, double *value, double *d_q, double *d_v, double *d_qdd,
                double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)qdd, (void)user;
    double J = q[0];
    for (int i = 0; i < g_n; ++i) {
        J += 0.5 * v[i] * v[i];
        d_q[i] = i == 0 ? 1.0 : 0.0, d_v[i] = v[i], d_qdd[i] = 0.0;
    }
    for (int i = 0; i < g_m; ++i)
        d_lambda[i] = 0.0;
    J += lambda[0] * lambda[0];
    d_lambda[0] = 2.0 * lambda[0];
    for (int j = 0; j < g_np; ++j)
        d_p[j] = 0.0;
    *value = J;
    return 0;
}

typedef struct setup {
    int scene, formulation, adaptive, steps;
    double t_end, tol;
    int methods;
} setup;

static int depends(int scene)
{
    return scene == 0 ? GA_DEPENDS_FORCE : GA_DEPENDS_FORCE | GA_DEPENDS_MASS;
}
static double *params(int scene)
{
    return scene == 0 ? &g_catalog_pendulum.gravity
           : scene == 1 ? &g_catalog_crank.m3
                        : &g_catalog_chain.mass;
}

/* A solver for the setup; interval 0: the full record. */
static ga_solver *make(const setup *u, long interval, long count, catalog_scene *sc)
{
    *sc = catalog_make(u->scene);
    g_catalog_pendulum = (pendulum){1.0, 1.0, 9.81};
    g_n = sc->n, g_m = sc->m, g_np = u->scene == 0 ? 1 : 3;
    ga_solver *s = catalog_solver(sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, u->formulation), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, g_np, params(u->scene), NULL, depends(u->scene)),
                     GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, u->methods, 5000), GA_OK);
    if (interval > 0)
        assert_int_equal(ga_set_adjoint_checkpoints(s, interval, count), GA_OK);
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc->q0, sc->v0), GA_OK);
    if (u->adaptive)
        assert_int_equal(ga_set_tolerances(s, u->tol, u->tol), GA_OK);
    return s;
}

static void run(ga_solver *s, const setup *u)
{
    double t = 0.0;
    if (u->adaptive)
        while (t < u->t_end) {
            assert_int_equal(ga_step_adaptive(s, u->t_end), GA_OK);
            assert_int_equal(ga_get_t(s, &t), GA_OK);
        }
    else
        for (int k = 0; k < u->steps; ++k)
            assert_int_equal(ga_step(s, u->t_end / u->steps), GA_OK);
}

static double gradient(ga_solver *s, double *dJ)
{
    double J = 0.0;
    const ga_status st = ga_adjoint_gradient(s, cost, cost, &J, dJ);
    if (st)
        printf("  %s\n", ga_last_error(s));
    assert_int_equal(st, GA_OK);
    return J;
}

static void agrees_with_the_full_record(void **state)
{
    (void)state;
    const int both = GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT;
    const setup list[] = {
        {0, GA_INDEX3, 0, 200, 1.0, 0, GA_SENSITIVITY_ADJOINT},
        {0, GA_INDEX2_STABILIZED, 0, 200, 1.0, 0, both},
        {1, GA_INDEX3, 0, 100, 0.5, 0, GA_SENSITIVITY_ADJOINT},
        {1, GA_INDEX2_STABILIZED, 0, 100, 0.5, 0, both},
        {4, GA_INDEX3, 0, 100, 1.0, 0, GA_SENSITIVITY_ADJOINT},
        {0, GA_INDEX3, 1, 0, 1.0, 1e-4, GA_SENSITIVITY_ADJOINT},
        {1, GA_INDEX2_STABILIZED, 1, 0, 0.5, 1e-5, both},
        {4, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-5, GA_SENSITIVITY_ADJOINT},
    };
    const long intervals[] = {1, 7, 64};
    for (size_t c = 0; c < sizeof list / sizeof list[0]; ++c) {
        const setup *u = &list[c];
        catalog_scene sc;
        ga_solver *full = make(u, 0, 0, &sc);
        run(full, u);
        double dJ[3], J = gradient(full, dJ);
        long long steps = 0;
        assert_int_equal(ga_get_counter(full, GA_COUNT_STEPS, &steps), GA_OK);
        for (size_t i = 0; i < 3; ++i) {
            ga_solver *s = make(u, intervals[i], steps / intervals[i] + 2, &sc);
            run(s, u);
            double dK[3], K = gradient(s, dK);
            double worst = fabs(K - J) / fabs(J);
            for (int j = 0; j < g_np; ++j)
                worst = fmax(worst, fabs(dK[j] - dJ[j]) / fabs(dJ[j]));
            printf("  %s %s %s, %lld steps, interval %ld: J %.15e, largest difference %.1e\n",
                   sc.name, u->formulation == GA_INDEX3 ? "index 3" : "index 2",
                   u->adaptive ? "adaptive" : "fixed", steps, intervals[i], K, worst);
            assert_true(worst == 0.0);
            ga_free(s);
        }
        ga_free(full);
    }
}

/* After the sweep the run goes on as its twin that did not sweep: state, dense output over the
 * last step, events, and a second sweep gives the first one's numbers. */
static int crossing(double t, const double *q, const double *v, const double *lambda,
                    double *g, void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    g[0] = q[0]; /* the pendulum passes the vertical */
    return 0;
}

static void leaves_the_run_as_it_was(void **state)
{
    (void)state;
    const setup u = {0, GA_INDEX2_STABILIZED, 0, 0, 0.0, 0, GA_SENSITIVITY_ADJOINT};
    catalog_scene sc;
    ga_solver *a = make(&u, 5, 100, &sc), *b = make(&u, 5, 100, &sc);
    for (ga_solver **s = (ga_solver *[]){a, b, NULL}; *s; ++s)
        assert_int_equal(ga_set_events(*s, 1, crossing, NULL, NULL, 0), GA_OK);
    for (int k = 0; k < 33; ++k) {
        assert_int_equal(ga_step(a, 3e-3), GA_OK);
        assert_int_equal(ga_step(b, 3e-3), GA_OK);
    }
    double dJ[1], dJ2[1];
    const double J = gradient(a, dJ);
    double x[2][2];
    assert_int_equal(ga_interpolate(a, 0.0985, x[0], NULL, NULL), GA_OK);
    assert_int_equal(ga_interpolate(b, 0.0985, x[1], NULL, NULL), GA_OK);
    assert_memory_equal(x[0], x[1], sizeof x[0]);
    int events[2] = {0, 0};
    for (int k = 0; k < 400; ++k) {
        ga_status st[2] = {ga_step(a, 3e-3), ga_step(b, 3e-3)};
        assert_int_equal(st[0], st[1]);
        assert_true(st[0] == GA_OK || st[0] == GA_EVENT);
        events[0] += st[0] == GA_EVENT;
        assert_int_equal(ga_get_q(a, x[0]), GA_OK);
        assert_int_equal(ga_get_q(b, x[1]), GA_OK);
        assert_memory_equal(x[0], x[1], sizeof x[0]);
        if (k == 50) { /* asked again in the middle: the sweep over the longer run */
            (void)gradient(a, dJ2);
            (void)gradient(b, dJ2);
        }
    }
    printf("  %d events on both runs; J after 33 steps %.15e\n", events[0], J);
    assert_true(events[0] > 0);
    double dA[1], dB[1];
    assert_true(gradient(a, dA) == gradient(b, dB));
    assert_memory_equal(dA, dB, sizeof dA);
    ga_free(a);
    ga_free(b);
}

/* A callback that fails anywhere in the sweep -- at each of its force calls in turn, those
 * of the segments computed again included -- fails the call and leaves the state as its
 * twin's; the next sweep gives the twin's numbers. */
static int g_countdown; /* the force call that fails (counted down), 0: none */
static int failing_force(double t, const double *q, const double *v, double *f, void *user)
{
    if (g_countdown > 0 && --g_countdown == 0)
        return -2;
    return pendulum_force(t, q, v, f, user);
}

static void callback_failure_in_the_sweep(void **state)
{
    (void)state;
    const setup u = {0, GA_INDEX3, 0, 0, 0.0, 0, GA_SENSITIVITY_ADJOINT};
    catalog_scene sc;
    ga_solver *s[2];
    for (int i = 0; i < 2; ++i) {
        sc = catalog_make(0);
        g_n = sc.n, g_m = sc.m, g_np = 1;
        sc.force = failing_force;
        s[i] = catalog_solver(&sc);
        assert_int_equal(ga_set_sensitivity(s[i], 1, params(0), NULL, depends(0)), GA_OK);
        assert_int_equal(ga_set_sensitivity_method(s[i], u.methods, 100), GA_OK);
        assert_int_equal(ga_set_adjoint_checkpoints(s[i], 5, 20), GA_OK);
        assert_int_equal(ga_set_output(s[i], GA_OUTPUT_STEP), GA_OK);
        assert_int_equal(ga_init(s[i], 0.0, sc.q0, sc.v0), GA_OK);
        for (int k = 0; k < 23; ++k)
            assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
    }
    double J = 0.0, dJ[1];
    int calls = 1, in_replay = 0;
    for (;; ++calls) {
        g_countdown = calls;
        const ga_status st = ga_adjoint_gradient(s[0], cost, cost, &J, dJ);
        if (g_countdown > 0) { /* fewer force calls than that: the sweep went through */
            assert_int_equal(st, GA_OK);
            break;
        }
        assert_int_equal(st, GA_ERR_CALLBACK);
        in_replay += strstr(ga_last_error(s[0]), "recomputing step") != NULL;
        double x[2][4][2] = {{{0}}};
        for (int i = 0; i < 2; ++i) {
            assert_int_equal(ga_get_q(s[i], x[i][0]), GA_OK);
            assert_int_equal(ga_get_v(s[i], x[i][1]), GA_OK);
            assert_int_equal(ga_get_qdd(s[i], x[i][2]), GA_OK);
            assert_int_equal(ga_get_lambda(s[i], x[i][3]), GA_OK);
        }
        assert_memory_equal(x[0], x[1], sizeof x[0]);
    }
    g_countdown = 0;
    printf("  each of %d force calls of the sweep failed in turn, %d of them while a segment "
           "was computed again\n", calls - 1, in_replay);
    assert_true(in_replay > 0);
    double dA[1], dB[1];
    assert_true(gradient(s[0], dA) == gradient(s[1], dB));
    assert_memory_equal(dA, dB, sizeof dA);
    /* the failed sweeps left the run's kept matrix as it was (set aside, not rebuilt): the
     * run goes on as the twin's, bit for bit */
    for (int k = 0; k < 10; ++k) {
        double q[2][2];
        for (int i = 0; i < 2; ++i) {
            assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
            assert_int_equal(ga_get_q(s[i], q[i]), GA_OK);
        }
        assert_memory_equal(q[0], q[1], sizeof q[0]);
    }
    ga_free(s[0]);
    ga_free(s[1]);
}

/* A step beyond interval * count fails with GA_ERR_NOMEM and changes nothing; refusals. */
/* A gradient that fails at any force call of its sweep (in a recomputed segment, or in the
 * rebuild of the kept matrix afterwards) leaves the live run as it was: 7 steps later q, v, a
 * and lambda equal a twin's that never made the call, bit for bit, and so does the next
 * gradient. */
static void a_failed_sweep_leaves_the_run_as_it_was(void **state)
{
    (void)state;
    const setup u = {0, GA_INDEX3, 0, 0, 0.0, 0, GA_SENSITIVITY_ADJOINT};
    int calls = 0, k = 1;
    for (;; ++k) {
        catalog_scene sc;
        ga_solver *s[2];
        for (int i = 0; i < 2; ++i) {
            sc = catalog_make(0);
            g_n = sc.n, g_m = sc.m, g_np = 1;
            sc.force = failing_force;
            s[i] = catalog_solver(&sc);
            assert_int_equal(ga_set_sensitivity(s[i], 1, params(0), NULL, depends(0)), GA_OK);
            assert_int_equal(ga_set_sensitivity_method(s[i], u.methods, 100), GA_OK);
            assert_int_equal(ga_set_adjoint_checkpoints(s[i], 4, 25), GA_OK);
            assert_int_equal(ga_init(s[i], 0.0, sc.q0, sc.v0), GA_OK);
            for (int j = 0; j < 12; ++j)
                assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
        }
        double J = 0.0, dJ[1];
        g_countdown = k;
        const ga_status st = ga_adjoint_gradient(s[0], cost, cost, &J, dJ);
        char why[512];
        snprintf(why, sizeof why, "%s", ga_last_error(s[0]));
        const int went_through = g_countdown > 0;
        g_countdown = 0;
        if (!went_through)
            assert_int_equal(st, GA_ERR_CALLBACK);
        double x[2][4][2] = {{{0}}};
        for (int i = 0; i < 2; ++i) {
            for (int j = 0; j < 7; ++j)
                assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
            assert_int_equal(ga_get_q(s[i], x[i][0]), GA_OK);
            assert_int_equal(ga_get_v(s[i], x[i][1]), GA_OK);
            assert_int_equal(ga_get_a(s[i], x[i][2]), GA_OK);
            assert_int_equal(ga_get_lambda(s[i], x[i][3]), GA_OK);
        }
        if (memcmp(x[0], x[1], sizeof x[0]) != 0)
            fail_msg("the sweep failed at force call %d (%s): 7 steps later the run differs "
                     "(q by %.1e)", k, why, fabs(x[0][0][0] - x[1][0][0]));
        double dA[1], dB[1];
        assert_true(gradient(s[0], dA) == gradient(s[1], dB));
        assert_memory_equal(dA, dB, sizeof dA);
        ga_free(s[0]);
        ga_free(s[1]);
        if (went_through)
            break;
        ++calls;
    }
    printf("  the sweep failed at each of its %d force calls in turn: the run went on as its "
           "twin's\n", calls);
}

static void capacity_and_refusals(void **state)
{
    (void)state;
    const setup u = {0, GA_INDEX3, 0, 0, 0.0, 0, GA_SENSITIVITY_ADJOINT};
    catalog_scene sc;
    ga_solver *s = make(&u, 4, 3, &sc);
    for (int k = 0; k < 12; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    double q[2][2];
    assert_int_equal(ga_get_q(s, q[0]), GA_OK);
    assert_int_equal(ga_step(s, 1e-2), GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(s), "adjoint record is full (12 steps: interval = 4 "
                                             "times 3 checkpoints, ga_set_adjoint_checkpoints)"));
    assert_int_equal(ga_get_q(s, q[1]), GA_OK);
    assert_memory_equal(q[0], q[1], sizeof q[0]);
    double dJ[1];
    (void)gradient(s, dJ);
    assert_int_equal(ga_set_adjoint_checkpoints(s, 4, 3), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "after ga_init"));
    ga_free(s);

    ga_solver *t = catalog_solver(&sc);
    assert_int_equal(ga_set_adjoint_checkpoints(t, 4, 3), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(t), "GA_SENSITIVITY_ADJOINT"));
    assert_int_equal(ga_set_sensitivity(t, 1, &g_catalog_pendulum.gravity, NULL,
                                        GA_DEPENDS_FORCE),
                     GA_OK);
    assert_int_equal(ga_set_adjoint_checkpoints(t, 4, 3), GA_ERR_STATE);
    assert_int_equal(ga_set_sensitivity_method(t, GA_SENSITIVITY_ADJOINT, 10), GA_OK);
    assert_int_equal(ga_set_adjoint_checkpoints(t, -1, 3), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(t), "interval = -1"));
    assert_int_equal(ga_set_adjoint_checkpoints(t, 4, 0), GA_ERR_ARG);
    assert_int_equal(ga_set_adjoint_checkpoints(t, 1L << 40, 1L << 40), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(t), "overflows"));
    /* sizes beyond memory, refused before anything is allocated or multiplied (the step log's
     * 11 doubles per step of interval * count wrapped to a small vector) */
    assert_int_equal(ga_set_adjoint_checkpoints(t, 1, 1676976733973595602L), GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(t), "checkpoints of"));
    assert_int_equal(ga_set_adjoint_checkpoints(t, LONG_MAX, 1), GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(t), "adjoint segment of interval"));
    assert_int_equal(ga_set_adjoint_checkpoints(t, 1L << 60, 2), GA_ERR_NOMEM);
    assert_int_equal(ga_set_adjoint_checkpoints(t, 1L << 56, 100), GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(t), "step log"));
    /* interval 0: the full record of max_steps again (10 steps) */
    assert_int_equal(ga_set_adjoint_checkpoints(t, 4, 1), GA_OK);
    assert_int_equal(ga_set_adjoint_checkpoints(t, 0, 0), GA_OK);
    assert_int_equal(ga_init(t, 0.0, sc.q0, sc.v0), GA_OK);
    for (int k = 0; k < 10; ++k)
        assert_int_equal(ga_step(t, 1e-2), GA_OK);
    assert_int_equal(ga_step(t, 1e-2), GA_ERR_NOMEM);
    ga_free(t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(agrees_with_the_full_record),
        cmocka_unit_test(leaves_the_run_as_it_was),
        cmocka_unit_test(callback_failure_in_the_sweep),
        cmocka_unit_test(a_failed_sweep_leaves_the_run_as_it_was),
        cmocka_unit_test(capacity_and_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
