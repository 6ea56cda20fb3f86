/* The sparse path on a mesh: a square membrane of particles joined to their four neighbours by
 * springs, its edge pinned (one constraint per pinned coordinate), set swinging. Its pattern is
 * a 2-D grid, on which the band of reverse Cuthill-McKee fills solid and KLU keeps its AMD
 * ordering (the chain takes the band): the sparse solver must give the dense solvers' steps, in
 * the index-3 and in the stabilized index-2 formulation. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
/* cmocka.h after the headers it needs */
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"

enum { SIDE = 18 }; /* nodes per side */
enum { NODES = SIDE * SIDE, N = 2 * NODES, EDGE = 4 * SIDE - 4, M = 2 * EDGE };
static const double kSpring = 400.0, kMass = 0.01;

static int on_edge(int i, int j)
{
    return i == 0 || j == 0 || i == SIDE - 1 || j == SIDE - 1;
}

/* Pattern of K: per coordinate its diagonal and its neighbours in the same direction. The
 * callbacks fill values in this order. */
static int stiffness_pattern(int *rows, int *cols)
{
    int k = 0;
    for (int j = 0; j < SIDE; ++j)
        for (int i = 0; i < SIDE; ++i)
            for (int d = 0; d < 2; ++d) {
                const int p = 2 * (j * SIDE + i) + d;
                const int nb[4][2] = {{i - 1, j}, {i + 1, j}, {i, j - 1}, {i, j + 1}};
                rows[k] = cols[k] = p;
                ++k;
                for (int e = 0; e < 4; ++e)
                    if (nb[e][0] >= 0 && nb[e][0] < SIDE && nb[e][1] >= 0 && nb[e][1] < SIDE) {
                        rows[k] = p;
                        cols[k] = 2 * (nb[e][1] * SIDE + nb[e][0]) + d;
                        ++k;
                    }
            }
    return k;
}

static int stiffness_values(double *K)
{
    int k = 0;
    for (int j = 0; j < SIDE; ++j)
        for (int i = 0; i < SIDE; ++i)
            for (int d = 0; d < 2; ++d) {
                int neighbours = (i > 0) + (i < SIDE - 1) + (j > 0) + (j < SIDE - 1);
                K[k++] = kSpring * neighbours;
                for (int e = 0; e < neighbours; ++e)
                    K[k++] = -kSpring;
            }
    return k;
}

static int mass(double t, const double *q, double *Mv, void *u)
{
    (void)t, (void)q, (void)u;
    for (int p = 0; p < N; ++p)
        Mv[p] = kMass;
    return 0;
}

/* f = -K q, with K from the pattern */
static int *K_rows, *K_cols, K_nnz;
static double *K_vals;
static int force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    memset(f, 0, sizeof(double) * N);
    for (int k = 0; k < K_nnz; ++k)
        f[K_rows[k]] -= K_vals[k] * q[K_cols[k]];
    return 0;
}

/* K_t = d r^q / dq = K (r^q = M qdd - f + Phi_q^T lambda) */
static int stiffness(double t, const double *q, const double *v, const double *qdd,
                     const double *lambda, double *K, void *u)
{
    (void)t, (void)q, (void)v, (void)qdd, (void)lambda, (void)u;
    stiffness_values(K);
    return 0;
}

/* the edge pinned: Phi = q of every edge coordinate, in node order */
static int constraint(double t, const double *q, double *phi, void *u)
{
    (void)t, (void)u;
    int c = 0;
    for (int j = 0; j < SIDE; ++j)
        for (int i = 0; i < SIDE; ++i)
            if (on_edge(i, j))
                for (int d = 0; d < 2; ++d)
                    phi[c++] = q[2 * (j * SIDE + i) + d];
    return 0;
}

static int jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    for (int c = 0; c < M; ++c)
        J[c] = 1.0;
    return 0;
}

static int constraint_dt(double t, const double *q, double *out, void *u)
{
    (void)t, (void)q, (void)u;
    memset(out, 0, sizeof(double) * M);
    return 0;
}

static int jacobian_pattern(int *rows, int *cols)
{
    int c = 0;
    for (int j = 0; j < SIDE; ++j)
        for (int i = 0; i < SIDE; ++i)
            if (on_edge(i, j))
                for (int d = 0; d < 2; ++d) {
                    rows[c] = c;
                    cols[c] = 2 * (j * SIDE + i) + d;
                    ++c;
                }
    return c;
}

typedef struct membrane_run {
    double q[N], lambda[M];
    long long newton, steps;
    char backend[64];
} membrane_run;

