/* The step hook (ga_set_step_hook): called once per accepted step of ga_step, ga_step_adaptive
 * and ga_advance with that step's state, a run it watches is bit for bit the run without it,
 * it may read the solver but not change it, a nonzero return stops the call after the step
 * (GA_STOPPED), a terminal event still wins, a failure of its multipliers undoes the step, and
 * the adjoint sweep's replays from checkpoints do not call it. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <galpha.h>

#include "helpers.h"

enum { MAX_RECORD = 8192 };

/* The pendulum, and a constraint-acceleration callback that fails when armed: it is called
 * by the consistent multipliers (ga_init, ga_get_lambda, the hook's lambda), never by a step. */
typedef struct scene {
    pendulum p; /* first: the pendulum callbacks read the user pointer as a pendulum */
    int accel_fails;
} scene;

static int failing_accel(double t, const double *q, const double *v, double *out, void *user)
{
    const scene *s = user;
    if (s->accel_fails)
        return -1;
    return pendulum_constraint_accel(t, q, v, out, user);
}

/* What a hook saw, and what it is told to do. */
typedef struct watch {
    long calls;
    double t[MAX_RECORD], q[MAX_RECORD][2], v[MAX_RECORD][2], lambda[MAX_RECORD];
    int lambda_given;
    long stop_at;       /* return 1 at this call (1-based; 0: never) */
    int read_solver;    /* read the solver as a user would, and check what it gives */
    int read_failures;  /* reads that did not give what the hook was passed */
    int write_refusals; /* calls that change the solver, refused as they must be */
} watch;

static int hook(const ga_solver *s, double t, const double *q, const double *v,
                const double *lambda, void *user)
{
    watch *w = user;
    const long k = w->calls++;
    if (k < MAX_RECORD) {
        w->t[k] = t;
        memcpy(w->q[k], q, sizeof w->q[k]);
        memcpy(w->v[k], v, sizeof w->v[k]);
        w->lambda[k] = lambda ? lambda[0] : NAN;
        w->lambda_given += lambda != NULL;
    }
    if (w->read_solver) {
        double tt, qq[2], vv[2], lam, h, qi[2], vi[2], li;
        long long steps;
        if (ga_get_t(s, &tt) != GA_OK || tt != t || ga_get_q(s, qq) != GA_OK ||
            memcmp(qq, q, sizeof qq) != 0 || ga_get_v(s, vv) != GA_OK ||
            memcmp(vv, v, sizeof vv) != 0 || ga_get_lambda(s, &lam) != GA_OK ||
            (lambda && lam != lambda[0]) || ga_get_h_last(s, &h) != GA_OK ||
            ga_interpolate(s, t - 0.5 * h, qi, vi, &li) != GA_OK ||
            ga_get_counter(s, GA_COUNT_STEPS, &steps) != GA_OK || steps != k + 1)
            ++w->read_failures;
        ga_solver *writable = (ga_solver *)s; /* what a careless hook might do */
        double q0[2] = {1.0, 0.0}, v0[2] = {0.0, 0.0};
        w->write_refusals += ga_step(writable, 1e-3) == GA_ERR_STATE;
        w->write_refusals += ga_advance(writable, t + 1.0) == GA_ERR_STATE;
        w->write_refusals += ga_set_rho_inf(writable, 0.5) == GA_ERR_STATE;
        w->write_refusals += ga_init(writable, 0.0, q0, v0) == GA_ERR_STATE;
        w->write_refusals += ga_set_step_hook(writable, NULL, NULL, 0) == GA_ERR_STATE;
        w->write_refusals += ga_reset_counters(writable) == GA_ERR_STATE;
    }
    return w->stop_at && w->calls == w->stop_at;
}

static scene make_scene(void)
{
    scene sc;
    memset(&sc, 0, sizeof sc);
    sc.p.mass = 1.0;
    sc.p.length = 1.0;
    sc.p.gravity = 9.81;
    return sc;
}

/* A pendulum solver started at 0.9 rad from rest, adaptive tolerances 1e-5. */
static ga_solver *started(scene *sc, int formulation)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, sc), GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, failing_accel), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-5, 1e-5), GA_OK);
    double q0[2], v0[2];
    pendulum_state(&sc->p, 0.9, 0.0, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    return s;
}

