/* GA_TANGENT_AUTO (the default without tangent callbacks) takes finite-difference tangents
 * where they matter and leaves them out where they do not:
 *  - a chain of 10 links with stiff torsional spring-dampers between them (k = 1e4, c = 5), at
 *    steps where the simplified Newton iteration (GA_TANGENT_NEGLECT) does not converge at all:
 *    AUTO takes at most 1.25 times the Newton iterations and factorizations of GA_TANGENT_FD;
 *  - Andrews' mechanism (31 coordinates), where beta h^2 K_t is small against M: AUTO spares the
 *    finite differences that GA_TANGENT_FD evaluates at every refactorization. */
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>
#include <galpha.h>

#include "helpers.h"
#include "scenes/andrews.h"
#include "scenes/chain.h"
#include "scenes/lattice.h"
#include "scenes/pendulum.h"

enum { kLinks = 10 };
static chain g_chain;
static const double kSpring = 1e4, kDamper = 5.0;

/* gravity plus torsional spring-dampers on the relative angles of neighbouring links */
static int stiff_force(double t, const double *q, const double *v, double *f, void *u)
{
    chain_force(t, q, v, f, u);
    for (int i = 1; i < kLinks; ++i) {
        const int a = 3 * i + 2, b = 3 * (i - 1) + 2;
        const double torque = kSpring * (q[a] - q[b]) + kDamper * (v[a] - v[b]);
        f[a] -= torque;
        f[b] += torque;
    }
    return 0;
}

typedef struct work {
    ga_status status;
    double iterations, factorizations; /* per step */
    long long tangent_evals;
} work;

static work stiff_chain_run(int mode, double h)
{
    ga_solver *s = NULL;
    int rows[3 * kLinks * 3], cols[3 * kLinks * 3], k = 0;
    double q[3 * kLinks], v[3 * kLinks];
    work w = {GA_OK, 0, 0, 0};
    g_chain = chain_make(kLinks);
    assert_int_equal(ga_create(3 * kLinks, 2 * kLinks, &s), GA_OK);
    assert_int_equal(chain_declare_patterns(&g_chain, s), GA_OK);
    /* K_t and C_t: the angles of neighbouring links (and the constraints' angle terms) */
    for (int i = 0; i < kLinks; ++i)
        for (int j = i - 1; j <= i + 1; ++j)
            if (j >= 0 && j < kLinks) {
                rows[k] = 3 * i + 2;
                cols[k] = 3 * j + 2;
                ++k;
            }
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, k, rows, cols), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_DAMPING, k, rows, cols), GA_OK);
    assert_int_equal(ga_set_callbacks(s, chain_mass, stiff_force, chain_constraint,
                                      chain_jacobian, &g_chain),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, chain_constraint_accel), GA_OK);
    assert_int_equal(ga_set_constraint_dt(s, chain_constraint_dt), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
    chain_initial(&g_chain, q, v);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    const long n = lround(1.0 / h);
    long i = 0;
    for (; i < n && !w.status; ++i)
        w.status = ga_step(s, h);
    long long it, fac;
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &fac);
    ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &w.tangent_evals);
    w.iterations = (double)it / (double)i;
    w.factorizations = (double)fac / (double)i;
    ga_free(s);
    return w;
}

static void auto_takes_the_tangents_where_they_matter(void **state)
{
    (void)state;
    for (int k = 0; k < 2; ++k) {
        const double h = k == 0 ? 3e-3 : 1e-2;
        const work neglect = stiff_chain_run(GA_TANGENT_NEGLECT, h);
        const work fd = stiff_chain_run(GA_TANGENT_FD, h);
        const work aut = stiff_chain_run(GA_TANGENT_AUTO, h);
        printf("  stiff chain, h = %g: without tangents %s; FD %.2f iterations, %.2f "
               "factorizations per step; AUTO %.2f, %.2f\n",
               h, ga_strerror(neglect.status), fd.iterations, fd.factorizations,
               aut.iterations, aut.factorizations);
        assert_int_not_equal(neglect.status, GA_OK); /* the tangents matter here */
        assert_int_equal(fd.status, GA_OK);
        assert_int_equal(aut.status, GA_OK);
        assert_true(aut.iterations <= 1.25 * fd.iterations);
        assert_true(aut.factorizations <= 1.25 * fd.factorizations);
    }
}

