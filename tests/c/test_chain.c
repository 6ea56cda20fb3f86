/* The sparse path on the N-link chain: the sparse (KLU) and dense solvers give the same steps,
 * in the index-3 and in the stabilized index-2 formulation, grouped finite differences
 * reproduce the exact tangent at a few evaluations per matrix, and the energy of the chain is
 * kept to the order of the integration error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "chain_solver.h"

typedef struct chain_run {
    double *q, *lambda;
    double energy_drift;
    double velocity_constraint; /* max over the steps of |Phi_q v|_inf */
    double rcond;               /* GA_INFO_RCOND after the last step */
    long long stiffness_evals, jacobian_evals, factorizations, steps;
    char backend[64];
} chain_run;

static double energy(const chain *c, const double *q, const double *v)
{
    double e = 0.0;
    for (int i = 0; i < c->links; ++i)
        e += 0.5 * c->mass * (v[3 * i] * v[3 * i] + v[3 * i + 1] * v[3 * i + 1]) +
             0.5 * c->inertia * v[3 * i + 2] * v[3 * i + 2] + c->mass * c->gravity * q[3 * i + 1];
    return e;
}

/* max |Phi_q(q) v|_inf, from the chain's Jacobian values in the order of its pattern */
static double velocity_constraint(const chain *c, const double *q, const double *v)
{
    const int nnz = chain_pattern(c, GA_MATRIX_JACOBIAN, NULL, NULL);
    int *rows = malloc(sizeof(int) * nnz), *cols = malloc(sizeof(int) * nnz);
    double *J = malloc(sizeof(double) * nnz), *Jv = calloc(2 * c->links, sizeof(double));
    chain_pattern(c, GA_MATRIX_JACOBIAN, rows, cols);
    chain_jacobian(0.0, q, J, (void *)c);
    for (int k = 0; k < nnz; ++k)
        Jv[rows[k]] += J[k] * v[cols[k]];
    double worst = 0.0;
    for (int i = 0; i < 2 * c->links; ++i)
        worst = fmax(worst, fabs(Jv[i]));
    free(rows);
    free(cols);
    free(J);
    free(Jv);
    return worst;
}

static chain_run run_formulation(int links, int solver, int formulation, int exact_tangent,
                                 double h, int steps)
{
    chain c = chain_make(links);
    const int n = 3 * links, m = 2 * links;
    chain_run r;
    double *q = malloc(sizeof(double) * n), *v = malloc(sizeof(double) * n);
    memset(&r, 0, sizeof r);
    r.q = malloc(sizeof(double) * n);
    r.lambda = malloc(sizeof(double) * m);
    chain_initial(&c, q, v);
    ga_solver *s = chain_solver(&c, exact_tangent);
    assert_int_equal(ga_set_constraint_accel(s, chain_constraint_accel), GA_OK);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, solver), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-10, 20), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    snprintf(r.backend, sizeof r.backend, "%s", ga_linear_solver_name(s));
    const double e0 = energy(&c, q, v);
    for (int k = 0; k < steps; ++k) {
        const ga_status st = ga_step(s, h);
        if (st)
            fail_msg("step %d: %s", k, ga_last_error(s));
        ga_get_q(s, q);
        ga_get_v(s, v);
        r.energy_drift = fmax(r.energy_drift, fabs(energy(&c, q, v) - e0));
        r.velocity_constraint = fmax(r.velocity_constraint, velocity_constraint(&c, q, v));
    }
    ga_get_q(s, r.q);
    ga_get_lambda(s, r.lambda);
    ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &r.stiffness_evals);
    ga_get_counter(s, GA_COUNT_JACOBIAN_EVALS, &r.jacobian_evals);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &r.factorizations);
    ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
    assert_int_equal(ga_get_info(s, GA_INFO_RCOND, &r.rcond), GA_OK);
    ga_free(s);
    free(q);
    free(v);
    return r;
}

static chain_run run(int links, int solver, int exact_tangent, double h, int steps)
{
    return run_formulation(links, solver, GA_INDEX3, exact_tangent, h, steps);
}

static void release(chain_run *r)
{
    free(r->q);
    free(r->lambda);
}

