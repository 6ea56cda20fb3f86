/* Events through the C API (ga_set_events): located times against exact references (the
 * pendulum's quarter period from the complete elliptic integral, the time a whirled rope goes
 * slack from a quadrature of the energy equation), their convergence at order 2 under fixed
 * steps and their proportionality to the tolerance in adaptive runs; the same events with and
 * without Jacobian reuse; several roots in one step, a root at a step end, the log and its
 * capacity; the sparse path and the index-2 formulation; runs that events do not change; and
 * every failure path, which leaves the solver as it was. */
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

#include "chain_solver.h"
#include "helpers.h"

/* The pendulum of every test here, with what the event functions need besides. */
typedef struct scene {
    pendulum p;         /* first: the pendulum callbacks read the user pointer as a pendulum */
    double level[3];    /* event functions of t only: g_k = t - level[k] */
    double freq;        /* sines: g_k = sin(2 pi freq t - k pi / 3) */
    int fail_at;        /* the event callback returns `fail_with` at this call (1-based) */
    double fail_after;  /* levels: ... or at any t > fail_after (if positive) */
    int fail_with;
    int calls;
    double sign_flip;   /* multiplies the multiplier event (test of with_multipliers) */
} scene;

static scene make_scene(void)
{
    scene s;
    memset(&s, 0, sizeof s);
    s.p.mass = 1.0;
    s.p.length = 1.0;
    s.p.gravity = 9.81;
    s.sign_flip = 1.0;
    return s;
}

static int counted(scene *s)
{
    ++s->calls;
    return s->fail_at && s->calls == s->fail_at ? s->fail_with : 0;
}

/* g_0 = x: the pendulum crosses the vertical. */
static int crossing_vertical(double t, const double *q, const double *v, const double *lambda,
                             double *g, void *user)
{
    (void)t, (void)v, (void)lambda;
    g[0] = q[0];
    return counted(user);
}

/* g_0 = lambda: the rod (a rope) pulls no more. */
static int rope_tension(double t, const double *q, const double *v, const double *lambda,
                        double *g, void *user)
{
    (void)t, (void)q, (void)v;
    scene *s = user;
    if (!lambda)
        return -1;
    g[0] = s->sign_flip * lambda[0];
    return counted(user);
}

static int levels(double t, const double *q, const double *v, const double *lambda, double *g,
                  void *user)
{
    (void)q, (void)v, (void)lambda;
    scene *s = user;
    for (int k = 0; k < 3; ++k)
        g[k] = t - s->level[k];
    if (s->fail_after > 0.0 && t > s->fail_after)
        return s->fail_with;
    return counted(user);
}

static int sines(double t, const double *q, const double *v, const double *lambda, double *g,
                 void *user)
{
    (void)q, (void)v, (void)lambda;
    scene *s = user;
    for (int k = 0; k < 3; ++k)
        g[k] = sin(2.0 * M_PI * s->freq * t - k * M_PI / 3.0);
    return counted(user);
}

static int not_a_number(double t, const double *q, const double *v, const double *lambda,
                        double *g, void *user)
{
    (void)t, (void)q, (void)v, (void)lambda, (void)user;
    g[0] = NAN;
    return 0;
}

/* ---- references -------------------------------------------------------------------------- */
/* A quarter period of the pendulum released at rest from theta0: sqrt(L/g) K(sin(theta0/2)),
 * K from the arithmetic-geometric mean, K(k) = pi / (2 AGM(1, sqrt(1 - k^2))). */
static double quarter_period(const pendulum *p, double theta0)
{
    const double k = sin(0.5 * theta0);
    double a = 1.0, b = sqrt(1.0 - k * k);
    for (int i = 0; i < 40; ++i) {
        const double an = 0.5 * (a + b);
        b = sqrt(a * b);
        a = an;
    }
    return sqrt(p->length / p->gravity) * M_PI / (2.0 * a);
}

/* Whirled from the bottom with speed u (2 g L < u^2 < 5 g L), the rope pulls m (|v|^2/L + g cos
 * theta) with |v|^2 = u^2 - 2 g L (1 - cos theta): zero at cos theta* = (2 g L - u^2) / (3 g L).
 * The time to get there, the integral of L / |v| over theta in [0, theta*], by composite
 * Simpson (the integrand is smooth: |v| > 0 up to theta*). */