/* The run without a hook, step by step: the times and states after each accepted step. */
static long plain_adaptive_run(int formulation, double t_end, watch *out)
{
    scene sc = make_scene();
    ga_solver *s = started(&sc, formulation);
    out->calls = 0;
    double t = 0.0;
    while (t < t_end) {
        assert_int_equal(ga_step_adaptive(s, t_end), GA_OK);
        const long k = out->calls++;
        assert_true(k < MAX_RECORD);
        assert_int_equal(ga_get_t(s, &t), GA_OK);
        out->t[k] = t;
        assert_int_equal(ga_get_q(s, out->q[k]), GA_OK);
        assert_int_equal(ga_get_v(s, out->v[k]), GA_OK);
        assert_int_equal(ga_get_lambda(s, &out->lambda[k]), GA_OK);
    }
    ga_free(s);
    return out->calls;
}

static void same_steps(const watch *a, const watch *b, int with_lambda)
{
    assert_int_equal(a->calls, b->calls);
    for (long k = 0; k < a->calls; ++k) {
        assert_true(a->t[k] == b->t[k]);
        assert_memory_equal(a->q[k], b->q[k], sizeof a->q[k]);
        assert_memory_equal(a->v[k], b->v[k], sizeof a->v[k]);
        if (with_lambda)
            assert_true(a->lambda[k] == b->lambda[k]);
    }
}

/* ga_advance with a hook that reads the solver (and tries to change it) at every step: it
 * sees every step the run without the hook takes, with the same states bit for bit, and the
 * multipliers it is passed are ga_get_lambda's. */
static void sees_every_step(void **state)
{
    (void)state;
    static watch plain, seen;
    const int forms[2] = {GA_INDEX3, GA_INDEX2_STABILIZED};
    for (int f = 0; f < 2; ++f) {
        const long steps = plain_adaptive_run(forms[f], 1.0, &plain);
        assert_true(steps > 50);
        for (int with_lambda = 0; with_lambda < 2; ++with_lambda) {
            scene sc = make_scene();
            ga_solver *s = started(&sc, forms[f]);
            memset(&seen, 0, sizeof seen);
            seen.read_solver = 1;
            assert_int_equal(ga_set_step_hook(s, hook, &seen, with_lambda), GA_OK);
            assert_int_equal(ga_advance(s, 1.0), GA_OK);
            same_steps(&plain, &seen, with_lambda);
            assert_int_equal(seen.lambda_given, with_lambda ? steps : 0);
            assert_int_equal(seen.read_failures, 0);
            assert_int_equal(seen.write_refusals, 6 * steps);
            long long counted;
            assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, &counted), GA_OK);
            assert_int_equal(counted, steps);
            ga_free(s);
        }
    }
}

