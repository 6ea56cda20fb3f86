/* A failure injected at every callback call of a step, one call at a time, in every
 * configuration of the step: dense and sparse linear algebra, index-3 and stabilized index-2
 * formulations, exact and finite-difference tangents, fixed and adaptive steps, and a step
 * that starts with the matrix kept from the step before. The hand-picked failures of
 * test_errors.c hit one place each; this sweep reaches the places in between (a failure in the
 * middle of a finite-difference tangent, in the second Newton iteration with a reused matrix,
 * in the velocity constraint of the index-2 system, in the retry after a rejection).
 *
 * For each call k of the step and each kind of failure (callback returning > 0, < 0, or a NaN
 * in its output):
 *   fixed steps: ga_step returns the status of that kind, with a message, and leaves the solver
 *     bit-identical to its last accepted state (q, v, qdd, lambda, a, t); its next step equals
 *     that of an identical solver that never saw the failure, its matrix dropped (and, with
 *     dense linear algebra, that of a new solver restarted from a checkpoint);
 *   adaptive steps: a recoverable failure (> 0, NaN) is absorbed (the attempt is counted as
 *     failed and retried smaller), the step is accepted and satisfies the constraints; a fatal
 *     one (< 0) is returned as in fixed steps, with the same checks.
 * The sweep ends at the first k that the step no longer reaches. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"
#include "scenes/chain.h"

enum { LINKS = 4, N = 3 * LINKS, M = 2 * LINKS, WARMUP = 3, MAX_CALLS = 400 };

typedef enum fault_kind { RETRY, FATAL, NOT_A_NUMBER, KINDS } fault_kind;

/* The chain, with a failure armed at the k-th callback call after arming (k = 0: none). */
typedef struct faulty_chain {
    chain c;
    int calls, k;
    fault_kind kind;
    const char *failed_in; /* the callback that failed */
} faulty_chain;

/* The callbacks a sweep has failed, as a bit set over the names below. */
static const char *const CALLBACK_NAMES[] = {
    "mass", "force", "constraint", "jacobian", "stiffness", "constraint_accel", "constraint_dt"};
enum { CALLBACKS = sizeof CALLBACK_NAMES / sizeof CALLBACK_NAMES[0] };
enum {
    CB_MASS = 1,
    CB_FORCE = 2,
    CB_CONSTRAINT = 4,
    CB_JACOBIAN = 8,
    CB_STIFFNESS = 16,
    CB_CONSTRAINT_ACCEL = 32,
    CB_CONSTRAINT_DT = 64
};

static unsigned callback_bit(const char *name)
{
    for (unsigned i = 0; i < CALLBACKS; ++i)
        if (strcmp(name, CALLBACK_NAMES[i]) == 0)
            return 1u << i;
    return 0;
}

static int fault(faulty_chain *f, const char *name, double *out)
{
    if (f->k == 0 || ++f->calls != f->k)
        return 0;
    f->failed_in = name;
    switch (f->kind) {
    case RETRY:
        return 1;
    case FATAL:
        return -1;
    default:
        out[0] = NAN;
        return 0;
    }
}

static int f_mass(double t, const double *q, double *M_, void *u)
{
    faulty_chain *f = u;
    chain_mass(t, q, M_, &f->c);
    return fault(f, "mass", M_);
}
static int f_force(double t, const double *q, const double *v, double *out, void *u)
{
    faulty_chain *f = u;
    chain_force(t, q, v, out, &f->c);
    return fault(f, "force", out);
}
static int f_constraint(double t, const double *q, double *phi, void *u)
{
    faulty_chain *f = u;
    chain_constraint(t, q, phi, &f->c);
    return fault(f, "constraint", phi);
}
static int f_jacobian(double t, const double *q, double *J, void *u)
{
    faulty_chain *f = u;
    chain_jacobian(t, q, J, &f->c);
    return fault(f, "jacobian", J);
}
static int f_stiffness(double t, const double *q, const double *v, const double *qdd,
                       const double *lambda, double *K, void *u)
{
    faulty_chain *f = u;
    chain_stiffness(t, q, v, qdd, lambda, K, &f->c);
    return fault(f, "stiffness", K);
}
static int f_accel(double t, const double *q, const double *v, double *out, void *u)
{
    faulty_chain *f = u;
    chain_constraint_accel(t, q, v, out, &f->c);
    return fault(f, "constraint_accel", out);
}
static int f_dt(double t, const double *q, double *out, void *u)
{
    faulty_chain *f = u;
    chain_constraint_dt(t, q, out, &f->c);
    return fault(f, "constraint_dt", out);
}