static double slack_time(const pendulum *p, double u)
{
    const double g = p->gravity, L = p->length;
    const double theta_star = acos((2.0 * g * L - u * u) / (3.0 * g * L));
    const int N = 20000;
    const double d = theta_star / N;
    double sum = 0.0;
    for (int i = 0; i <= N; ++i) {
        const double th = i * d, w = (i == 0 || i == N) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += w * L / sqrt(u * u - 2.0 * g * L * (1.0 - cos(th)));
    }
    return sum * d / 3.0;
}

/* ---- helpers ----------------------------------------------------------------------------- */
static ga_solver *released(scene *sc, double theta0, double omega0, int formulation)
{
    ga_solver *s = pendulum_new_solver(&sc->p, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    double q[2], v[2];
    pendulum_state(&sc->p, theta0, omega0, q, v);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    return s;
}

typedef struct found {
    int count;
    double t[256];
    int index[256], direction[256];
} found;

static void collect(const ga_solver *s, found *f)
{
    int n = 0;
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    for (int i = 0; i < n; ++i) {
        assert_true(f->count < 256);
        assert_int_equal(ga_get_event(s, i, &f->t[f->count], &f->index[f->count],
                                      &f->direction[f->count]),
                         GA_OK);
        ++f->count;
    }
}

/* Fixed steps of h to t_end, every event collected; a terminal one goes on. */
static found run_fixed(ga_solver *s, double h, double t_end)
{
    found f = {0};
    double t = 0.0;
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    while (t < t_end - 1e-12) {
        const ga_status st = ga_step(s, h);
        assert_true(st == GA_OK || st == GA_EVENT);
        collect(s, &f);
        assert_int_equal(ga_get_t(s, &t), GA_OK);
    }
    return f;
}

static found run_adaptive(ga_solver *s, double t_end)
{
    found f = {0};
    ga_status st;
    while ((st = ga_advance(s, t_end)) == GA_EVENT)
        collect(s, &f);
    assert_int_equal(st, GA_OK);
    collect(s, &f);
    return f;
}

/* ---- located times against exact ones --------------------------------------------------- */
/* Released horizontally, the pendulum crosses the vertical at T/4 (falling x) and 3T/4
 * (rising): order 2 in the located time under fixed steps, in both formulations. */
static void quarter_period_converges_at_order_two(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double h[4], e1[4], e3[4];
        for (int k = 0; k < 4; ++k) {
            scene sc = make_scene();
            const double T4 = quarter_period(&sc.p, M_PI / 2);
            ga_solver *s = released(&sc, M_PI / 2, 0.0, formulation);
            const int dir = GA_EVENT_BOTH, terminal = 0;
            assert_int_equal(ga_set_events(s, 1, crossing_vertical, &dir, &terminal, 0), GA_OK);
            h[k] = 0.01 / (1 << k);
            const found f = run_fixed(s, h[k], 3.5 * T4);
            assert_int_equal(f.count, 2);
            assert_int_equal(f.direction[0], -1);
            assert_int_equal(f.direction[1], +1);
            e1[k] = fabs(f.t[0] - T4);
            e3[k] = fabs(f.t[1] - 3.0 * T4);
            ga_free(s);
        }
        const double p1 = fit_order(h, e1, 4), p3 = fit_order(h, e3, 4);
        printf("    %s: |t - T/4| %.2e .. %.2e (order %.2f), |t - 3T/4| %.2e .. %.2e (%.2f)\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", e1[0], e1[3], p1, e3[0], e3[3],
               p3);
        assert_true(p1 > 1.8 && p1 < 2.3);
        assert_true(p3 > 1.8 && p3 < 2.3);
        assert_true(e1[3] < 1e-4 && e3[3] < 1e-4);
    }
}

/* Adaptive runs: the error of the located time follows the tolerance (slope 1). */
static void quarter_period_follows_the_tolerance(void **state)
{
    (void)state;
    enum { K = 5 };
    const double tol[K] = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double e[K];
        for (int k = 0; k < K; ++k) {
            scene sc = make_scene();
            const double T4 = quarter_period(&sc.p, M_PI / 2);
            ga_solver *s = released(&sc, M_PI / 2, 0.0, formulation);
            assert_int_equal(ga_set_tolerances(s, tol[k], tol[k]), GA_OK);
            assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, NULL, 0), GA_OK);
            const found f = run_adaptive(s, 3.5 * T4);
            assert_int_equal(f.count, 2);
            e[k] = fmax(fabs(f.t[0] - T4), fabs(f.t[1] - 3.0 * T4));
            ga_free(s);
        }
        const double slope = fit_order(tol, e, K);
        printf("    %s: located-time error / tol %.2f %.2f %.2f %.2f %.2f, slope %.2f\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", e[0] / tol[0], e[1] / tol[1],
               e[2] / tol[2], e[3] / tol[3], e[4] / tol[4], slope);
        assert_true(slope > 0.85 && slope < 1.15);
    }
}