static void sparse_and_dense_solvers_agree(void **state)
{
    (void)state;
    const int links = 12;
    chain_run sp = run(links, GA_LINEAR_SPARSE, 1, 2e-3, 100);
    chain_run de = run(links, GA_LINEAR_DENSE_EIGEN, 1, 2e-3, 100);
    chain_run la = run(links, GA_LINEAR_DENSE_LAPACK, 1, 2e-3, 100);
    chain_run un = run(links, GA_LINEAR_DENSE, 1, 2e-3, 100);
    assert_string_equal(sp.backend, "sparse KLU");
    /* 60 unknowns, under 10 % of S nonzero: GA_LINEAR_DENSE takes the unblocked kernel */
    assert_string_equal(un.backend, "dense unblocked LU");
    assert_string_equal(de.backend, "dense Eigen LU");
    assert_string_equal(la.backend, "dense LAPACK LU");
    const double dq = max_abs_diff(sp.q, de.q, 3 * links);
    const double dl = max_abs_diff(sp.lambda, de.lambda, 2 * links);
    printf("  KLU vs Eigen LU: |dq| = %.1e, |dlambda| = %.1e; LAPACK vs Eigen |dq| = %.1e; "
           "unblocked vs Eigen |dq| = %.1e\n",
           dq, dl, max_abs_diff(la.q, de.q, 3 * links), max_abs_diff(un.q, de.q, 3 * links));
    assert_true(dq < 1e-9);
    assert_true(dl < 1e-6);
    assert_true(max_abs_diff(la.q, de.q, 3 * links) < 1e-9);
    assert_true(max_abs_diff(un.q, de.q, 3 * links) < 1e-9);
    assert_true(max_abs_diff(un.lambda, de.lambda, 2 * links) < 1e-6);
    /* GA_INFO_RCOND: 1-norm estimates of the same matrix from every backend (KLU's of its
     * rows as equilibrated for the factorization, LAPACK's dgecon for the dense factors) */
    printf("  rcond: KLU %.2e, Eigen %.2e, LAPACK %.2e, unblocked %.2e\n", sp.rcond, de.rcond,
           la.rcond, un.rcond);
    assert_true(la.rcond == de.rcond || fabs(la.rcond / de.rcond - 1.0) < 1e-6);
    assert_true(fabs(un.rcond / de.rcond - 1.0) < 1e-6);
    assert_true(sp.rcond > 0.1 * de.rcond && sp.rcond < 10.0 * de.rcond);
    release(&sp);
    release(&de);
    release(&la);
    release(&un);
}

/* The sparse index-2 system (the Newmark increment as extra unknowns, index2_matrix.hpp) and
 * the dense one solve the same equations: the same steps to round-off; both keep the velocity
 * constraint Phi_q v = 0 at every step, which the index-3 formulation does not. */
static void sparse_and_dense_index2_agree(void **state)
{
    (void)state;
    const int links = 12;
    chain_run sp = run_formulation(links, GA_LINEAR_SPARSE, GA_INDEX2_STABILIZED, 1, 2e-3, 100);
    chain_run de =
        run_formulation(links, GA_LINEAR_DENSE_EIGEN, GA_INDEX2_STABILIZED, 1, 2e-3, 100);
    chain_run i3 = run(links, GA_LINEAR_SPARSE, 1, 2e-3, 100);
    assert_string_equal(sp.backend, "sparse KLU (stabilized index-2)");
    assert_string_equal(de.backend, "dense Eigen LU (stabilized index-2)");
    const double dq = max_abs_diff(sp.q, de.q, 3 * links);
    const double dl = max_abs_diff(sp.lambda, de.lambda, 2 * links);
    printf("  index 2, KLU vs Eigen LU: |dq| = %.1e, |dlambda| = %.1e; max |Phi_q v|: %.1e "
           "(sparse), %.1e (dense), %.1e (index 3)\n",
           dq, dl, sp.velocity_constraint, de.velocity_constraint, i3.velocity_constraint);
    assert_true(dq < 1e-9);
    assert_true(dl < 1e-6);
    assert_true(sp.velocity_constraint < 1e-9);
    assert_true(de.velocity_constraint < 1e-9);
    assert_true(i3.velocity_constraint > 1e3 * sp.velocity_constraint);
    /* the index-2 systems report 1-norm condition estimates too */
    printf("  index 2: rcond %.2e (sparse), %.2e (dense)\n", sp.rcond, de.rcond);
    assert_true(de.rcond > 0.0 && de.rcond <= 1.0);
    assert_true(sp.rcond > 0.1 * de.rcond && sp.rcond < 10.0 * de.rcond);
    release(&sp);
    release(&de);
    release(&i3);
}

