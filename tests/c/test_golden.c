/* Golden outputs: the solver's results, bit for bit, over a matrix of its capabilities, so that
 * moving code between files and classes is seen to change nothing.
 *
 * Each case runs a shipped scene (the pendulum, the slider-crank and Andrews in 7 angles on the
 * dense path; Andrews in 31 coordinates and the 4-link chain on the sparse path) in fixed or
 * adaptive steps, index 3 or stabilized index 2, with one group of services: events (a
 * terminal one and non-terminal ones, without multipliers and on lambda), the step hook
 * (stopping the run once), forward sensitivities, the adjoint (full record and checkpointed),
 * a checkpoint taken and restored mid-run, first-order states, and all of those that combine
 * together. Its FNV-1a hash covers the bytes of every status returned, the event logs, what
 * the hook saw, the checkpoint's buffer, and at the end t, q, v, qdd, lambda, a, the last h,
 * y and y', the sensitivities, J and dJ/dp, every counter and every info value.
 *
 * No hash is recorded in the repository: the bits of a run are those of one compiler, libm and
 * CPU (glibc picks its FMA or SSE kernels of sin and exp by CPU), and a hash kept from one
 * machine would fail a correct build on another. What the suite asserts holds on any machine:
 * every case run twice in one process hashes the same (no state carried from one solver to the
 * next, no uninitialized read that changes a result), and the hash sees one bit. Comparisons
 * across builds are made on one machine, between two runs of this program:
 *   GALPHA_GOLDEN_RECORD=FILE   writes the 200 hashes to FILE;
 *   GALPHA_GOLDEN_COMPARE=FILE  compares every case with FILE and names those that differ.
 * scripts/golden.sh compares a commit with the working tree that way (the tool for a refactor
 * that must change nothing), and tests/check_blas.sh each installed BLAS/LAPACK with the one
 * selected (galpha's results do not depend on it). The library is built with
 * -ffp-contract=off, so that a moved expression cannot be fused differently on targets with FMA
 * in their baseline. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fnv.h"
#include "scene_catalog.h"

enum { kModes = 4, kMaxParams = 2, kMaxState = 4096 };
static const char *const kModeNames[kModes] = {"fixed index 3", "fixed index 2",
                                               "adaptive index 3", "adaptive index 2"};

typedef enum feature {
    F_PLAIN,
    F_EVENTS,        /* terminal at 0.37 t_end, non-terminal on v_0, no multipliers */
    F_EVENTS_LAMBDA, /* the same and one on lambda_0 */
    F_HOOK,
    F_FORWARD,
    F_ADJOINT,
    F_ADJOINT_CHECKPOINTS,
    F_CHECKPOINT,
    F_FIRST_ORDER,
    F_COMBINED, /* events on lambda, hook, forward sensitivities, first order, checkpoint */
    kFeatures
} feature;
static const char *const kFeatureNames[kFeatures] = {
    "plain",   "events",  "events on lambda",       "step hook",  "forward sensitivities",
    "adjoint", "adjoint with checkpoints", "checkpoint", "first order", "combined"};

/* ---- the hash ---- */
#define HASH(h, x) ((h) = fnv((h), &(x), sizeof(x)))

/* ---- what the callbacks of a run need (one run at a time) ---- */
static struct run_context {
    catalog_scene sc;
    double t_event;    /* the terminal event's time */
    double hook_sum;   /* what the hook saw */
    long hook_calls;
    double dummy_p;    /* a parameter no callback reads: the initial values' sensitivity */
    int np;            /* parameters of the run's sensitivities (the cost writes np of dJ/dp) */
    long events, stops, steps; /* events logged, GA_STOPPED returned, steps at the end */
} g;

