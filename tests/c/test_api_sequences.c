/* Random sequences of C API calls, as a careless or hurried host program makes them: options
 * set before and after ga_init, out-of-range and non-finite arguments, steps of every size,
 * checkpoints restored with a corrupted entry or the wrong length, and callbacks that fail at a
 * random call (returning > 0 or < 0, writing a NaN, an Inf or 1e300 into their output, or
 * calling ga_step on their own solver). test_errors.c pins each failure's status and message;
 * test_fault_sweep.c sweeps failures over the calls of one step; this suite checks what must hold
 * whatever the order of calls (and runs under ASan, UBSan and valgrind with the others):
 *   - every call returns GA_OK or one of the ga_status codes;
 *   - every failed call that may change the solver leaves a message (ga_last_error);
 *   - a failed ga_step or ga_step_adaptive leaves t, q, v, qdd, a and lambda bit-identical;
 *   - a callback's call of ga_step on its own solver is refused with GA_ERR_STATE.
 * Models: a double pendulum in Cartesian coordinates (4 coordinates, 2 constraints), the same
 * with its first constraint stated twice (3, one redundant), and two free particles (none);
 * a third of the runs declare sparsity patterns and take the sparse path, and pattern
 * declarations (valid ones, and invalid ones that must be refused) come at random too.
 * ga_advance is left out: it runs as many steps as its interval needs, which at the step
 * limits and tolerances drawn here can be millions (its checks are those of
 * ga_step_adaptive, which it repeats). */
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

enum { N = 4, SEQUENCES = 20000, MAX_OPS = 64, STATE_MAX = 1 + 4 * N + 3 };

typedef enum fault_kind { NONE, RETURN_RETRY, RETURN_FATAL, WRITE_NAN, WRITE_INF, WRITE_HUGE,
                          REENTER, FAULT_KINDS } fault_kind;
enum { MASS, FORCE, CONSTRAINT, JACOBIAN, STIFFNESS, ACCEL, DT, CALLBACKS };

typedef struct model {
    uint64_t rng;
    int m;                 /* 2, 3 (redundant) or 0 */
    fault_kind fault;      /* armed failure */
    int fault_callback;    /* which callback fails */
    long calls, fault_at;  /* it fails from its fault_at-th call on */
    ga_solver *s;
    int reentry_allowed;   /* a callback's ga_step on its own solver returned other than STATE */
    int sparse_M, sparse_J, sparse_K; /* patterns declared: the callbacks write values only */
} model;

static uint64_t next(model *md)
{
    md->rng ^= md->rng << 13;
    md->rng ^= md->rng >> 7;
    md->rng ^= md->rng << 17;
    return md->rng;
}
static int pick(model *md, int k) { return (int)(next(md) % (uint64_t)k); }
static double uniform(model *md) { return (double)(next(md) >> 11) * 0x1.0p-53; }

static int misbehave(model *md, int callback, double *out, int len)
{
    if (md->fault == NONE || md->fault_callback != callback || ++md->calls < md->fault_at)
        return 0;
    switch (md->fault) {
    case RETURN_RETRY: return 1;
    case RETURN_FATAL: return -1;
    case WRITE_NAN: out[pick(md, len)] = NAN; return 0;
    case WRITE_INF: out[pick(md, len)] = -INFINITY; return 0;
    case WRITE_HUGE: out[pick(md, len)] = 1e300; return 0;
    case REENTER:
        if (ga_step(md->s, 1e-3) != GA_ERR_STATE)
            md->reentry_allowed = 1;
        return 0;
    default: return 0;
    }
}