static const double H = 2e-3, RTOL = 1e-4, ATOL = 1e-6, T_STOP = 10.0;

/* exact_tangent: K_t by callback, else finite differences (GA_TANGENT_FD); fresh_matrix:
 * tangents and factorization at every Newton iteration (GA_REUSE_NEVER), else the matrix kept
 * across steps (the swept step starts with the matrix of the step before). */
typedef struct config {
    int linear_solver, formulation, exact_tangent, fresh_matrix, adaptive;
    int sliver; /* the swept step is a sliver of 1e-12 (a Taylor step, see ga_step) */
} config;

/* Callbacks, options and patterns of configuration cf on a new solver (NULL on failure). */
static ga_solver *configured(const config *cf, faulty_chain *f)
{
    ga_solver *s = NULL;
    if (ga_create(N, M, &s) != GA_OK)
        return NULL;
    /* the state as the steps leave it: qdd and lambda of the step, not consistent output */
    if (ga_set_output(s, GA_OUTPUT_STEP) || chain_declare_patterns(&f->c, s) ||
        ga_set_callbacks(s, f_mass, f_force, f_constraint, f_jacobian, f) ||
        ga_set_constraint_accel(s, f_accel) || ga_set_constraint_dt(s, f_dt) ||
        ga_set_linear_solver(s, cf->linear_solver) || ga_set_formulation(s, cf->formulation) ||
        ga_set_tolerances(s, RTOL, ATOL) ||
        (cf->exact_tangent ? ga_set_tangents(s, f_stiffness, NULL)
                           : ga_set_tangent_mode(s, GA_TANGENT_FD)) ||
        (cf->fresh_matrix && ga_set_jacobian_reuse(s, GA_REUSE_NEVER))) {
        ga_free(s);
        return NULL;
    }
    return s;
}

static ga_status take_step(ga_solver *s, const config *cf)
{
    return cf->adaptive ? ga_step_adaptive(s, T_STOP) : ga_step(s, H);
}

/* A solver of configuration cf after ga_init and WARMUP steps, or NULL. */
static ga_solver *warmed_up(const config *cf, faulty_chain *f)
{
    double q[N], v[N];
    ga_solver *s = configured(cf, f);
    if (!s)
        return NULL;
    chain_initial(&f->c, q, v);
    int st = ga_init(s, 0.0, q, v);
    for (int i = 0; i < WARMUP && !st; ++i)
        st = take_step(s, cf);
    if (st) {
        ga_free(s);
        return NULL;
    }
    return s;
}

/* What the caller can read of the state. */
typedef struct readout {
    double t, h_last, q[N], v[N], qdd[N], lambda[M], a[N];
} readout;

static readout read_state(const ga_solver *s)
{
    readout r;
    memset(&r, 0, sizeof r);
    assert_int_equal(ga_get_t(s, &r.t), GA_OK);
    assert_int_equal(ga_get_h_last(s, &r.h_last), GA_OK);
    assert_int_equal(ga_get_q(s, r.q), GA_OK);
    assert_int_equal(ga_get_v(s, r.v), GA_OK);
    assert_int_equal(ga_get_qdd(s, r.qdd), GA_OK);
    assert_int_equal(ga_get_lambda(s, r.lambda), GA_OK);
    assert_int_equal(ga_get_a(s, r.a), GA_OK);
    return r;
}