/* Chosen after the sparse workspace exists, the index-2 system is set up sparse too; and a
 * large chain runs adaptively in it. */
static void index2_on_a_sparse_solver_set_up_already(void **state)
{
    (void)state;
    chain c = chain_make(2000);
    const int n = 3 * c.links;
    double *q = malloc(sizeof(double) * n), *v = malloc(sizeof(double) * n);
    chain_initial(&c, q, v);
    ga_solver *s = chain_solver(&c, 1);
    assert_int_equal(ga_set_constraint_accel(s, chain_constraint_accel), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_string_equal(ga_linear_solver_name(s), "sparse KLU");
    assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
    assert_string_equal(ga_linear_solver_name(s), "sparse KLU (stabilized index-2)");
    assert_int_equal(ga_set_tolerances(s, 1e-4, 1e-4), GA_OK);
    assert_int_equal(ga_advance(s, 0.2), GA_OK);
    ga_get_q(s, q);
    ga_get_v(s, v);
    long long steps;
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    double vmax = 0.0;
    for (int i = 0; i < n; ++i)
        vmax = fmax(vmax, fabs(v[i]));
    printf("  2000-link chain, adaptive index 2 to t = 0.2: %lld steps, |Phi_q v| = %.1e, "
           "|v| = %.2f\n",
           steps, velocity_constraint(&c, q, v), vmax);
    /* to the Newton tolerance of adaptive steps, 1e-2 rtol, relative to the velocities */
    assert_true(velocity_constraint(&c, q, v) < 1e-6 * vmax);
    ga_free(s);
    free(q);
    free(v);
}

static void grouped_finite_differences_match_exact_tangent(void **state)
{
    (void)state;
    const int links = 40;
    chain_run ex = run(links, GA_LINEAR_SPARSE, 1, 2e-3, 50);
    chain_run fd = run(links, GA_LINEAR_SPARSE, 0, 2e-3, 50);
    printf("  exact vs grouped FD tangent: |dq| = %.1e; FD: %lld Jacobian evaluations for %lld "
           "stiffness matrices of a %d-link chain\n",
           max_abs_diff(ex.q, fd.q, 3 * links), fd.jacobian_evals, fd.stiffness_evals, links);
    assert_true(max_abs_diff(ex.q, fd.q, 3 * links) < 1e-9);
    /* the stiffness pattern is diagonal: one group, so one extra Jacobian per K_t instead of
     * 3N = 120 */
    assert_true(fd.jacobian_evals - ex.jacobian_evals <= fd.stiffness_evals);
    release(&ex);
    release(&fd);
}

static void auto_choice_is_sparse_for_large_chains(void **state)
{
    (void)state;
    chain_run big = run(200, GA_LINEAR_AUTO, 1, 1e-3, 5);
    chain_run small = run(1, GA_LINEAR_AUTO, 1, 1e-3, 5); /* 5 unknowns: dense */
    assert_string_equal(big.backend, "sparse KLU");
    assert_string_equal(small.backend, "dense unblocked LU");
    release(&big);
    release(&small);
}

static void energy_is_kept_to_integration_error(void **state)
{
    (void)state;
    double hs[3], de[3];
    for (int k = 0; k < 3; ++k) {
        hs[k] = 4e-3 / (1 << k);
        chain_run r = run(8, GA_LINEAR_SPARSE, 1, hs[k], (int)lround(0.4 / hs[k]));
        de[k] = r.energy_drift;
        release(&r);
    }
    const double o = fit_order(hs, de, 3);
    printf("  8-link chain, max energy drift over 0.4 s: %.2e, %.2e, %.2e (order %.2f)\n", de[0],
           de[1], de[2], o);
    assert_true(o > 1.7);
}

/* An inconsistent start projected on the sparse path (the projection's saddle-point matrix
 * [I Phi_q^T; Phi_q 0] assembled in the sparse layout) as on the dense one: the same
 * consistent q0 and v0, on the constraints to round-off. */
static void inconsistent_start_projected_sparse_as_dense(void **state)
{
    (void)state;
    enum { LINKS = 20, N = 3 * LINKS, M = 2 * LINKS };
    chain c = chain_make(LINKS);
    double q0[N], v0[N], q[2][N], v[2][N], phi[M];
    chain_initial(&c, q0, v0);
    for (int i = 0; i < N; ++i) { /* off the constraints in positions and velocities */
        q0[i] += 1e-3 * sin(1.7 * i);
        v0[i] += 1e-2 * cos(0.9 * i);
    }
    const int solvers[2] = {GA_LINEAR_SPARSE, GA_LINEAR_DENSE_EIGEN};
    for (int k = 0; k < 2; ++k) {
        ga_solver *s = chain_solver(&c, 1);
        assert_int_equal(ga_set_linear_solver(s, solvers[k]), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
        ga_get_q(s, q[k]);
        ga_get_v(s, v[k]);
        ga_free(s);
        chain_constraint(0.0, q[k], phi, &c);
        double worst = 0.0;
        for (int i = 0; i < M; ++i)
            worst = fmax(worst, fabs(phi[i]));
        assert_true(worst < 1e-12);
        assert_true(velocity_constraint(&c, q[k], v[k]) < 1e-12);
    }
    printf("  projected start, sparse vs dense: |dq0| = %.1e, |dv0| = %.1e (moved by %.1e)\n",
           max_abs_diff(q[0], q[1], N), max_abs_diff(v[0], v[1], N), max_abs_diff(q[0], q0, N));
    assert_true(max_abs_diff(q[0], q0, N) > 1e-4); /* the projection did move q0 */
    assert_true(max_abs_diff(q[0], q[1], N) < 1e-13);
    assert_true(max_abs_diff(v[0], v[1], N) < 1e-12);
}

#if defined(__SSE2__)
#include <xmmintrin.h>
/* galpha flushes subnormal numbers to zero inside KLU's kernels (the factors of long chains
 * decay through them): the caller's floating-point mode (the control bits of MXCSR: rounding,
 * exception masks, flush-to-zero, denormals-are-zero; not the exception flags, which any
 * arithmetic raises) must be back on return, and the callbacks, which run outside those
 * kernels, must see the caller's mode. Checked from the default mode and from one with
 * flush-to-zero on, index 3 and 2, on the sparse path. */
enum { CONTROL_BITS = 0xFFC0 };
static unsigned seen_csr[64];
static int seen_count;
static int recording_force(double t, const double *q, const double *v, double *f, void *u)
{
    if (seen_count < 64)
        seen_csr[seen_count++] = _mm_getcsr() & CONTROL_BITS;
    return chain_force(t, q, v, f, u);
}

/* A singular iteration matrix in the middle of a sparse run (Phi_q = 0 from the callback, for
 * one step): GA_ERR_SINGULAR, the state bit-identical, and once Phi_q is back the next step
 * equals that of a new solver restored from a checkpoint of the same state (both choose new
 * pivots), index 3 and 2. */
static int jacobian_vanishes; /* the test's switch for the callback below */
static int vanishing_jacobian(double t, const double *q, double *J, void *user)
{
    const int st = chain_jacobian(t, q, J, user);
    if (jacobian_vanishes)
        memset(J, 0, sizeof(double) * (size_t)chain_pattern(user, GA_MATRIX_JACOBIAN, NULL, NULL));
    return st;
}

static void singular_matrix_mid_run_sparse(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        chain c = chain_make(20);
        double q[60], v[60];
        chain_initial(&c, q, v);
        ga_solver *s = sparse_chain_solver(&c, chain_force, vanishing_jacobian, formulation),
                  *r = sparse_chain_solver(&c, chain_force, vanishing_jacobian, formulation);
        jacobian_vanishes = 0;
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        for (int i = 0; i < 5; ++i)
            assert_int_equal(ga_step(s, 1e-3), GA_OK);
        double before[2048], after[2048], restart[2048];
        size_t len = 0;
        assert_int_equal(ga_state_size(s, &len), GA_OK);
        assert_true(len <= 2048);
        assert_int_equal(ga_get_state(s, before, len), GA_OK);
        jacobian_vanishes = 1;
        assert_int_equal(ga_step(s, 1e-3), GA_ERR_SINGULAR);
        assert_non_null(strstr(ga_last_error(s), "is singular"));
        jacobian_vanishes = 0;
        assert_int_equal(ga_get_state(s, after, len), GA_OK);
        assert_true(ckpt_same_state(before, after));
        /* the failed step dropped its matrix and pivots: it goes on as a restart */
        assert_int_equal(ga_set_state(r, restart, ckpt_as_layout2(before, restart)), GA_OK);
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
        assert_int_equal(ga_step(r, 1e-3), GA_OK);
        assert_int_equal(ga_get_state(s, after, len), GA_OK);
        assert_int_equal(ga_get_state(r, before, len), GA_OK);
        assert_true(ckpt_same_state(before, after));
        ga_free(s);
        ga_free(r);
    }
}

static void callers_floating_point_mode_is_kept(void **state)
{
    (void)state;
    const unsigned original = _mm_getcsr(), flush_to_zero = 0x8000;
    _mm_setcsr(original | flush_to_zero);
    const int honoured = (_mm_getcsr() & flush_to_zero) != 0;
    _mm_setcsr(original);
    if (!honoured) {  /* valgrind, for one, emulates no flush-to-zero mode */
        printf("  the MXCSR register ignores writes here: nothing to check\n");
        skip();
    }
    chain c = chain_make(50);
    double q[150], v[150];
    for (int mode = 0; mode < 2; ++mode)
        for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
            const unsigned caller = mode ? original | flush_to_zero : original & ~flush_to_zero;
            _mm_setcsr(caller);
            chain_initial(&c, q, v);
            ga_solver *s = sparse_chain_solver(&c, recording_force, chain_jacobian, formulation);
            seen_count = 0;
            assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
            for (int k = 0; k < 5; ++k)
                assert_int_equal(ga_step(s, 1e-3), GA_OK);
            const unsigned after = _mm_getcsr() & CONTROL_BITS;
            ga_free(s);
            _mm_setcsr(original);
            assert_true(after == (caller & CONTROL_BITS));
            assert_true(seen_count >= 5);
            for (int k = 0; k < seen_count; ++k)
                assert_true(seen_csr[k] == (caller & CONTROL_BITS));
        }
}
#endif