static int mass(double t, const double *q, double *M, void *user)
{
    model *md = user;
    (void)t, (void)q;
    if (md->sparse_M) {  /* the diagonal */
        for (int i = 0; i < N; ++i)
            M[i] = 1.0;
        return misbehave(md, MASS, M, N);
    }
    memset(M, 0, sizeof(double) * N * N);
    for (int i = 0; i < N; ++i)
        M[i + i * N] = 1.0;
    return misbehave(md, MASS, M, N * N);
}
static int force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t, (void)q, (void)v;
    for (int i = 0; i < N; ++i)
        f[i] = i % 2 ? -9.81 : 0.0;
    return misbehave(user, FORCE, f, N);
}
static int constraint(double t, const double *q, double *phi, void *user)
{
    model *md = user;
    (void)t;
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - 1.0);
    phi[1] = 0.5 * ((q[2] - q[0]) * (q[2] - q[0]) + (q[3] - q[1]) * (q[3] - q[1]) - 1.0);
    if (md->m == 3)
        phi[2] = phi[0];
    return misbehave(md, CONSTRAINT, phi, md->m);
}
static int jacobian(double t, const double *q, double *J, void *user)
{
    model *md = user;
    const int m = md->m;
    (void)t;
    if (md->sparse_J) {  /* in the order of J_ROWS, J_COLS */
        const double values[] = {q[0], q[1], q[0] - q[2], q[1] - q[3], q[2] - q[0], q[3] - q[1],
                                 q[0], q[1]};
        const int nnz = m == 3 ? 8 : 6;
        memcpy(J, values, sizeof(double) * (size_t)nnz);
        return misbehave(md, JACOBIAN, J, nnz);
    }
    memset(J, 0, sizeof(double) * (size_t)(m * N));
    J[0] = q[0], J[m] = q[1];
    J[1] = q[0] - q[2], J[1 + m] = q[1] - q[3], J[1 + 2 * m] = q[2] - q[0],
    J[1 + 3 * m] = q[3] - q[1];
    if (m == 3)
        J[2] = q[0], J[2 + m] = q[1];
    return misbehave(md, JACOBIAN, J, m * N);
}
/* K_t = d(Phi_q^T lambda)/dq (M constant, f constant) */
static int stiffness(double t, const double *q, const double *v, const double *qdd,
                     const double *lambda, double *K, void *user)
{
    model *md = user;
    (void)t, (void)q, (void)v, (void)qdd;
    if (md->sparse_K) {  /* in the order of K_ROWS, K_COLS */
        const double l0 = md->m ? lambda[0] + (md->m == 3 ? lambda[2] : 0.0) : 0.0,
                     l1 = md->m ? lambda[1] : 0.0;
        const double values[] = {l0 + l1, l0 + l1, l1, l1, -l1, -l1, -l1, -l1};
        memcpy(K, values, sizeof values);
        return misbehave(md, STIFFNESS, K, 8);
    }
    memset(K, 0, sizeof(double) * N * N);
    if (md->m > 0) {
        const double l0 = lambda[0] + (md->m == 3 ? lambda[2] : 0.0), l1 = lambda[1];
        K[0] = K[1 + N] = l0 + l1;
        K[2 + 2 * N] = K[3 + 3 * N] = l1;
        K[2 * N] = K[2] = K[1 + 3 * N] = K[3 + N] = -l1;
    }
    return misbehave(md, STIFFNESS, K, N * N);
}
static int accel(double t, const double *q, const double *v, double *out, void *user)
{
    model *md = user;
    (void)t, (void)q;
    out[0] = v[0] * v[0] + v[1] * v[1];
    out[1] = (v[2] - v[0]) * (v[2] - v[0]) + (v[3] - v[1]) * (v[3] - v[1]);
    if (md->m == 3)
        out[2] = out[0];
    return misbehave(md, ACCEL, out, md->m);
}
static int time_derivative(double t, const double *q, double *phi_t, void *user)
{
    model *md = user;
    (void)t, (void)q;
    for (int i = 0; i < md->m; ++i)
        phi_t[i] = 0.0;
    return misbehave(md, DT, phi_t, md->m);
}

/* The patterns the callbacks above write when declared; and ones ga_set_pattern must refuse. */
static const int M_DIAG[] = {0, 1, 2, 3}, M_COLPTR[] = {0, 1, 2, 3, 4};
static const int J_ROWS[] = {0, 0, 1, 1, 1, 1, 2, 2}, J_COLS[] = {0, 1, 0, 1, 2, 3, 0, 1};
static const int K_ROWS[] = {0, 1, 2, 3, 0, 2, 1, 3}, K_COLS[] = {0, 1, 2, 3, 2, 0, 3, 1};