/* first-order state: y' = (q_0 - y) / T, and a force k y on coordinate 0 */
static const double kT = 0.05, kForceY = 1e-4; /* (Andrews turns at 0.033 N m) */
static int golden_force_y(double t, const double *q, const double *v, const double *y,
                          double *f, void *user)
{
    const int rc = g.sc.force(t, q, v, f, user);
    f[0] += kForceY * y[0];
    return rc;
}
static int golden_rate(double t, const double *q, const double *v, const double *y,
                       double *ydot, void *user)
{
    (void)t, (void)v, (void)user;
    ydot[0] = (q[0] - y[0]) / kT;
    return 0;
}

static int golden_events(double t, const double *q, const double *v, const double *lambda,
                         double *out, void *user)
{
    (void)q, (void)user;
    out[0] = t - g.t_event;
    out[1] = v[0];
    if (lambda)
        out[2] = lambda[0];
    return 0;
}

static int golden_hook(const ga_solver *s, double t, const double *q, const double *v,
                       const double *lambda, void *user)
{
    (void)s, (void)v, (void)user;
    g.hook_sum += t * q[0] + (lambda ? lambda[0] : 0.0);
    return ++g.hook_calls == 25; /* stops the run once (GA_STOPPED) */
}

/* running cost L = |v|^2 / 2; terminal G = q_0 + lambda_0 / 10 */
static int golden_running(double t, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *value, double *d_q, double *d_v,
                          double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)q, (void)qdd, (void)lambda, (void)user;
    const int n = g.sc.n, m = g.sc.m;
    *value = 0.0;
    for (int i = 0; i < n; ++i) {
        *value += 0.5 * v[i] * v[i];
        d_q[i] = 0.0, d_v[i] = v[i], d_qdd[i] = 0.0;
    }
    for (int i = 0; i < m; ++i)
        d_lambda[i] = 0.0;
    for (int j = 0; j < g.np; ++j)
        d_p[j] = 0.0;
    return 0;
}
static int golden_terminal(double t, const double *q, const double *v, const double *qdd,
                           const double *lambda, double *value, double *d_q, double *d_v,
                           double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)v, (void)qdd, (void)user;
    const int n = g.sc.n, m = g.sc.m;
    *value = q[0] + 0.1 * lambda[0];
    for (int i = 0; i < n; ++i)
        d_q[i] = i == 0 ? 1.0 : 0.0, d_v[i] = 0.0, d_qdd[i] = 0.0;
    for (int i = 0; i < m; ++i)
        d_lambda[i] = i == 0 ? 0.1 : 0.0;
    for (int j = 0; j < g.np; ++j)
        d_p[j] = 0.0;
    return 0;
}

/* ---- one case ---- */
typedef struct run_hash {
    uint64_t hash;
    int steps_ok; /* every call returned what the case expects */
} run_hash;

static uint64_t hash_status(uint64_t h, ga_solver *s, ga_status st)
{
    HASH(h, st);
    int count = 0;
    assert_int_equal(ga_get_event_count(s, &count), GA_OK);
    HASH(h, count);
    g.events += count;
    g.stops += st == GA_STOPPED;
    for (int i = 0; i < count; ++i) {
        double t;
        int index, direction;
        assert_int_equal(ga_get_event(s, i, &t, &index, &direction), GA_OK);
        HASH(h, t);
        HASH(h, index);
        HASH(h, direction);
    }
    return h;
}

/* A stepping call that may stop at an event or at the hook's request: called again until it
 * returns GA_OK (each return hashed). */
static uint64_t drive(uint64_t h, ga_solver *s, int adaptive, double h_fixed, long *k,
                      long k_end, double t_out)
{
    if (!adaptive) {
        for (; *k < k_end; ++*k) {
            const ga_status st = ga_step(s, h_fixed);
            h = hash_status(h, s, st);
            if (st != GA_OK && st != GA_EVENT && st != GA_STOPPED)
                print_error("ga_step %ld: %s\n", *k, ga_last_error(s));
            assert_true(st == GA_OK || st == GA_EVENT || st == GA_STOPPED);
        }
        return h;
    }
    for (int calls = 0;; ++calls) {
        const ga_status st = ga_advance(s, t_out);
        h = hash_status(h, s, st);
        if (st != GA_OK && st != GA_EVENT && st != GA_STOPPED)
            print_error("ga_advance to %g: %s\n", t_out, ga_last_error(s));
        assert_true(st == GA_OK || st == GA_EVENT || st == GA_STOPPED);
        assert_true(calls < 1000);
        if (st == GA_OK)
            return h;
    }
}