/* A rope whirled from the bottom with too little speed goes slack where its multiplier
 * reaches zero: the event on lambda (consistent at the interpolated state) converges at
 * order 2 to the time from the energy equation's quadrature. */
static void slack_rope_converges_at_order_two(void **state)
{
    (void)state;
    double h[4], e[4];
    for (int k = 0; k < 4; ++k) {
        scene sc = make_scene();
        const double u = sqrt(3.5 * sc.p.gravity * sc.p.length);
        const double t_star = slack_time(&sc.p, u);
        ga_solver *s = released(&sc, 0.0, u / sc.p.length, GA_INDEX3);
        const int dir = GA_EVENT_FALLING, terminal = 1;
        assert_int_equal(ga_set_events(s, 1, rope_tension, &dir, &terminal, 1), GA_OK);
        h[k] = 0.01 / (1 << k);
        ga_status st = GA_OK;
        double t = 0.0;
        while (st == GA_OK && t < 2.0 * t_star) {
            st = ga_step(s, h[k]);
            assert_int_equal(ga_get_t(s, &t), GA_OK);
        }
        assert_int_equal(st, GA_EVENT);
        int n = 0, index = -1, direction = 0;
        double te = 0.0, lambda = 0.0;
        assert_int_equal(ga_get_event_count(s, &n), GA_OK);
        assert_int_equal(n, 1);
        assert_int_equal(ga_get_event(s, 0, &te, &index, &direction), GA_OK);
        assert_int_equal(index, 0);
        assert_int_equal(direction, -1);
        /* the event lies in the last step, and the multiplier vanishes there */
        assert_true(te > t - h[k] && te <= t);
        assert_int_equal(ga_interpolate(s, te, NULL, NULL, &lambda), GA_OK);
        assert_true(fabs(lambda) < 1e-9);
        e[k] = fabs(te - t_star);
        ga_free(s);
    }
    const double p = fit_order(h, e, 4);
    printf("    slack: |t - t*| %.2e %.2e %.2e %.2e, order %.2f\n", e[0], e[1], e[2], e[3], p);
    assert_true(p > 1.8 && p < 2.3);
}

/* Without with_multipliers the event function gets no lambda. */
static void multipliers_only_when_asked(void **state)
{
    (void)state;
    scene sc = make_scene();
    ga_solver *s = released(&sc, 0.0, 1.0, GA_INDEX3);
    assert_int_equal(ga_set_events(s, 1, rope_tension, NULL, NULL, 0), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_ERR_CALLBACK);
    assert_non_null(strstr(ga_last_error(s), "event callback returned -1"));
    ga_free(s);
}

/* ---- Jacobian reuse cannot change what is found ------------------------------------------ */
static void reuse_does_not_change_the_events(void **state)
{
    (void)state;
    const double h = 2e-3;
    found f[2];
    double q[2][2048][2];
    int steps = 0;
    for (int r = 0; r < 2; ++r) {
        scene sc = make_scene();
        ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
        assert_int_equal(ga_set_jacobian_reuse(s, r ? GA_REUSE_NEVER : GA_REUSE_AUTO), GA_OK);
        const int terminal = 0;
        assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, &terminal, 0), GA_OK);
        found all = {0};
        steps = 0;
        double t = 0.0;
        while (t < 2.0) {
            const ga_status st = ga_step(s, h);
            assert_true(st == GA_OK);
            collect(s, &all);
            assert_int_equal(ga_get_q(s, q[r][steps]), GA_OK);
            ++steps;
            assert_int_equal(ga_get_t(s, &t), GA_OK);
        }
        f[r] = all;
        ga_free(s);
    }
    double dq = 0.0;
    for (int i = 0; i < steps; ++i)
        dq = fmax(dq, max_abs_diff(q[0][i], q[1][i], 2));
    assert_int_equal(f[0].count, f[1].count);
    assert_true(f[0].count == 2);
    scene sc = make_scene();
    const double speed = sqrt(2.0 * sc.p.gravity * sc.p.length); /* |x'| at the vertical */
    for (int i = 0; i < f[0].count; ++i) {
        assert_int_equal(f[0].index[i], f[1].index[i]);
        assert_int_equal(f[0].direction[i], f[1].direction[i]);
        const double dt = fabs(f[0].t[i] - f[1].t[i]);
        printf("    event %d: times differ by %.2e, |dx| / |x'| of the steps up to %.2e\n", i,
               dt, dq / speed);
        assert_true(dt <= 2.0 * dq / speed + 1e-14);
    }
}