/* ga_set_pattern_csc: the chain's patterns declared in compressed-column form (the Jacobian's
 * values then come column by column) run bit for bit as the same entries declared as triplets
 * in that order; and the solution is the chain's with its own (row-wise) triplets, up to the
 * order of the sums in Phi_q^T lambda. */
typedef struct csc_chain {
    chain c; /* first: the scene's callbacks take the user pointer as a chain */
    int *perm; /* CSC position k holds the value at triplet position perm[k] */
    double *scratch;
} csc_chain;

static int csc_jacobian(double t, const double *q, double *J, void *user)
{
    csc_chain *x = user;
    const int rc = chain_jacobian(t, q, x->scratch, &x->c);
    const int nnz = chain_pattern(&x->c, GA_MATRIX_JACOBIAN, NULL, NULL);
    for (int k = 0; k < nnz; ++k)
        J[k] = x->scratch[x->perm[k]];
    return rc;
}

static void run_csc_chain(int how, double *q, double *lambda) /* 0 triplets, 1 CSC, 2 own */
{
    enum { L = 40, N = 3 * L, M = 2 * L };
    csc_chain x = {chain_make(L), NULL, NULL};
    const int nnz = chain_pattern(&x.c, GA_MATRIX_JACOBIAN, NULL, NULL);
    int *rows = malloc(sizeof(int) * nnz), *cols = malloc(sizeof(int) * nnz);
    int *rowind = malloc(sizeof(int) * nnz), *colsort = malloc(sizeof(int) * nnz);
    int colptr[N + 1] = {0}, next[N];
    x.perm = malloc(sizeof(int) * nnz);
    x.scratch = malloc(sizeof(double) * nnz);
    chain_pattern(&x.c, GA_MATRIX_JACOBIAN, rows, cols);
    for (int k = 0; k < nnz; ++k) /* counting sort by column, stable */
        ++colptr[cols[k] + 1];
    for (int j = 0; j < N; ++j) {
        colptr[j + 1] += colptr[j];
        next[j] = colptr[j];
    }
    for (int k = 0; k < nnz; ++k) {
        const int p = next[cols[k]]++;
        x.perm[p] = k;
        rowind[p] = rows[k];
        colsort[p] = cols[k];
    }
    int diag_ptr[N + 1], diag_row[N], th_ptr[N + 1], th_row[L], empty[N + 1];
    for (int j = 0; j <= N; ++j) {
        diag_ptr[j] = j;
        empty[j] = 0;
        th_ptr[j] = j / 3; /* column 3i + 2 (the angle of link i) holds row 3i + 2 */
    }
    for (int i = 0; i < N; ++i)
        diag_row[i] = i;
    for (int i = 0; i < L; ++i)
        th_row[i] = 3 * i + 2;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(N, M, &s), GA_OK);
    if (how == 1) {
        assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_MASS, diag_ptr, diag_row), GA_OK);
        assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_JACOBIAN, colptr, rowind), GA_OK);
        assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_STIFFNESS, th_ptr, th_row), GA_OK);
        assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_DAMPING, empty, NULL), GA_OK);
    } else {
        assert_int_equal(chain_declare_patterns(&x.c, s), GA_OK);
        if (how == 0)
            assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, nnz, rowind, colsort), GA_OK);
    }
    assert_int_equal(ga_set_callbacks(s, chain_mass, chain_force, chain_constraint,
                                      how == 2 ? chain_jacobian : csc_jacobian, &x),
                     GA_OK);
    assert_int_equal(ga_set_tangents(s, chain_stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    double q0[N], v0[N];
    chain_initial(&x.c, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    for (int k = 0; k < 30; ++k)
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
    assert_int_equal(ga_get_q(s, q), GA_OK);
    assert_int_equal(ga_get_lambda(s, lambda), GA_OK);
    ga_free(s);
    free(rows);
    free(cols);
    free(rowind);
    free(colsort);
    free(x.perm);
    free(x.scratch);
}

static void csc_patterns_run_as_their_triplets(void **state)
{
    (void)state;
    enum { L = 40, N = 3 * L, M = 2 * L };
    double q[3][N], lambda[3][M];
    for (int how = 0; how < 3; ++how)
        run_csc_chain(how, q[how], lambda[how]);
    assert_memory_equal(q[0], q[1], sizeof q[0]);
    assert_memory_equal(lambda[0], lambda[1], sizeof lambda[0]);
    double lmax = 0.0;
    for (int i = 0; i < M; ++i)
        lmax = fmax(lmax, fabs(lambda[2][i]));
    printf("  CSC declaration = its triplets bit for bit; against the row-wise triplets: |dq| "
           "%.1e, |dlambda| %.1e of %.1e\n",
           max_abs_diff(q[1], q[2], N), max_abs_diff(lambda[1], lambda[2], M), lmax);
    assert_true(max_abs_diff(q[1], q[2], N) < 1e-12);
    assert_true(max_abs_diff(lambda[1], lambda[2], M) < 1e-6 * lmax);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
#if defined(__SSE2__)
        cmocka_unit_test(callers_floating_point_mode_is_kept),
#endif
        cmocka_unit_test(sparse_and_dense_solvers_agree),
        cmocka_unit_test(csc_patterns_run_as_their_triplets),
        cmocka_unit_test(singular_matrix_mid_run_sparse),
        cmocka_unit_test(sparse_and_dense_index2_agree),
        cmocka_unit_test(index2_on_a_sparse_solver_set_up_already),
        cmocka_unit_test(grouped_finite_differences_match_exact_tangent),
        cmocka_unit_test(auto_choice_is_sparse_for_large_chains),
        cmocka_unit_test(energy_is_kept_to_integration_error),
        cmocka_unit_test(inconsistent_start_projected_sparse_as_dense),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