static uint64_t golden_run(int scene, int mode, feature f)
{
    memset(&g, 0, sizeof g);
    g.sc = catalog_make(scene);
    catalog_scene *sc = &g.sc;
    const int n = sc->n, m = sc->m;
    const int adaptive = mode >= 2;
    const int formulation = mode % 2 == 0 ? GA_INDEX3 : GA_INDEX2_STABILIZED;
    const int events = f == F_EVENTS || f == F_EVENTS_LAMBDA || f == F_COMBINED;
    const int with_lambda = f == F_EVENTS_LAMBDA || f == F_COMBINED;
    const int hook = f == F_HOOK || f == F_COMBINED;
    const int forward = f == F_FORWARD || f == F_COMBINED;
    const int adjoint = f == F_ADJOINT || f == F_ADJOINT_CHECKPOINTS;
    const int checkpoint = f == F_CHECKPOINT || f == F_COMBINED;
    const int r = f == F_FIRST_ORDER || f == F_COMBINED ? 1 : 0;
    const double t_end = adaptive ? 0.5 * sc->t_end : sc->t_end;
    const long steps = 80;
    const double h_fixed = sc->t_end / (double)steps;
    g.t_event = 0.37 * t_end;

    ga_solver *s = catalog_solver(sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    if (adaptive)
        assert_int_equal(ga_set_tolerances(s, 1e-4, 1e-4), GA_OK);
    if (r)
        assert_int_equal(ga_set_first_order(s, 1, golden_force_y, golden_rate), GA_OK);
    int np = 0;
    if (forward || adjoint) {
        if (scene == 0) { /* the pendulum's length and gravity, by central differences */
            np = 2;
            assert_int_equal(ga_set_sensitivity(s, np, &g_catalog_pendulum.length, NULL,
                                                GA_DEPENDS_FORCE | GA_DEPENDS_CONSTRAINT),
                             GA_OK);
        } else { /* a parameter of the initial velocity only */
            np = 1;
            g.dummy_p = 1.0;
            assert_int_equal(ga_set_sensitivity(s, np, &g.dummy_p, NULL, 0), GA_OK);
            double dv0[kCatalogMaxN] = {0};
            dv0[0] = 1.0;
            assert_int_equal(ga_set_sensitivity_start(s, 0, NULL, dv0), GA_OK);
        }
        g.np = np;
        if (adjoint)
            assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 4000),
                             GA_OK);
        if (f == F_ADJOINT_CHECKPOINTS)
            assert_int_equal(ga_set_adjoint_checkpoints(s, 16, 400), GA_OK);
    }
    if (events) {
        const int direction[3] = {GA_EVENT_RISING, GA_EVENT_BOTH, GA_EVENT_BOTH};
        const int terminal[3] = {1, 0, 0};
        assert_int_equal(ga_set_events(s, with_lambda ? 3 : 2, golden_events, direction,
                                       terminal, with_lambda),
                         GA_OK);
    }
    if (hook)
        assert_int_equal(ga_set_step_hook(s, golden_hook, NULL, 1), GA_OK);

    uint64_t h = 14695981039346656037ull;
    const double y0[1] = {0.0};
    const ga_status st0 = r ? ga_init_y(s, 0.0, sc->q0, sc->v0, y0) : ga_init(s, 0.0, sc->q0, sc->v0);
    if (st0 != GA_OK)
        print_error("init: %s\n", ga_last_error(s));
    assert_int_equal(st0, GA_OK);
    h = hash_status(h, s, st0);

    long k = 0;
    if (checkpoint) {
        /* to the middle, a checkpoint, a detour, back to the checkpoint, on to the end */
        h = drive(h, s, adaptive, h_fixed, &k, steps / 2, 0.5 * t_end);
        size_t len = 0;
        assert_int_equal(ga_state_size(s, &len), GA_OK);
        assert_true(len <= kMaxState);
        static double buf[kMaxState];
        assert_int_equal(ga_get_state(s, buf, len), GA_OK);
        h = fnv(h, buf, sizeof(double) * len);
        long detour = k;
        h = drive(h, s, adaptive, h_fixed, &detour, k + 5, 0.6 * t_end);
        assert_int_equal(ga_set_state(s, buf, len), GA_OK);
    }
    h = drive(h, s, adaptive, h_fixed, &k, steps, t_end);

    double t, h_last, x[kCatalogMaxN];
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_int_equal(ga_get_h_last(s, &h_last), GA_OK);
    HASH(h, t);
    HASH(h, h_last);
    ga_status (*const getters[])(const ga_solver *, double *) = {ga_get_q, ga_get_v, ga_get_qdd,
                                                                 ga_get_a};
    for (size_t i = 0; i < sizeof getters / sizeof getters[0]; ++i) {
        assert_int_equal(getters[i](s, x), GA_OK);
        h = fnv(h, x, sizeof(double) * (size_t)n);
    }
    assert_int_equal(ga_get_lambda(s, x), GA_OK);
    h = fnv(h, x, sizeof(double) * (size_t)m);
    if (r) {
        double y, ydot;
        assert_int_equal(ga_get_y(s, &y, &ydot), GA_OK);
        HASH(h, y);
        HASH(h, ydot);
    }
    if (forward)
        for (int j = 0; j < np; ++j) {
            double dq[kCatalogMaxN], dv[kCatalogMaxN], dqdd[kCatalogMaxN], dl[kCatalogMaxN];
            assert_int_equal(ga_get_sensitivity(s, j, dq, dv, dqdd, dl), GA_OK);
            h = fnv(h, dq, sizeof(double) * (size_t)n);
            h = fnv(h, dv, sizeof(double) * (size_t)n);
            h = fnv(h, dqdd, sizeof(double) * (size_t)n);
            h = fnv(h, dl, sizeof(double) * (size_t)m);
            if (r) {
                double dy, dydot;
                assert_int_equal(ga_get_sensitivity_y(s, j, &dy, &dydot), GA_OK);
                HASH(h, dy);
                HASH(h, dydot);
            }
        }
    if (adjoint) {
        double J = 0.0, dJ[kMaxParams] = {0};
        const ga_status st = ga_adjoint_gradient(s, golden_running, golden_terminal, &J, dJ);
        if (st != GA_OK)
            print_error("adjoint: %s\n", ga_last_error(s));
        assert_int_equal(st, GA_OK);
        HASH(h, J);
        h = fnv(h, dJ, sizeof(double) * (size_t)np);
    }
    if (hook) {
        HASH(h, g.hook_sum);
        HASH(h, g.hook_calls);
    }
    for (int key = 0; key < GA_COUNTER_COUNT; ++key) {
        long long c;
        assert_int_equal(ga_get_counter(s, key, &c), GA_OK);
        HASH(h, c);
        if (key == GA_COUNT_STEPS)
            g.steps = (long)c;
    }
    for (int key = 0; key < GA_INFO_COUNT; ++key) {
        double value = 0.0;
        const ga_status st = ga_get_info(s, key, &value);
        HASH(h, st);
        HASH(h, value);
    }
    ga_free(s);
    return h;
}