/* ga_step and ga_step_adaptive call it once per step with the state they leave. */
static void once_per_step(void **state)
{
    (void)state;
    static watch seen;
    scene sc = make_scene();
    ga_solver *s = started(&sc, GA_INDEX3);
    memset(&seen, 0, sizeof seen);
    assert_int_equal(ga_set_step_hook(s, hook, &seen, 1), GA_OK);
    for (int k = 0; k < 20; ++k) {
        if (k % 2)
            assert_int_equal(ga_step(s, 1e-2), GA_OK);
        else
            assert_int_equal(ga_step_adaptive(s, 5.0), GA_OK);
        assert_int_equal(seen.calls, k + 1);
        double t, q[2], v[2], lambda;
        assert_int_equal(ga_get_t(s, &t), GA_OK);
        assert_int_equal(ga_get_q(s, q), GA_OK);
        assert_int_equal(ga_get_v(s, v), GA_OK);
        assert_int_equal(ga_get_lambda(s, &lambda), GA_OK);
        assert_true(seen.t[k] == t);
        assert_memory_equal(seen.q[k], q, sizeof q);
        assert_memory_equal(seen.v[k], v, sizeof v);
        assert_true(seen.lambda[k] == lambda);
    }
    /* kept by ga_set_state and by ga_init (a restart) */
    size_t len;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *ckpt = malloc(len * sizeof *ckpt);
    assert_non_null(ckpt);
    assert_int_equal(ga_get_state(s, ckpt, len), GA_OK);
    assert_int_equal(ga_set_state(s, ckpt, len), GA_OK);
    free(ckpt);
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(seen.calls, 21);
    double q0[2], v0[2];
    pendulum_state(&sc.p, 0.5, 0.0, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    assert_int_equal(seen.calls, 21); /* (ga_init takes no step) */
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(seen.calls, 22);
    seen.calls = 20;
    /* removed: no more calls */
    assert_int_equal(ga_set_step_hook(s, NULL, &seen, 1), GA_OK);
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(seen.calls, 20);
    ga_free(s);
}

/* A nonzero return stops ga_advance after that step with GA_STOPPED; going on from there
 * gives the unstopped run bit for bit. ga_step and ga_step_adaptive return GA_STOPPED too. */
static void stops_and_goes_on(void **state)
{
    (void)state;
    static watch plain, seen;
    const long steps = plain_adaptive_run(GA_INDEX3, 2.0, &plain);
    scene sc = make_scene();
    ga_solver *s = started(&sc, GA_INDEX3);
    memset(&seen, 0, sizeof seen);
    seen.stop_at = 7;
    assert_int_equal(ga_set_step_hook(s, hook, &seen, 0), GA_OK);
    assert_int_equal(ga_advance(s, 2.0), GA_STOPPED);
    assert_string_equal(ga_strerror(GA_STOPPED), "stopped by the step hook");
    double t;
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_true(t == plain.t[6]);
    assert_int_equal(seen.calls, 7);
    seen.stop_at = 0;
    assert_int_equal(ga_advance(s, 2.0), GA_OK);
    same_steps(&plain, &seen, 0);
    assert_int_equal(seen.calls, steps);

    seen.stop_at = seen.calls + 1;
    assert_int_equal(ga_step(s, 1e-2), GA_STOPPED);
    seen.stop_at = seen.calls + 1;
    assert_int_equal(ga_step_adaptive(s, 3.0), GA_STOPPED);
    assert_int_equal(seen.calls, steps + 2);
    ga_free(s);
}

/* The pendulum crossing the vertical, terminal. */
static int crossing(double t, const double *q, const double *v, const double *lambda, double *g,
                    void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    g[0] = q[0];
    return 0;
}

/* The step that holds a terminal event is accepted: the hook sees it, and the call returns
 * GA_EVENT whether or not the hook asks to stop there too. */
static void terminal_event_wins(void **state)
{
    (void)state;
    static watch seen;
    for (int stop = 0; stop < 2; ++stop) {
        scene sc = make_scene();
        ga_solver *s = started(&sc, GA_INDEX3);
        assert_int_equal(ga_set_events(s, 1, crossing, NULL, NULL, 0), GA_OK);
        memset(&seen, 0, sizeof seen);
        assert_int_equal(ga_set_step_hook(s, hook, &seen, 0), GA_OK);
        int st;
        long steps = 0;
        if (stop) { /* stop at the step that holds the event: find it first */
            scene sc2 = make_scene();
            ga_solver *probe = started(&sc2, GA_INDEX3);
            assert_int_equal(ga_set_events(probe, 1, crossing, NULL, NULL, 0), GA_OK);
            assert_int_equal(ga_advance(probe, 2.0), GA_EVENT);
            long long k;
            assert_int_equal(ga_get_counter(probe, GA_COUNT_STEPS, &k), GA_OK);
            steps = (long)k;
            seen.stop_at = steps;
            ga_free(probe);
        }
        st = ga_advance(s, 2.0);
        assert_int_equal(st, GA_EVENT);
        double t, te;
        assert_int_equal(ga_get_t(s, &t), GA_OK);
        assert_int_equal(ga_get_event(s, 0, &te, NULL, NULL), GA_OK);
        assert_true(seen.calls > 0 && seen.t[seen.calls - 1] == t);
        assert_true(te <= t && te > 0.3 && te < 0.7);
        if (stop)
            assert_int_equal(seen.calls, steps);
        ga_free(s);
    }
}

/* With multipliers asked for, a failure of their solve fails the step and undoes it: the
 * state is as before, the hook was not called; the run then goes on. (Adaptive index-3 steps
 * solve for them in their error estimate, before the step is accepted: there the failure is
 * the estimate's, and the hook takes the multipliers it left.) */
static void multiplier_failure_undoes_step(void **state)
{
    (void)state;
    static watch seen;
    const int forms[2] = {GA_INDEX3, GA_INDEX2_STABILIZED};
    for (int f = 0; f < 2; ++f)
        for (int adaptive = 0; adaptive < 2; ++adaptive) {
            scene sc = make_scene();
            ga_solver *s = started(&sc, forms[f]);
            memset(&seen, 0, sizeof seen);
            assert_int_equal(ga_set_step_hook(s, hook, &seen, 1), GA_OK);
            for (int k = 0; k < 5; ++k)
                assert_int_equal(adaptive ? ga_step_adaptive(s, 5.0) : ga_step(s, 1e-2), GA_OK);
            size_t len;
            assert_int_equal(ga_state_size(s, &len), GA_OK);
            double *before = malloc(len * sizeof *before), *after = malloc(len * sizeof *after);
            assert_non_null(before);
            assert_non_null(after);
            assert_int_equal(ga_get_state(s, before, len), GA_OK);
            sc.accel_fails = 1;
            assert_int_equal(adaptive ? ga_step_adaptive(s, 5.0) : ga_step(s, 1e-2),
                             GA_ERR_CALLBACK);
            assert_non_null(strstr(ga_last_error(s), adaptive && forms[f] == GA_INDEX3
                                                         ? "for the error estimate"
                                                         : "step hook"));
            assert_int_equal(ga_get_state(s, after, len), GA_OK);
            assert_true(ckpt_same_state(before, after));
            assert_int_equal(seen.calls, 5);
            sc.accel_fails = 0;
            assert_int_equal(adaptive ? ga_advance(s, 1.0) : ga_step(s, 1e-2), GA_OK);
            assert_true(seen.calls > 5);
            free(before);
            free(after);
            ga_free(s);
        }
}

/* Terminal cost: q_x at the end (its gradient in the gravity is what the sweep computes). */
static int terminal_x(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *value, double *d_q, double *d_v,
                      double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)v, (void)qdd, (void)lambda, (void)d_v, (void)d_qdd, (void)d_lambda,
        (void)d_p, (void)user;
    *value = q[0];
    d_q[0] = 1.0;
    return 0;
}