static void expect_same_state(const readout *x, const readout *y, const char *what, int k)
{
    if (memcmp(x, y, sizeof *x) != 0)
        fail_msg("%s: states differ (fault at call %d): by %g in q, %g in v, %g in qdd, %g in "
                 "lambda",
                 what, k, max_abs_diff(x->q, y->q, N), max_abs_diff(x->v, y->v, N),
                 max_abs_diff(x->qdd, y->qdd, N), max_abs_diff(x->lambda, y->lambda, M));
}

/* A solver of configuration cf restarted from a checkpoint `buf` (a new solver, no history). */
static ga_solver *restarted(const config *cf, faulty_chain *f, const double *buf, size_t len)
{
    ga_solver *s = configured(cf, f);
    assert_non_null(s);
    assert_int_equal(ga_set_state(s, buf, len), GA_OK);
    return s;
}

/* The failed step left no trace: the next step of s equals that of an identical solver that
 * never saw the failure, its kept matrix dropped (setting the reuse mode again does that; a
 * failure does too). With dense linear algebra it also equals the next step of a new solver
 * restarted from a checkpoint of that state (as a restart: layout 2, without the matrix a
 * layout-3 checkpoint would rebuild). On the sparse path a restart also makes the LU choose
 * new pivots, which the failed solver keeps: there the two agree to round-off
 * (test_checkpoint.c restores sparse runs bit-identically). */
static void leaves_no_trace(ga_solver *s, const config *cf, faulty_chain *f)
{
    faulty_chain quiet = *f;
    quiet.k = 0;
    ga_solver *twin = warmed_up(cf, &quiet), *fresh = NULL;
    assert_non_null(twin);
    if (cf->linear_solver != GA_LINEAR_SPARSE) {
        size_t len = 0;
        assert_int_equal(ga_state_size(twin, &len), GA_OK);
        double *buf = malloc(2 * len * sizeof *buf);
        assert_non_null(buf);
        assert_int_equal(ga_get_state(twin, buf, len), GA_OK);
        fresh = restarted(cf, &quiet, buf + len, ckpt_as_layout2(buf, buf + len));
        free(buf);
    }
    assert_int_equal(ga_set_jacobian_reuse(twin, cf->fresh_matrix ? GA_REUSE_NEVER
                                                                  : GA_REUSE_AUTO),
                     GA_OK);

    const int k = f->calls;
    f->k = 0;
    assert_int_equal(take_step(s, cf), GA_OK);
    assert_int_equal(take_step(twin, cf), GA_OK);
    const readout x = read_state(s), y = read_state(twin);
    expect_same_state(&x, &y, "the step after the failure and that of a solver without it", k);
    if (fresh) {
        assert_int_equal(take_step(fresh, cf), GA_OK);
        const readout z = read_state(fresh);
        expect_same_state(&x, &z, "the step after the failure and the step after a restart", k);
        ga_free(fresh);
    }
    ga_free(twin);
}

/* max |Phi(q)| of the solver's state */
static double constraint_residual(const ga_solver *s, const chain *c)
{
    double q[N], phi[M];
    assert_int_equal(ga_get_q(s, q), GA_OK);
    chain_constraint(0.0, q, phi, (void *)c);
    double worst = 0.0;
    for (int i = 0; i < M; ++i)
        worst = fmax(worst, fabs(phi[i]));
    return worst;
}

static ga_status expected_status(fault_kind kind)
{
    return kind == RETRY   ? GA_ERR_CALLBACK_RETRY
           : kind == FATAL ? GA_ERR_CALLBACK
                           : GA_ERR_NONFINITE;
}

/* One sweep: the failure of `kind` at call k = 1, 2, ... of the step after the warm-up.
 * Returns the number of calls the step makes. */