/* ---- several roots, a root at a step end, the log ----------------------------------------- */
/* Two roots in one step (the later one first in the list), both non-terminal: logged in time
 * order, each within IDA's tolerance after its root. Terminal: one per call, and the second
 * call takes no step. */
static void two_roots_in_one_step(void **state)
{
    (void)state;
    for (int terminal_run = 0; terminal_run < 2; ++terminal_run) {
        scene sc = make_scene();
        sc.level[0] = 0.3375;
        sc.level[1] = 0.3125;
        sc.level[2] = 10.0;
        ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
        const int terminal[3] = {terminal_run, terminal_run, terminal_run};
        assert_int_equal(ga_set_events(s, 3, levels, NULL, terminal, 0), GA_OK);
        const double h = 0.05, tol = 100 * 2.3e-16 * (0.35 + h);
        found f = {0};
        for (int i = 0; i < 6; ++i)
            assert_int_equal(ga_step(s, h), GA_OK);
        double t = 0.0;
        assert_int_equal(ga_get_t(s, &t), GA_OK);
        assert_true(fabs(t - 0.3) < 1e-12);
        if (terminal_run) {
            assert_int_equal(ga_step(s, h), GA_EVENT);
            collect(s, &f);
            assert_int_equal(f.count, 1);
            assert_int_equal(ga_step(s, h), GA_EVENT); /* the rest of the same step */
            assert_int_equal(ga_get_t(s, &t), GA_OK);
            assert_true(fabs(t - 0.35) < 1e-12);
            collect(s, &f);
            assert_int_equal(ga_step(s, h), GA_OK);
            collect(s, &f);
        } else {
            assert_int_equal(ga_step(s, h), GA_OK);
            collect(s, &f);
        }
        assert_int_equal(f.count, 2);
        assert_int_equal(f.index[0], 1);
        assert_int_equal(f.index[1], 0);
        assert_true(f.t[0] >= 0.3125 && f.t[0] - 0.3125 <= tol);
        assert_true(f.t[1] >= 0.3375 && f.t[1] - 0.3375 <= tol);
        assert_int_equal(f.direction[0], 1);
        ga_free(s);
    }
}

/* A function zero at a step's end fires there once, exactly; one zero at the start never. */
static void root_at_a_step_end_found_once(void **state)
{
    (void)state;
    scene sc = make_scene();
    sc.level[0] = 0.5;   /* 4 steps of 1/8 */
    sc.level[1] = 0.0;   /* zero at t0 */
    sc.level[2] = 0.75;
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    /* (steps of 1/8 do not resolve the swing, which the check sees; these events are
     * functions of t alone) */
    assert_int_equal(ga_set_resolution_check(s, INFINITY), GA_OK);
    const int terminal[3] = {0, 0, 0};
    assert_int_equal(ga_set_events(s, 3, levels, NULL, terminal, 0), GA_OK);
    const found f = run_fixed(s, 0.125, 1.0);
    assert_int_equal(f.count, 2);
    assert_int_equal(f.index[0], 0);
    assert_true(f.t[0] == 0.5);
    assert_int_equal(f.index[1], 2);
    assert_true(f.t[1] == 0.75);
    ga_free(s);
}

/* g = (t - t0) (t0 + 0.05 - t): zero at the start of the first step, positive inside it, and
 * falling through zero at t0 + 0.05. With h = 0.1 the values at the step's ends (0, then
 * negative) showed no crossing and it was never reported (with h = 0.01 it was); every restart
 * at an event whose function crosses again within the first step is such a case. */