static ga_status declare_pattern(model *md, ga_solver *s, int *must_fail)
{
    static const int bad_rows[] = {0, 5, -1, 2}, bad_cols[] = {0, 1, 2, 4};
    const int k = pick(md, 9);
    *must_fail = k >= 5;
    switch (k) {
    case 0: {
        const ga_status st = ga_set_pattern(s, GA_MATRIX_MASS, N, M_DIAG, M_DIAG);
        md->sparse_M |= st == GA_OK;
        return st;
    }
    case 1: {
        const ga_status st = ga_set_pattern_csc(s, GA_MATRIX_MASS, M_COLPTR, M_DIAG);
        md->sparse_M |= st == GA_OK;
        return st;
    }
    case 2: {
        const ga_status st =
            ga_set_pattern(s, GA_MATRIX_JACOBIAN, md->m == 3 ? 8 : 6, J_ROWS, J_COLS);
        md->sparse_J |= st == GA_OK;
        return st;
    }
    case 3: {
        const ga_status st = ga_set_pattern(s, GA_MATRIX_STIFFNESS, 8, K_ROWS, K_COLS);
        md->sparse_K |= st == GA_OK;
        return st;
    }
    case 4: return ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL);
    /* each of these must be refused: an index out of range, NULL arrays with entries, an
     * unknown matrix, a negative count, a decreasing colptr */
    case 5: return ga_set_pattern(s, pick(md, 4), 4, bad_rows, bad_cols);
    case 6: return ga_set_pattern(s, pick(md, 4), 3, NULL, M_DIAG);
    case 7: return ga_set_pattern(s, 4 + pick(md, 3), 4, M_DIAG, M_DIAG);
    default: {
        static const int decreasing[] = {0, 2, 1, 3, 4};
        return pick(md, 2) ? ga_set_pattern(s, GA_MATRIX_MASS, -1, M_DIAG, M_DIAG)
                           : ga_set_pattern_csc(s, GA_MATRIX_MASS, decreasing, M_DIAG);
    }
    }
}

static double edge_value(model *md)
{
    static const double values[] = {0.0, -1.0, 1.0, 0.5, 1e-3, 1e-12, 1e300, -1e300, 1e-320,
                                    2.0, 0.9, 0.7, 1e-6, 1e-10, 10.0};
    const int k = pick(md, 18);
    return k < 15 ? values[k] : k == 15 ? NAN : k == 16 ? INFINITY : uniform(md);
}
static double step_size(model *md)
{
    static const double values[] = {1e-3, 1e-2, 1e-4, 0.1, 1.0, 1e-8, 1e-15, 0.0, -1e-3, 1e3,
                                    5e-3, NAN, INFINITY};
    return values[pick(md, 13)];
}

/* t, q, v, qdd, a, lambda; 0 before ga_init */
static int snapshot(ga_solver *s, int m, double *x)
{
    if (ga_get_t(s, x) != GA_OK)
        return 0;
    assert_int_equal(ga_get_q(s, x + 1), GA_OK);
    assert_int_equal(ga_get_v(s, x + 1 + N), GA_OK);
    assert_int_equal(ga_get_qdd(s, x + 1 + 2 * N), GA_OK);
    assert_int_equal(ga_get_a(s, x + 1 + 3 * N), GA_OK);
    assert_int_equal(ga_get_lambda(s, m ? x + 1 + 4 * N : NULL), GA_OK);
    return 1 + 4 * N + m;
}

static void check(ga_solver *s, ga_status st, int changes_solver, const char *call, int seq)
{
    if (st > GA_OK || st < GA_ERR_STEP_SIZE)
        fail_msg("sequence %d: %s returned %d, not a ga_status", seq, call, st);
    if (st != GA_OK && changes_solver && ga_last_error(s)[0] == '\0')
        fail_msg("sequence %d: %s failed (%s) without a message", seq, call, ga_strerror(st));
}

/* A failed step must leave the state as it was. */
static void check_transaction(ga_solver *s, int m, ga_status st, const double *before, int len,
                              const char *call, int seq)
{
    double after[STATE_MAX];
    if (st == GA_OK || len == 0)
        return;
    assert_int_equal(snapshot(s, m, after), len);
    if (memcmp(before, after, sizeof(double) * (size_t)len) != 0)
        fail_msg("sequence %d: %s failed (%s: %s) but changed the state", seq, call,
                 ga_strerror(st), ga_last_error(s));
}