static int sweep(const config *cf, fault_kind kind, unsigned *failed)
{
    for (int k = 1; k <= MAX_CALLS; ++k) {
        faulty_chain f;
        memset(&f, 0, sizeof f);
        f.c = chain_make(LINKS);
        ga_solver *s = warmed_up(cf, &f);
        assert_non_null(s);
        const readout before = read_state(s);
        long long failed_before = 0, failed_after = 0;
        assert_int_equal(ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed_before), GA_OK);
        f.kind = kind;
        f.k = k;
        f.calls = 0;
        const ga_status st = cf->sliver ? ga_step(s, 1e-12) : take_step(s, cf);
        if (f.calls < k) { /* the step made fewer calls: the sweep is complete */
            assert_int_equal(st, GA_OK);
            ga_free(s);
            return k - 1;
        }
        assert_int_equal(ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed_after), GA_OK);
        *failed |= callback_bit(f.failed_in);
        if (cf->adaptive && kind != FATAL) {
            if (st != GA_OK)
                fail_msg("adaptive step: a recoverable failure in %s (call %d) was not "
                         "absorbed: %s (%s)",
                         f.failed_in, k, ga_strerror(st), ga_last_error(s));
            assert_true(failed_after > failed_before);
            double t = 0.0;
            assert_int_equal(ga_get_t(s, &t), GA_OK);
            assert_true(t > before.t);
            if (constraint_residual(s, &f.c) > 1e-10)
                fail_msg("adaptive step after a failure in %s (call %d): |Phi| = %g",
                         f.failed_in, k, constraint_residual(s, &f.c));
        } else {
            if (st != expected_status(kind))
                fail_msg("failure in %s at call %d: expected '%s', got '%s' (%s)",
                         f.failed_in, k, ga_strerror(expected_status(kind)), ga_strerror(st),
                         ga_last_error(s));
            assert_true(strlen(ga_last_error(s)) > 0);
            assert_true(failed_after > failed_before);
            const readout after = read_state(s);
            expect_same_state(&before, &after, f.failed_in, k);
            leaves_no_trace(s, cf, &f);
        }
        ga_free(s);
    }
    fail_msg("the step makes more than %d callback calls", MAX_CALLS);
    return MAX_CALLS;
}

static void sweep_all_kinds(const config *cf, unsigned must_fail)
{
    int calls[KINDS];
    unsigned failed = 0;
    for (int kind = 0; kind < KINDS; ++kind)
        calls[kind] = sweep(cf, (fault_kind)kind, &failed);
    /* every kind saw the same step (the faults do not change what a clean step calls) */
    assert_int_equal(calls[RETRY], calls[FATAL]);
    assert_int_equal(calls[RETRY], calls[NOT_A_NUMBER]);
    assert_true(calls[RETRY] >= 4); /* at least force, constraint, Jacobian, mass */
    print_message("    %d calls in the step, each failed in three ways:", calls[RETRY]);
    for (unsigned i = 0; i < CALLBACKS; ++i)
        if (failed & (1u << i))
            print_message(" %s", CALLBACK_NAMES[i]);
    print_message("\n");
    if ((failed & must_fail) != must_fail)
        fail_msg("the sweep did not reach every callback it should (missing mask %#x)",
                 must_fail & ~failed);
}

/* The same for ga_init: a failure at any of its calls returns the status of its kind, leaves
 * the solver uninitialized (a step is refused) and usable: ga_init again, without the fault,
 * gives exactly the state of a solver that never failed. */