static double g_t0;
static int zero_at_start(double t, const double *q, const double *v, const double *lambda,
                         double *g, void *user)
{
    (void)q, (void)v, (void)lambda, (void)user;
    g[0] = (t - g_t0) * (g_t0 + 0.05 - t);
    return 0;
}
static void a_zero_at_the_start_of_a_step_hides_no_crossing(void **state)
{
    (void)state;
    const double starts[] = {0.0, 1.25};
    for (size_t i = 0; i < 2; ++i)
        for (int adaptive = 0; adaptive < 2; ++adaptive) {
            scene sc = make_scene();
            g_t0 = starts[i];
            ga_solver *s = pendulum_new_solver(&sc.p, 1);
            assert_non_null(s);
            double q[2], v[2];
            pendulum_state(&sc.p, 0.5, 0.0, q, v);
            assert_int_equal(ga_init(s, g_t0, q, v), GA_OK); /* a restart at t0 = 1.25 */
            assert_int_equal(ga_set_tolerances(s, 1e-3, 1e-3), GA_OK);
            assert_int_equal(ga_set_initial_step(s, 0.1), GA_OK);
            assert_int_equal(ga_set_events(s, 1, zero_at_start, NULL, NULL, 0), GA_OK);
            const ga_status st =
                adaptive ? ga_step_adaptive(s, g_t0 + 0.1) : ga_step(s, 0.1);
            assert_int_equal(st, GA_EVENT);
            double te;
            int index, direction;
            assert_int_equal(ga_get_event(s, 0, &te, &index, &direction), GA_OK);
            assert_int_equal(direction, -1);
            assert_true(fabs(te - (g_t0 + 0.05)) < 1e-12);
            ga_free(s);
        }
}

/* 89 crossings of three sines in one ga_advance: the call stops when its log is full, the
 * next one goes on, and every root is found once, in order, next to its exact time. */
static void a_full_log_loses_nothing(void **state)
{
    (void)state;
    scene sc = make_scene();
    sc.freq = 15.0;
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    assert_int_equal(ga_set_step_limits(s, 0.0, 0.01), GA_OK);
    const int terminal[3] = {0, 0, 0};
    assert_int_equal(ga_set_events(s, 3, sines, NULL, terminal, 0), GA_OK);
    found f = {0};
    int n = 0;
    assert_int_equal(ga_advance(s, 1.0 - 1e-3), GA_EVENT);
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    assert_int_equal(n, GA_EVENT_LOG);
    collect(s, &f);
    assert_int_equal(ga_advance(s, 1.0 - 1e-3), GA_OK);
    collect(s, &f);
    /* roots of sin(2 pi f t - k pi/3): t = (j + k/3) / (2 f), j >= 1 for k = 0 */
    assert_int_equal(f.count, 29 + 30 + 30);
    for (int i = 0; i < f.count; ++i) {
        const double j = f.t[i] * 2.0 * sc.freq - f.index[i] / 3.0;
        assert_true(fabs(j - round(j)) * 1.0 / (2 * sc.freq) < 1e-12);
        if (i > 0)
            assert_true(f.t[i] > f.t[i - 1]);
        assert_int_equal(f.direction[i], ((long)round(j) % 2) ? -1 : 1);
    }
    ga_free(s);
}

/* ---- the sparse path and the index-2 formulation ------------------------------------------ */
static int first_link_angle(double t, const double *q, const double *v, const double *lambda,
                            double *g, void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    g[0] = q[2] + M_PI / 4; /* the first link, falling from horizontal, passes -45 degrees */
    return 0;
}

static void chain_events_sparse_and_dense_agree(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double te[2];
        for (int sparse = 0; sparse < 2; ++sparse) {
            chain c = chain_make(10);
            ga_solver *s = chain_solver(&c, 1);
            assert_int_equal(
                ga_set_linear_solver(s, sparse ? GA_LINEAR_SPARSE : GA_LINEAR_DENSE), GA_OK);
            assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
            assert_int_equal(ga_set_events(s, 1, first_link_angle, NULL, NULL, 1), GA_OK);
            double q[30], v[30];
            chain_initial(&c, q, v);
            assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
            ga_status st;
            while ((st = ga_step(s, 1e-3)) == GA_OK) {
            }
            assert_int_equal(st, GA_EVENT);
            assert_int_equal(ga_get_event(s, 0, &te[sparse], NULL, NULL), GA_OK);
            /* a root of the interpolant: g changes sign across the located time */
            double qa[30], qb[30];
            assert_int_equal(ga_interpolate(s, te[sparse], qb, NULL, NULL), GA_OK);
            assert_int_equal(ga_interpolate(s, te[sparse] - 1e-9, qa, NULL, NULL), GA_OK);
            assert_true(qa[2] + M_PI / 4 > 0.0 && qb[2] + M_PI / 4 <= 1e-13);
            if (sparse)
                assert_non_null(strstr(ga_linear_solver_name(s), "sparse"));
            ga_free(s);
        }
        printf("    chain, %s: t = %.15f sparse, %.15f dense\n",
               formulation ? "index 2" : "index 3", te[1], te[0]);
        assert_true(fabs(te[0] - te[1]) < 1e-9);
    }
}