static void run_sequence(int seq, long long *calls, long long *steps_ok, long long *sparse_ok)
{
    model md = {0};
    md.rng = 0x9E3779B97F4A7C15ull * (uint64_t)(seq + 1);
    for (int k = 0; k < 4; ++k)
        next(&md);
    const int kinds[] = {2, 3, 0};
    md.m = kinds[pick(&md, 3)];
    ga_solver *s = NULL;
    assert_int_equal(ga_create(N, md.m, &s), GA_OK);
    md.s = s;
    /* snapshots read the state: the step's qdd and lambda, no callbacks */
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    assert_int_equal(ga_set_callbacks(s, mass, force, constraint, jacobian, &md), GA_OK);
    if (pick(&md, 3) == 0) {  /* a third of the runs on the sparse path */
        md.sparse_M = 1;
        assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, N, M_DIAG, M_DIAG), GA_OK);
        if (md.m > 0) {
            md.sparse_J = 1;
            assert_int_equal(
                ga_set_pattern(s, GA_MATRIX_JACOBIAN, md.m == 3 ? 8 : 6, J_ROWS, J_COLS), GA_OK);
        }
        if (pick(&md, 2)) {
            md.sparse_K = 1;
            assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, 8, K_ROWS, K_COLS), GA_OK);
        }
        assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    }
    const int ops = 5 + pick(&md, MAX_OPS - 5);
    for (int op = 0; op < ops; ++op) {
        if (pick(&md, 6) == 0) {  /* arm a failure (or disarm: NONE) */
            md.fault = (fault_kind)pick(&md, FAULT_KINDS);
            md.fault_callback = pick(&md, CALLBACKS);
            md.calls = 0;
            md.fault_at = 1 + pick(&md, 30);
        }
        double before[STATE_MAX];
        ga_status st = GA_OK;
        int changes = 1;
        const char *call = "";
        switch (pick(&md, 36)) {
        case 0: call = "ga_set_rho_inf"; st = ga_set_rho_inf(s, edge_value(&md)); break;
        case 1: {
            const double am = edge_value(&md), af = edge_value(&md), b = edge_value(&md);
            call = "ga_set_params";
            st = ga_set_params(s, am, af, b, edge_value(&md));
            break;
        }
        case 2: call = "ga_set_newton"; st = ga_set_newton(s, edge_value(&md), pick(&md, 30) - 2); break;
        case 3: call = "ga_set_tangents"; st = ga_set_tangents(s, pick(&md, 2) ? stiffness : NULL, NULL); break;
        case 4: call = "ga_set_tangent_mode"; st = ga_set_tangent_mode(s, pick(&md, 5) - 1); break;
        case 5: call = "ga_set_scaling"; st = ga_set_scaling(s, pick(&md, 3)); break;
        case 6: call = "ga_set_jacobian_reuse"; st = ga_set_jacobian_reuse(s, pick(&md, 3)); break;
        case 7: call = "ga_set_constant_mass"; st = ga_set_constant_mass(s, pick(&md, 3)); break;
        case 8: call = "ga_set_predictor"; st = ga_set_predictor(s, pick(&md, 4)); break;
        case 9: call = "ga_set_linear_solver"; st = ga_set_linear_solver(s, pick(&md, 7) - 1); break;
        case 10: call = "ga_set_formulation"; st = ga_set_formulation(s, pick(&md, 3)); break;
        case 11: call = "ga_set_redundant_constraints"; st = ga_set_redundant_constraints(s, pick(&md, 3)); break;
        case 12: call = "ga_set_rescale"; st = ga_set_rescale(s, pick(&md, 3)); break;
        case 13: call = "ga_set_corrected_start"; st = ga_set_corrected_start(s, pick(&md, 3)); break;
        case 14: {
            const double rtol = edge_value(&md);
            call = "ga_set_tolerances";
            st = ga_set_tolerances(s, rtol, edge_value(&md));
            break;
        }
        case 15: {
            const double h_min = pick(&md, 2) ? 0.0 : edge_value(&md);
            call = "ga_set_step_limits";
            st = ga_set_step_limits(s, h_min, edge_value(&md));
            break;
        }
        case 16: call = "ga_set_initial_step"; st = ga_set_initial_step(s, edge_value(&md)); break;
        case 17: call = "ga_set_constraint_accel"; st = ga_set_constraint_accel(s, pick(&md, 2) ? accel : NULL); break;
        case 18: call = "ga_set_constraint_dt"; st = ga_set_constraint_dt(s, pick(&md, 2) ? time_derivative : NULL); break;
        case 19: {
            const int mode = pick(&md, 3);
            call = "ga_set_init_mode";
            st = ga_set_init_mode(s, mode, edge_value(&md));
            break;
        }
        case 20: case 21: case 34: case 35: {
            const double angle = 0.3 + uniform(&md);
            double q0[N] = {sin(angle), -cos(angle), sin(angle) + 1.0, -cos(angle)}, v0[N] = {0};
            if (pick(&md, 4) == 0)
                q0[pick(&md, N)] += edge_value(&md);
            if (pick(&md, 4) == 0)
                v0[pick(&md, N)] += edge_value(&md);
            const double t0 = pick(&md, 5) == 0 ? edge_value(&md) : 0.0;
            call = "ga_init";
            st = ga_init(s, t0, q0, v0);
            break;
        }
        case 22: case 23: case 24: case 25: {
            const int len = snapshot(s, md.m, before);
            call = "ga_step";
            st = ga_step(s, step_size(&md));
            check_transaction(s, md.m, st, before, len, call, seq);
            *steps_ok += st == GA_OK;
            *sparse_ok += st == GA_OK && strstr(ga_linear_solver_name(s), "sparse") != NULL;
            break;
        }
        case 26: {
            double t = 0.0;
            const int len = snapshot(s, md.m, before);
            ga_get_t(s, &t);
            const double t_stop = pick(&md, 4) ? t + step_size(&md) : edge_value(&md);
            call = "ga_step_adaptive";
            st = ga_step_adaptive(s, t_stop);
            check_transaction(s, md.m, st, before, len, call, seq);
            *steps_ok += st == GA_OK;
            *sparse_ok += st == GA_OK && strstr(ga_linear_solver_name(s), "sparse") != NULL;
            break;
        }
        case 27: {
            double t = 0.0, q[N], v[N], lambda[3];
            ga_get_t(s, &t);
            call = "ga_interpolate";
            changes = 0;
            st = ga_interpolate(s, t - 1e-4 * uniform(&md), q, v, md.m ? lambda : NULL);
            break;
        }
        case 28: {
            size_t len = 0;
            double buf[512];
            assert_int_equal(ga_state_size(s, &len), GA_OK);
            assert_true(len <= 512);
            call = "ga_get_state";
            changes = 0;
            st = ga_get_state(s, buf, len);
            if (st == GA_OK) {
                check(s, st, changes, call, seq);
                if (pick(&md, 3) == 0)
                    buf[pick(&md, (int)len)] = edge_value(&md);
                call = "ga_set_state";
                changes = 1;
                st = ga_set_state(s, buf, len - (size_t)(pick(&md, 5) == 0));
            }
            break;
        }
        case 29: {
            long long value;
            call = "ga_get_counter";
            changes = 0;
            st = ga_get_counter(s, pick(&md, 16) - 1, &value);
            if (pick(&md, 3) == 0) {
                check(s, st, changes, call, seq);
                call = "ga_reset_counters";
                changes = 1;
                st = ga_reset_counters(s);
            }
            break;
        }
        case 31: case 32: {
            int must_fail = 0;
            call = "ga_set_pattern";
            st = declare_pattern(&md, s, &must_fail);
            if (must_fail && st == GA_OK)
                fail_msg("sequence %d: an invalid pattern was accepted", seq);
            break;
        }
        case 30: {
            double value;
            call = "ga_get_info";
            changes = 0;
            st = ga_get_info(s, pick(&md, 7) - 1, &value);
            break;
        }
        default: {
            int active[3];
            call = "ga_get_active_constraints";
            changes = 0;
            st = ga_get_active_constraints(s, active);
            break;
        }
        }
        check(s, st, changes, call, seq);
        ++*calls;
    }
    if (md.reentry_allowed)
        fail_msg("sequence %d: a callback's ga_step on its own solver was not refused", seq);
    ga_free(s);
}

static void random_call_sequences_keep_the_contract(void **state)
{
    (void)state;
    long long calls = 0, steps_ok = 0, sparse_ok = 0;
    for (int seq = 0; seq < SEQUENCES; ++seq)
        run_sequence(seq, &calls, &steps_ok, &sparse_ok);
    printf("  %d sequences, %lld calls, %lld accepted steps (%lld on the sparse path)\n",
           SEQUENCES, calls, steps_ok, sparse_ok);
    /* the sequences must reach the stepping code, dense and sparse, not only the checks of
     * arguments and of the call order */
    assert_true(steps_ok > SEQUENCES / 2);
    assert_true(sparse_ok > SEQUENCES / 100);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(random_call_sequences_keep_the_contract),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