/* The adjoint sweep computes the early segments of a checkpointed run again: not steps the
 * hook is called for. */
static void not_called_by_adjoint_replays(void **state)
{
    (void)state;
    static watch seen;
    scene sc = make_scene();
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &sc), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 1, &sc.p.gravity, NULL, GA_DEPENDS_FORCE), GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 200), GA_OK);
    assert_int_equal(ga_set_adjoint_checkpoints(s, 10, 20), GA_OK);
    memset(&seen, 0, sizeof seen);
    assert_int_equal(ga_set_step_hook(s, hook, &seen, 0), GA_OK);
    double q0[2], v0[2];
    pendulum_state(&sc.p, 0.9, 0.0, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    double J, dJ;
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_x, &J, &dJ), GA_OK);
    assert_int_equal(seen.calls, 100);
    assert_true(isfinite(dJ) && dJ != 0.0);
    ga_free(s);
}

/* Argument and state errors. */
static void errors(void **state)
{
    (void)state;
    assert_int_equal(ga_set_step_hook(NULL, hook, NULL, 0), GA_ERR_ARG);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sees_every_step),
        cmocka_unit_test(once_per_step),
        cmocka_unit_test(stops_and_goes_on),
        cmocka_unit_test(terminal_event_wins),
        cmocka_unit_test(multiplier_failure_undoes_step),
        cmocka_unit_test(not_called_by_adjoint_replays),
        cmocka_unit_test(errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