/* ---- events do not change the run --------------------------------------------------------- */
/* Stopping at every terminal event and going on gives the run without events, bit for bit. */
static void stopping_at_events_changes_nothing(void **state)
{
    (void)state;
    double q[2][2], v[2][2];
    long long steps[2];
    for (int with = 0; with < 2; ++with) {
        scene sc = make_scene();
        ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        if (with) {
            assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, NULL, 1), GA_OK);
            const found f = run_adaptive(s, 4.0);
            assert_int_equal(f.count, 3);
        } else {
            assert_int_equal(ga_advance(s, 4.0), GA_OK);
        }
        assert_int_equal(ga_get_q(s, q[with]), GA_OK);
        assert_int_equal(ga_get_v(s, v[with]), GA_OK);
        assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, &steps[with]), GA_OK);
        ga_free(s);
    }
    assert_memory_equal(q[0], q[1], sizeof q[0]);
    assert_memory_equal(v[0], v[1], sizeof v[0]);
    assert_true(steps[0] == steps[1]);
}

/* ga_init on a running solver (the restart after a jump) keeps the events: a pendulum stopped
 * at the vertical and sent back with the opposite velocity reaches it again after half a
 * period of its swing, found by the same functions. */
static void a_restart_keeps_the_events(void **state)
{
    (void)state;
    scene sc = make_scene();
    const double T4 = quarter_period(&sc.p, M_PI / 2);
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    assert_int_equal(ga_set_tolerances(s, 1e-8, 1e-8), GA_OK);
    const int dir = GA_EVENT_FALLING;
    assert_int_equal(ga_set_events(s, 1, crossing_vertical, &dir, NULL, 0), GA_OK);
    assert_int_equal(ga_advance(s, 10.0), GA_EVENT);
    double te, q[2], v[2];
    assert_int_equal(ga_get_event(s, 0, &te, NULL, NULL), GA_OK);
    assert_int_equal(ga_interpolate(s, te, q, v, NULL), GA_OK);
    v[0] = -v[0], v[1] = -v[1]; /* a perfectly elastic wall */
    assert_int_equal(ga_init(s, te, q, v), GA_OK);
    assert_int_equal(ga_advance(s, 10.0), GA_EVENT);
    double te2;
    assert_int_equal(ga_get_event(s, 0, &te2, NULL, NULL), GA_OK);
    printf("    back at the vertical after %.9f (exact %.9f)\n", te2 - te, 2.0 * T4);
    assert_true(fabs(te2 - te - 2.0 * T4) < 1e-5);
    ga_free(s);
}

/* ---- failures ----------------------------------------------------------------------------- */
static void bad_arguments_are_refused(void **state)
{
    (void)state;
    scene sc = make_scene();
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    const int bad_dir = 2;
    assert_int_equal(ga_set_events(NULL, 1, crossing_vertical, NULL, NULL, 0), GA_ERR_ARG);
    assert_int_equal(ga_set_events(s, -1, crossing_vertical, NULL, NULL, 0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "negative"));
    assert_int_equal(ga_set_events(s, 1, NULL, NULL, NULL, 0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "fn is NULL"));
    assert_int_equal(ga_set_events(s, 1, crossing_vertical, &bad_dir, NULL, 0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "direction[0] = 2"));
    int n = -1;
    assert_int_equal(ga_get_event_count(NULL, &n), GA_ERR_ARG);
    assert_int_equal(ga_get_event_count(s, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "count is NULL"));
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    assert_int_equal(n, 0);
    double t;
    assert_int_equal(ga_get_event(s, 0, &t, NULL, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "not an entry"));
    assert_int_equal(ga_get_event(NULL, 0, &t, NULL, NULL), GA_ERR_ARG);
    /* the refused calls set nothing: a step finds no event function */
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    assert_int_equal(sc.calls, 0);
    /* events set and removed again */
    assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, NULL, 0), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    assert_int_equal(sc.calls, 2);
    assert_int_equal(ga_set_events(s, 0, NULL, NULL, NULL, 0), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    assert_int_equal(sc.calls, 2);
    assert_string_equal(ga_strerror(GA_EVENT), "stopped at an event");
    ga_free(s);
}

