/* The dense LU kernels on a matrix without zeros: n masses coupled through a full mass matrix
 * M = I + c 1 1^T, springs to the origin, and m full linear constraints A q = b. Eigen's
 * blocked LU, LAPACK's dgetrf and galpha's unblocked kernel are three independent
 * implementations: the trajectories they produce must agree to round-off. GA_LINEAR_DENSE
 * picks Eigen's for this matrix (n + m > 40 and almost no zero entry) and the unblocked
 * kernel for a mechanism-like one (the chain, mostly zero: test_chain.c). Singular matrices:
 * test_errors.c, for every kernel. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"

enum { N_Q = 36, N_C = 12 };

/* A deterministic full constraint matrix: row i, column j */
static double a_entry(int i, int j) { return cos(1.0 + 0.7 * i + 1.3 * j) + (i == j ? 2.0 : 0.0); }

static int full_mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    for (int j = 0; j < N_Q; ++j)
        for (int i = 0; i < N_Q; ++i)
            M[i + j * N_Q] = (i == j ? 1.0 : 0.0) + 0.05;
    return 0;
}

static int springs(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t, (void)v, (void)user;
    for (int i = 0; i < N_Q; ++i)
        f[i] = -(1.0 + 0.1 * i) * q[i];
    return 0;
}

static int linear_constraints(double t, const double *q, double *phi, void *user)
{
    (void)t, (void)user;
    for (int i = 0; i < N_C; ++i) {
        phi[i] = 0.0;
        for (int j = 0; j < N_Q; ++j)
            phi[i] += a_entry(i, j) * q[j];
    }
    return 0;
}

static int constraint_matrix(double t, const double *q, double *J, void *user)
{
    (void)t, (void)q, (void)user;
    for (int j = 0; j < N_Q; ++j)
        for (int i = 0; i < N_C; ++i)
            J[i + j * N_C] = a_entry(i, j);
    return 0;
}

typedef struct run_result {
    double q[N_Q], lambda[N_C];
    double rcond; /* GA_INFO_RCOND after the last step */
    char backend[64];
} run_result;

static void run(int solver, run_result *out)
{
    ga_solver *s = NULL;
    double q[N_Q], v[N_Q];
    for (int i = 0; i < N_Q; ++i) {
        q[i] = sin(0.3 * i); /* projected onto A q = 0 by ga_init */
        v[i] = 0.0;
    }
    assert_int_equal(ga_create(N_Q, N_C, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, full_mass, springs, linear_constraints,
                                      constraint_matrix, NULL),
                     GA_OK);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, solver), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 10), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < 50; ++k)
        assert_int_equal(ga_step(s, 0.05), GA_OK);
    assert_int_equal(ga_get_q(s, out->q), GA_OK);
    assert_int_equal(ga_get_lambda(s, out->lambda), GA_OK);
    assert_int_equal(ga_get_info(s, GA_INFO_RCOND, &out->rcond), GA_OK);
    strncpy(out->backend, ga_linear_solver_name(s), sizeof out->backend - 1);
    out->backend[sizeof out->backend - 1] = '\0';
    ga_free(s);
}

static double relative_difference(const double *a, const double *b, int n)
{
    double d = 0.0, scale = 0.0;
    for (int i = 0; i < n; ++i) {
        d = fmax(d, fabs(a[i] - b[i]));
        scale = fmax(scale, fabs(b[i]));
    }
    return d / scale;
}

static void three_dense_kernels_agree_on_a_full_matrix(void **state)
{
    (void)state;
    static run_result eigen, lapack, unblocked, chosen;
    run(GA_LINEAR_DENSE_EIGEN, &eigen);
    run(GA_LINEAR_DENSE_LAPACK, &lapack);
    run(GA_LINEAR_DENSE_UNBLOCKED, &unblocked);
    run(GA_LINEAR_DENSE, &chosen);
    assert_string_equal(eigen.backend, "dense Eigen LU");
    assert_string_equal(lapack.backend, "dense LAPACK LU");
    assert_string_equal(unblocked.backend, "dense unblocked LU");
    /* 48 unknowns, every entry of S nonzero except the 12 x 12 block: Eigen's */
    assert_string_equal(chosen.backend, "dense Eigen LU");
    const double dq_lapack = relative_difference(lapack.q, eigen.q, N_Q);
    const double dl_lapack = relative_difference(lapack.lambda, eigen.lambda, N_C);
    const double dq_unblocked = relative_difference(unblocked.q, eigen.q, N_Q);
    const double dl_unblocked = relative_difference(unblocked.lambda, eigen.lambda, N_C);
    printf("  against Eigen's LU after 50 steps (relative): LAPACK |dq| %.1e |dlambda| %.1e, "
           "unblocked |dq| %.1e |dlambda| %.1e\n",
           dq_lapack, dl_lapack, dq_unblocked, dl_unblocked);
    /* positions agree to round-off; index-3 multipliers only to about eps / (beta h^2)
     * relative to the positions (paper, sec. 3.3): ask of the unblocked kernel what two
     * library LUs achieve between themselves */
    assert_true(dq_lapack < 1e-12);
    assert_true(dq_unblocked < 1e-12);
    assert_true(dl_unblocked <= 10.0 * fmax(dl_lapack, 1e-12));
    assert_true(relative_difference(chosen.q, eigen.q, N_Q) == 0.0); /* the same kernel */
    /* LAPACK's dgecon estimates the condition from the factors of each kernel: the same
     * number if the unblocked factors have dgetrf's layout and pivots */
    printf("  condition estimates: Eigen %.6e, LAPACK %.6e, unblocked %.6e\n", eigen.rcond,
           lapack.rcond, unblocked.rcond);
    assert_true(eigen.rcond > 0.0 && eigen.rcond < 1.0);
    assert_true(fabs(lapack.rcond - eigen.rcond) <= 1e-8 * eigen.rcond);
    assert_true(fabs(unblocked.rcond - eigen.rcond) <= 1e-8 * eigen.rcond);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(three_dense_kernels_agree_on_a_full_matrix),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