static void sweep_init(const config *cf)
{
    double q[N], v[N];
    unsigned failed = 0;
    int calls = -1;
    for (int kind = 0; kind < KINDS; ++kind)
        for (int k = 1; k <= MAX_CALLS; ++k) {
            faulty_chain f;
            memset(&f, 0, sizeof f);
            f.c = chain_make(LINKS);
            chain_initial(&f.c, q, v);
            ga_solver *s = configured(cf, &f);
            assert_non_null(s);
            f.kind = (fault_kind)kind;
            f.k = k;
            const ga_status st = ga_init(s, 0.0, q, v);
            if (f.calls < k) {
                assert_int_equal(st, GA_OK);
                assert_true(calls < 0 || calls == k - 1);
                calls = k - 1;
                ga_free(s);
                break;
            }
            failed |= callback_bit(f.failed_in);
            if (st != expected_status(f.kind))
                fail_msg("ga_init, failure in %s at call %d: expected '%s', got '%s' (%s)",
                         f.failed_in, k, ga_strerror(expected_status(f.kind)),
                         ga_strerror(st), ga_last_error(s));
            assert_true(strlen(ga_last_error(s)) > 0);
            assert_int_equal(ga_step(s, H), GA_ERR_STATE);

            f.k = 0;
            faulty_chain quiet = f;
            ga_solver *ref = configured(cf, &quiet);
            assert_non_null(ref);
            assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
            assert_int_equal(ga_init(ref, 0.0, q, v), GA_OK);
            size_t len = 0;
            assert_int_equal(ga_state_size(s, &len), GA_OK);
            double *x = malloc(2 * len * sizeof *x);
            assert_non_null(x);
            assert_int_equal(ga_get_state(s, x, len), GA_OK);
            assert_int_equal(ga_get_state(ref, x + len, len), GA_OK);
            if (memcmp(x, x + len, len * sizeof *x) != 0)
                fail_msg("ga_init after a failure in %s (call %d) differs from a first one",
                         f.failed_in, k);
            free(x);
            ga_free(ref);
            ga_free(s);
        }
    assert_true(calls >= 4);
    assert_true((failed & (CB_MASS | CB_FORCE | CB_CONSTRAINT | CB_JACOBIAN |
                           CB_CONSTRAINT_ACCEL)) ==
                (CB_MASS | CB_FORCE | CB_CONSTRAINT | CB_JACOBIAN | CB_CONSTRAINT_ACCEL));
    print_message("    ga_init: %d calls, each failed in three ways\n", calls);
}

#define INIT_SWEEP_TEST(name, solver, formulation)                                              \
    static void name(void **state)                                                             \
    {                                                                                          \
        (void)state;                                                                           \
        const config cf = {solver, formulation, 1, 0, 0, 0};                                   \
        sweep_init(&cf);                                                                       \
    }
INIT_SWEEP_TEST(init_sparse_index3, GA_LINEAR_SPARSE, GA_INDEX3)
INIT_SWEEP_TEST(init_sparse_index2, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED)
INIT_SWEEP_TEST(init_dense_index3, GA_LINEAR_DENSE, GA_INDEX3)
INIT_SWEEP_TEST(init_dense_index2, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED)

#define SWEEP_TEST(name, solver, formulation, exact, fresh, adaptive, must_fail)               \
    static void name(void **state)                                                             \
    {                                                                                          \
        (void)state;                                                                           \
        const config cf = {solver, formulation, exact, fresh, adaptive, 0};                    \
        sweep_all_kinds(&cf, must_fail);                                                       \
    }