/* t, q, v, qdd, lambda, a and the last h of the pendulum (the part of the state a failed step
 * must leave bit for bit; the kept matrix, like after any failed step, is dropped). */
static void solver_state(const ga_solver *s, double *x)
{
    memset(x, 0, 16 * sizeof *x);
    assert_int_equal(ga_get_t(s, x), GA_OK);
    assert_int_equal(ga_get_q(s, x + 1), GA_OK);
    assert_int_equal(ga_get_v(s, x + 3), GA_OK);
    assert_int_equal(ga_get_qdd(s, x + 5), GA_OK);
    assert_int_equal(ga_get_lambda(s, x + 7), GA_OK);
    assert_int_equal(ga_get_a(s, x + 8), GA_OK);
    assert_int_equal(ga_get_h_last(s, x + 10), GA_OK);
}

/* A failing event callback fails the step that called it; the solver, its counters of
 * accepted steps and the event search are as before, and a retry finds the same event. */
static void a_failed_event_call_changes_nothing(void **state)
{
    (void)state;
    const int codes[2] = {1, -1};
    const ga_status expect[2] = {GA_ERR_CALLBACK_RETRY, GA_ERR_CALLBACK};
    double te_ref = 0.0; /* the event of the run without failures */
    for (int c = 0; c < 2; ++c) {
        for (int fail_at = 0; fail_at <= 12; ++fail_at) {
            scene sc = make_scene();
            const double T4 = quarter_period(&sc.p, M_PI / 2);
            ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
            assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, NULL, 0), GA_OK);
            /* up to the step before the event; the failure falls anywhere from the start's
             * evaluation to the search inside the event's step */
            const double h = T4 / 7.5;
            for (int i = 0; i < 7; ++i)
                assert_int_equal(ga_step(s, h), GA_OK);
            sc.fail_at = fail_at ? sc.calls + fail_at : 0;
            sc.fail_with = codes[c];
            double before[16], after[16];
            solver_state(s, before);
            long long steps0, steps1, failed0, failed1;
            ga_get_counter(s, GA_COUNT_STEPS, &steps0);
            ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed0);
            ga_status st = ga_step(s, h);
            if (st == GA_EVENT) { /* no failure, or it would come after the search */
                assert_int_equal(ga_get_event(s, 0, &te_ref, NULL, NULL), GA_OK);
                ga_free(s);
                assert_true(fabs(te_ref - T4) < 0.02); /* h is T/30 */
                if (fail_at == 0)
                    continue;
                break;
            }
            assert_int_equal(st, expect[c]);
            assert_non_null(strstr(ga_last_error(s), "event callback returned"));
            solver_state(s, after);
            assert_memory_equal(before, after, sizeof before);
            ga_get_counter(s, GA_COUNT_STEPS, &steps1);
            ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed1);
            assert_true(steps1 == steps0 && failed1 == failed0 + 1);
            int n = -1;
            assert_int_equal(ga_get_event_count(s, &n), GA_OK);
            assert_int_equal(n, 0);
            /* the retry finds the event */
            assert_int_equal(ga_step(s, h), GA_EVENT);
            double te;
            assert_int_equal(ga_get_event(s, 0, &te, NULL, NULL), GA_OK);
            assert_true(fabs(te - te_ref) < 1e-12);
            ga_free(s);
        }
    }
}

static void a_nonfinite_event_value_is_reported(void **state)
{
    (void)state;
    scene sc = make_scene();
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    assert_int_equal(ga_set_events(s, 1, not_a_number, NULL, NULL, 0), GA_OK);
    double t;
    assert_int_equal(ga_step(s, 0.01), GA_ERR_NONFINITE);
    assert_non_null(strstr(ga_last_error(s), "event function g[0]"));
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_true(t == 0.0);
    ga_free(s);
}