/* 40 steps of 2 ms (the fastest mode of the springs turns 1.1 rad per step, the slowest 0.1) from
 * rest, the interior moving as sin(pi x) sin(pi y) in both directions. */
static void run(int solver, int formulation, membrane_run *r)
{
    int diag_rows[N], diag_cols[N], J_rows[M], J_cols[M];
    for (int p = 0; p < N; ++p)
        diag_rows[p] = diag_cols[p] = p;
    assert_int_equal(jacobian_pattern(J_rows, J_cols), M);
    ga_solver *s = NULL;
    assert_int_equal(ga_create(N, M, &s), GA_OK);
    /* the same callbacks for both solvers: the dense ones scatter the declared entries */
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, N, diag_rows, diag_cols), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, M, J_rows, J_cols), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, K_nnz, K_rows, K_cols), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_callbacks(s, mass, force, constraint, jacobian, NULL), GA_OK);
    assert_int_equal(ga_set_tangents(s, stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, solver), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 10), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_constraint_dt(s, constraint_dt), GA_OK);
    static double q[N], v[N];
    const double pi = acos(-1.0);
    for (int j = 0; j < SIDE; ++j)
        for (int i = 0; i < SIDE; ++i) {
            const double shape = sin(pi * i / (SIDE - 1)) * sin(pi * j / (SIDE - 1));
            q[2 * (j * SIDE + i)] = q[2 * (j * SIDE + i) + 1] = 0.0;
            v[2 * (j * SIDE + i)] = 0.3 * shape;
            v[2 * (j * SIDE + i) + 1] = shape;
        }
    if (ga_init(s, 0.0, q, v))
        fail_msg("ga_init: %s", ga_last_error(s));
    snprintf(r->backend, sizeof r->backend, "%s", ga_linear_solver_name(s));
    for (int k = 0; k < 40; ++k)
        if (ga_step(s, 2e-3))
            fail_msg("step %d: %s", k, ga_last_error(s));
    ga_get_q(s, r->q);
    ga_get_lambda(s, r->lambda);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &r->newton);
    ga_get_counter(s, GA_COUNT_STEPS, &r->steps);
    ga_free(s);
}

static double max_abs(const double *a, int len)
{
    double m = 0.0;
    for (int k = 0; k < len; ++k)
        m = fmax(m, fabs(a[k]));
    return m;
}

/* In both formulations; the stabilized index-2 system of the mesh is the reduced one (its
 * products of Phi_q with itself are diagonal here). */
static void sparse_and_dense_solvers_agree_on_a_mesh(void **state)
{
    (void)state;
    static membrane_run sp, de;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        const int index2 = formulation == GA_INDEX2_STABILIZED;
        run(GA_LINEAR_SPARSE, formulation, &sp);
        run(GA_LINEAR_DENSE_EIGEN, formulation, &de);
        assert_string_equal(sp.backend,
                            index2 ? "sparse KLU (stabilized index-2)" : "sparse KLU");
        assert_string_equal(de.backend, index2 ? "dense Eigen LU (stabilized index-2)"
                                               : "dense Eigen LU");
        const double q_size = max_abs(de.q, N), l_size = max_abs(de.lambda, M);
        const double dq = max_abs_diff(sp.q, de.q, N);
        const double dl = max_abs_diff(sp.lambda, de.lambda, M);
        printf("  %d x %d membrane, index %d, %d + %d unknowns: |q| %.3g, sparse - dense %.1e; "
               "|lambda| %.3g, %.1e; %.2f Newton iterations per step\n",
               SIDE, SIDE, index2 ? 2 : 3, N, M, q_size, dq, l_size, dl,
               (double)sp.newton / sp.steps);
        assert_true(q_size > 1e-3 && l_size > 1e-3); /* it moved, and the edge pulls */
        assert_true(dq <= 1e-12 * q_size);
        assert_true(dl <= 1e-10 * l_size);
        /* linear equations, exact tangent: Newton ends in its second iteration (the first
         * increment solves them, the second measures that) */
        assert_true(sp.newton == 2 * sp.steps && de.newton == 2 * de.steps);
    }
}

int main(void)
{
    static int rows[5 * N], cols[5 * N];
    static double vals[5 * N];
    K_rows = rows;
    K_cols = cols;
    K_vals = vals;
    K_nnz = stiffness_pattern(rows, cols);
    assert_int_equal(stiffness_values(vals), K_nnz);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sparse_and_dense_solvers_agree_on_a_mesh),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