SWEEP_TEST(sparse_index3_exact_kept_fixed, GA_LINEAR_SPARSE, GA_INDEX3, 1, 0, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)
SWEEP_TEST(sparse_index3_exact_fresh_fixed, GA_LINEAR_SPARSE, GA_INDEX3, 1, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_STIFFNESS)
SWEEP_TEST(sparse_index3_fd_fresh_fixed, GA_LINEAR_SPARSE, GA_INDEX3, 0, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)
SWEEP_TEST(sparse_index2_exact_kept_fixed, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED, 1, 0, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_CONSTRAINT_DT)
SWEEP_TEST(sparse_index2_exact_fresh_fixed, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED, 1, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_STIFFNESS|CB_CONSTRAINT_DT)
SWEEP_TEST(sparse_index2_fd_fresh_fixed, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED, 0, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_CONSTRAINT_DT)
SWEEP_TEST(dense_index3_exact_kept_fixed, GA_LINEAR_DENSE, GA_INDEX3, 1, 0, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)
SWEEP_TEST(dense_index3_exact_fresh_fixed, GA_LINEAR_DENSE, GA_INDEX3, 1, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_STIFFNESS)
SWEEP_TEST(dense_index3_fd_fresh_fixed, GA_LINEAR_DENSE, GA_INDEX3, 0, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)
SWEEP_TEST(dense_index2_exact_kept_fixed, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED, 1, 0, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_CONSTRAINT_DT)
SWEEP_TEST(dense_index2_exact_fresh_fixed, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED, 1, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_STIFFNESS|CB_CONSTRAINT_DT)
SWEEP_TEST(dense_index2_fd_fresh_fixed, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED, 0, 1, 0,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_CONSTRAINT_DT)
SWEEP_TEST(sparse_index3_exact_kept_adaptive, GA_LINEAR_SPARSE, GA_INDEX3, 1, 0, 1,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)
SWEEP_TEST(sparse_index2_fd_fresh_adaptive, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED, 0, 1, 1,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_CONSTRAINT_DT)
SWEEP_TEST(dense_index2_exact_fresh_adaptive, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED, 1, 1, 1,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN|CB_STIFFNESS|CB_CONSTRAINT_DT)
SWEEP_TEST(dense_index3_fd_fresh_adaptive, GA_LINEAR_DENSE, GA_INDEX3, 0, 1, 1,
           CB_MASS|CB_FORCE|CB_CONSTRAINT|CB_JACOBIAN)

/* A sliver: its Taylor step projects the velocities (Jacobian, Phi_t) and computes
 * consistent accelerations (mass, forces, Jacobian, constraint acceleration term). */
#define SLIVER_SWEEP_TEST(name, solver, formulation)                                            \
    static void name(void **state)                                                             \
    {                                                                                          \
        (void)state;                                                                           \
        const config cf = {solver, formulation, 1, 0, 0, 1};                                   \
        sweep_all_kinds(&cf, CB_MASS | CB_FORCE | CB_JACOBIAN | CB_CONSTRAINT_ACCEL |          \
                                 CB_CONSTRAINT_DT);                                            \
    }
SLIVER_SWEEP_TEST(sparse_index3_sliver, GA_LINEAR_SPARSE, GA_INDEX3)
SLIVER_SWEEP_TEST(dense_index2_sliver, GA_LINEAR_DENSE, GA_INDEX2_STABILIZED)

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sparse_index3_sliver),
        cmocka_unit_test(dense_index2_sliver),
        cmocka_unit_test(init_sparse_index3),
        cmocka_unit_test(init_sparse_index2),
        cmocka_unit_test(init_dense_index3),
        cmocka_unit_test(init_dense_index2),
        cmocka_unit_test(sparse_index3_exact_kept_fixed),
        cmocka_unit_test(sparse_index3_exact_fresh_fixed),
        cmocka_unit_test(sparse_index3_fd_fresh_fixed),
        cmocka_unit_test(sparse_index2_exact_kept_fixed),
        cmocka_unit_test(sparse_index2_exact_fresh_fixed),
        cmocka_unit_test(sparse_index2_fd_fresh_fixed),
        cmocka_unit_test(dense_index3_exact_kept_fixed),
        cmocka_unit_test(dense_index3_exact_fresh_fixed),
        cmocka_unit_test(dense_index3_fd_fresh_fixed),
        cmocka_unit_test(dense_index2_exact_kept_fixed),
        cmocka_unit_test(dense_index2_exact_fresh_fixed),
        cmocka_unit_test(dense_index2_fd_fresh_fixed),
        cmocka_unit_test(sparse_index3_exact_kept_adaptive),
        cmocka_unit_test(sparse_index2_fd_fresh_adaptive),
        cmocka_unit_test(dense_index2_exact_fresh_adaptive),
        cmocka_unit_test(dense_index3_fd_fresh_adaptive),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