/* Andrews (31 coordinates, no K_t callback), h = 3e-4 to t = 0.03, Newton tolerance 1e-6. */
static work andrews_run(int mode)
{
    ga_solver *s = NULL;
    double q[AN31_N], v[AN31_N], v7[7] = {0};
    work w = {GA_OK, 0, 0, 0};
    assert_int_equal(ga_create(AN31_N, AN31_M, &s), GA_OK);
    assert_int_equal(an31_declare_patterns(s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, an31_mass_sparse, an31_force, an31_constraint,
                                      an31_jacobian_sparse, NULL),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, an31_constraint_accel), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-6, 20), GA_OK);
    an31_from_angles(andrews_q0, v7, q, v);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int i = 0; i < 100 && !w.status; ++i)
        w.status = ga_step(s, 3e-4);
    long long it, fac, res;
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &fac);
    ga_get_counter(s, GA_COUNT_RESIDUALS, &res);
    ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &w.tangent_evals);
    w.iterations = (double)it / 100.0;
    w.factorizations = (double)fac / 100.0;
    ga_free(s);
    return w;
}

static void auto_spares_the_tangents_where_they_do_not(void **state)
{
    (void)state;
    const work fd = andrews_run(GA_TANGENT_FD), aut = andrews_run(GA_TANGENT_AUTO);
    printf("  Andrews: FD %.2f iterations, %.2f factorizations per step, %lld tangent "
           "evaluations; AUTO %.2f, %.2f, %lld\n",
           fd.iterations, fd.factorizations, fd.tangent_evals, aut.iterations,
           aut.factorizations, aut.tangent_evals);
    assert_int_equal(fd.status, GA_OK);
    assert_int_equal(aut.status, GA_OK);
    assert_true(aut.tangent_evals * 10 <= fd.tangent_evals);
    assert_true(aut.iterations <= 1.25 * fd.iterations);
}

/* The residual counter counts all residuals, those of finite-difference tangents too (one per
 * column for a dense K_t): work-precision comparisons count honestly (issue 17). */
static void differences_count_their_residuals(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2];
    pendulum_state(&p, 1.0, 0.5, q, v);
    ga_solver *s = pendulum_new_solver(&p, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int i = 0; i < 10; ++i)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    long long residuals, iterations, tangents;
    ga_get_counter(s, GA_COUNT_RESIDUALS, &residuals);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iterations);
    ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &tangents);
    printf("  %lld residuals: %lld Newton iterations, %lld tangents of 2 columns\n", residuals,
           iterations, tangents);
    assert_true(tangents > 0);
    assert_true(residuals == iterations + 2 * tangents);
    ga_free(s);
}

/* The lattice of the PETSc bench (examples/scenes/lattice.h): its K_t, written by hand for
 * the compressed rows it declares, is minus the derivative of its forces, checked column by
 * column against central differences at a displaced state (every spring stretched or bent). */
static void lattice_stiffness_is_the_force_derivative(void **state)
{
    (void)state;
    lattice l;
    assert_int_equal(lattice_make(&l, 6, 4, 1e4, 1e3), 0);
    const int n = l.n;
    double *q = calloc((size_t)n, sizeof(double)), *fp = calloc((size_t)n, sizeof(double)),
           *fm = calloc((size_t)n, sizeof(double)), *K = calloc((size_t)l.nnz, sizeof(double));
    assert_true(q && fp && fm && K);
    for (int i = 0; i < n; ++i)
        q[i] = 0.1 * sin(1.3 * i);
    lattice_stiffness_values(&l, q, K);
    double worst = 0.0, largest = 0.0;
    const double e = 1e-6;
    for (int c = 0; c < n; ++c) {
        q[c] += e;
        lattice_force(0.0, q, NULL, fp, &l);
        q[c] -= 2.0 * e;
        lattice_force(0.0, q, NULL, fm, &l);
        q[c] += e;
        for (int r = 0; r < n; ++r) {
            double k = 0.0; /* K[r][c], zero outside the pattern */
            for (int p = l.rowptr[r]; p < l.rowptr[r + 1]; ++p)
                if (l.colind[p] == c)
                    k = K[p];
            worst = fmax(worst, fabs(k + (fp[r] - fm[r]) / (2.0 * e)));
            largest = fmax(largest, fabs(k));
        }
    }
    printf("  lattice, %d unknowns: max |K_t + df/dq| %.2g of max |K_t| %.2g\n", n, worst,
           largest);
    /* central differences of forces of size k ~ 1e7: truncation e^2 and round-off eps f / e */
    assert_true(worst <= 1e-8 * largest);
    free(q);
    free(fp);
    free(fm);
    free(K);
    lattice_free(&l);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(auto_takes_the_tangents_where_they_matter),
        cmocka_unit_test(auto_spares_the_tangents_where_they_do_not),
        cmocka_unit_test(differences_count_their_residuals),
        cmocka_unit_test(lattice_stiffness_is_the_force_derivative),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