typedef struct golden_entry {
    int scene, mode, feature;
    unsigned long long hash;
} golden_entry;

enum { kCases = kCatalogScenes * kModes * kFeatures };

static void each_case(void (*visit)(int sc, int mode, int f, uint64_t hash, void *), void *ctx)
{
    for (int sc = 0; sc < kCatalogScenes; ++sc)
        for (int mode = 0; mode < kModes; ++mode)
            for (int f = 0; f < kFeatures; ++f)
                visit(sc, mode, f, golden_run(sc, mode, (feature)f), ctx);
}

static void write_case(int sc, int mode, int f, uint64_t hash, void *out)
{
    fprintf((FILE *)out,
            "    {%d, %d, %d, 0x%016llxull}, /* %s, %s, %s: %ld steps, %ld events, %ld stops */\n",
            sc, mode, f, (unsigned long long)hash, catalog_make(sc).name, kModeNames[mode],
            kFeatureNames[f], g.steps, g.events, g.stops);
}

typedef struct comparison {
    golden_entry recorded[kCases];
    int count, differ;
} comparison;

static void compare_case(int sc, int mode, int f, uint64_t hash, void *ctx)
{
    comparison *c = ctx;
    for (int i = 0; i < c->count; ++i)
        if (c->recorded[i].scene == sc && c->recorded[i].mode == mode &&
            c->recorded[i].feature == f) {
            if (c->recorded[i].hash != hash) {
                ++c->differ;
                print_error("  differs: %s, %s, %s\n", catalog_make(sc).name, kModeNames[mode],
                            kFeatureNames[f]);
            }
            return;
        }
    ++c->differ;
    print_error("  not recorded: %s, %s, %s\n", catalog_make(sc).name, kModeNames[mode],
                kFeatureNames[f]);
}