/* A call that stopped at a terminal event leaves the rest of its step to the next call; when
 * that call's step then fails, the rest is searched again by the retry: nothing found twice,
 * nothing lost. */
static void a_failed_step_after_a_stop_loses_nothing(void **state)
{
    (void)state;
    scene sc = make_scene();
    sc.level[0] = 0.3125; /* terminal */
    sc.level[1] = 0.3375; /* logged */
    sc.level[2] = 10.0;
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    const int terminal[3] = {1, 0, 0};
    assert_int_equal(ga_set_events(s, 3, levels, NULL, terminal, 0), GA_OK);
    for (int i = 0; i < 6; ++i)
        assert_int_equal(ga_step(s, 0.05), GA_OK);
    assert_int_equal(ga_step(s, 0.05), GA_EVENT);
    found f = {0};
    collect(s, &f);
    assert_int_equal(f.count, 1);
    assert_int_equal(f.index[0], 0);
    sc.fail_after = 0.36; /* the next step's end fails */
    sc.fail_with = 1;
    double t0, t1;
    assert_int_equal(ga_get_t(s, &t0), GA_OK);
    assert_int_equal(ga_step(s, 0.05), GA_ERR_CALLBACK_RETRY);
    assert_int_equal(ga_get_t(s, &t1), GA_OK);
    assert_true(t0 == t1);
    int n = -1;
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    assert_int_equal(n, 0);
    sc.fail_after = 0.0;
    assert_int_equal(ga_step(s, 0.05), GA_OK);
    collect(s, &f);
    assert_int_equal(f.count, 2);
    assert_int_equal(f.index[1], 1);
    assert_true(fabs(f.t[1] - 0.3375) < 1e-14);
    ga_free(s);
}

/* ga_advance keeps the steps it accepted before a failure, and the events found in them. */
static void advance_keeps_what_it_accepted(void **state)
{
    (void)state;
    scene sc = make_scene();
    const double T4 = quarter_period(&sc.p, M_PI / 2);
    ga_solver *s = released(&sc, M_PI / 2, 0.0, GA_INDEX3);
    assert_int_equal(ga_set_step_limits(s, 0.0, 0.05), GA_OK);
    assert_int_equal(ga_set_events(s, 1, crossing_vertical, NULL, (const int[]){0}, 0), GA_OK);
    assert_int_equal(ga_advance(s, 2.0 * T4), GA_OK);
    int n = 0;
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    assert_int_equal(n, 1);
    sc.fail_at = sc.calls + 3;
    sc.fail_with = -7;
    double t0, t1;
    assert_int_equal(ga_get_t(s, &t0), GA_OK);
    assert_int_equal(ga_advance(s, 4.0 * T4), GA_ERR_CALLBACK);
    assert_int_equal(ga_get_t(s, &t1), GA_OK);
    assert_true(t1 > t0 && t1 < 4.0 * T4);
    sc.fail_at = 0;
    assert_int_equal(ga_advance(s, 4.0 * T4), GA_OK);
    assert_int_equal(ga_get_event_count(s, &n), GA_OK);
    assert_int_equal(n, 1); /* 3T/4, found once */
    double te;
    assert_int_equal(ga_get_event(s, 0, &te, NULL, NULL), GA_OK);
    assert_true(fabs(te - 3.0 * T4) < 1e-3);
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(quarter_period_converges_at_order_two),
        cmocka_unit_test(quarter_period_follows_the_tolerance),
        cmocka_unit_test(slack_rope_converges_at_order_two),
        cmocka_unit_test(multipliers_only_when_asked),
        cmocka_unit_test(reuse_does_not_change_the_events),
        cmocka_unit_test(two_roots_in_one_step),
        cmocka_unit_test(root_at_a_step_end_found_once),
        cmocka_unit_test(a_zero_at_the_start_of_a_step_hides_no_crossing),
        cmocka_unit_test(a_full_log_loses_nothing),
        cmocka_unit_test(chain_events_sparse_and_dense_agree),
        cmocka_unit_test(stopping_at_events_changes_nothing),
        cmocka_unit_test(a_restart_keeps_the_events),
        cmocka_unit_test(bad_arguments_are_refused),
        cmocka_unit_test(a_failed_event_call_changes_nothing),
        cmocka_unit_test(a_nonfinite_event_value_is_reported),
        cmocka_unit_test(advance_keeps_what_it_accepted),
        cmocka_unit_test(a_failed_step_after_a_stop_loses_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