static void twice_the_same(int sc, int mode, int f, uint64_t hash, void *differ)
{
    if (golden_run(sc, mode, (feature)f) != hash) {
        ++*(int *)differ;
        print_error("  a second run differs: %s, %s, %s\n", catalog_make(sc).name,
                    kModeNames[mode], kFeatureNames[f]);
    }
}

/* The suite's assertion, or the tool's record or comparison when the environment asks. */
static void every_case(void **state)
{
    (void)state;
    const char *record = getenv("GALPHA_GOLDEN_RECORD");
    const char *compare = getenv("GALPHA_GOLDEN_COMPARE");
    if (record && *record) {
        FILE *out = fopen(record, "w");
        assert_non_null(out);
        each_case(write_case, out);
        assert_int_equal(fclose(out), 0);
        printf("  %d cases recorded in %s\n", kCases, record);
    } else if (compare && *compare) {
        static comparison c;
        FILE *in = fopen(compare, "r");
        if (!in)
            fail_msg("GALPHA_GOLDEN_COMPARE: cannot open %s", compare);
        char line[512];
        while (c.count < kCases && fgets(line, sizeof line, in)) {
            golden_entry *e = &c.recorded[c.count];
            if (sscanf(line, " {%d, %d, %d, 0x%llxull}", &e->scene, &e->mode, &e->feature,
                       &e->hash) == 4)
                ++c.count;
        }
        fclose(in);
        each_case(compare_case, &c);
        printf("  %d cases, %d differ from %s\n", kCases, c.differ, compare);
        assert_int_equal(c.differ, 0);
    } else {
        int differ = 0;
        each_case(twice_the_same, &differ);
        printf("  %d cases, each run twice: %d differ\n", kCases, differ);
        assert_int_equal(differ, 0);
    }
}

/* The hash sees what it should: a change in the last bit of one input changes it. */
static void the_hash_sees_one_bit(void **state)
{
    (void)state;
    const uint64_t before = golden_run(0, 0, F_PLAIN);
    const double length = g_catalog_pendulum.length;
    g_catalog_pendulum.length = nextafter(length, 2.0);
    const uint64_t after = golden_run(0, 0, F_PLAIN);
    g_catalog_pendulum.length = length;
    assert_true(before != after);
    assert_true(golden_run(0, 0, F_PLAIN) == before);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_hash_sees_one_bit),
        cmocka_unit_test(every_case),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
