/* The spatial chain (examples/scenes/spatial_chain.h) on (R^3 x SO(3))^N, the sparse path on a
 * group space: its callbacks against central differences (ga_check_derivatives), the sparse
 * run against the dense run of the same callbacks scattered into dense matrices (another
 * linear algebra, another assembly of K_t T and Phi_q T), and the physics it must keep: the
 * joints closed to round-off and, without numerical dissipation (rho_inf = 1), the energy. */
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

#include "scenes/spatial_chain.h"

/* The same model with dense matrices: each callback's pattern values scattered */
typedef struct dense_chain {
    spatial_chain c;
    int n, m;
    int nnz[4];
    int *rows[4], *cols[4];
    double *values;
} dense_chain;

static void dense_make(dense_chain *d, int bodies, double spin)
{
    d->c = spatial_chain_make(bodies, spin);
    d->n = 6 * bodies;
    d->m = 3 * bodies;
    int most = 0;
    for (int w = 0; w < 4; ++w) {
        d->nnz[w] = spatial_chain_pattern(&d->c, w, NULL, NULL);
        d->rows[w] = malloc(sizeof(int) * (size_t)d->nnz[w]);
        d->cols[w] = malloc(sizeof(int) * (size_t)d->nnz[w]);
        spatial_chain_pattern(&d->c, w, d->rows[w], d->cols[w]);
        if (d->nnz[w] > most)
            most = d->nnz[w];
    }
    d->values = malloc(sizeof(double) * (size_t)most);
}

static void dense_free(dense_chain *d)
{
    for (int w = 0; w < 4; ++w) {
        free(d->rows[w]);
        free(d->cols[w]);
    }
    free(d->values);
}

static void scatter(const dense_chain *d, int w, int rows, double *A)
{
    memset(A, 0, sizeof(double) * (size_t)rows * (size_t)d->n);
    for (int k = 0; k < d->nnz[w]; ++k)
        A[d->rows[w][k] + rows * d->cols[w][k]] += d->values[k];
}

static int dn_mass(double t, const double *q, double *M, void *user)
{
    dense_chain *d = user;
    spatial_chain_mass(t, q, d->values, &d->c);
    scatter(d, GA_MATRIX_MASS, d->n, M);
    return 0;
}
static int dn_force(double t, const double *q, const double *v, double *f, void *user)
{
    return spatial_chain_force(t, q, v, f, &((dense_chain *)user)->c);
}
static int dn_constraint(double t, const double *q, double *phi, void *user)
{
    return spatial_chain_constraint(t, q, phi, &((dense_chain *)user)->c);
}
static int dn_jacobian(double t, const double *q, double *J, void *user)
{
    dense_chain *d = user;
    spatial_chain_jacobian(t, q, d->values, &d->c);
    scatter(d, GA_MATRIX_JACOBIAN, d->m, J);
    return 0;
}
static int dn_stiffness(double t, const double *q, const double *v, const double *qdd,
                        const double *lambda, double *K, void *user)
{
    dense_chain *d = user;
    spatial_chain_stiffness(t, q, v, qdd, lambda, d->values, &d->c);
    scatter(d, GA_MATRIX_STIFFNESS, d->n, K);
    return 0;
}
static int dn_damping(double t, const double *q, const double *v, double *C, void *user)
{
    dense_chain *d = user;
    spatial_chain_damping(t, q, v, d->values, &d->c);
    scatter(d, GA_MATRIX_DAMPING, d->n, C);
    return 0;
}

static ga_solver *dense_solver(dense_chain *d)
{
    const int N = d->c.bodies;
    int *kinds = malloc(sizeof(int) * 2 * (size_t)N), *counts = malloc(sizeof(int) * 2 * (size_t)N);
    spatial_chain_blocks(&d->c, kinds, counts);
    ga_solver *s = NULL;
    assert_int_equal(ga_create_space(2 * N, kinds, counts, d->m, &s), GA_OK);
    free(kinds);
    free(counts);
    assert_int_equal(ga_set_callbacks(s, dn_mass, dn_force, dn_constraint, dn_jacobian, d), GA_OK);
    assert_int_equal(ga_set_tangents(s, dn_stiffness, dn_damping), GA_OK);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_DENSE), GA_OK);
    return s;
}

/* Every callback against central differences at a general state (attitudes turned away from
 * the start, all velocities and multipliers nonzero) */
static void test_callbacks_are_their_derivatives(void **state)
{
    (void)state;
    dense_chain d;
    dense_make(&d, 3, 2.0);
    ga_solver *s = dense_solver(&d);
    double q[21], v[18], qdd[18], lambda[9], worst = 0.0;
    spatial_chain_initial(&d.c, q, v);
    for (int k = 0; k < 3; ++k) {
        const double psi[3] = {0.3 * (k + 1), -0.2 + 0.1 * k, 0.5 - 0.2 * k};
        double r[4], out[4];
        assert_int_equal(ga_so3_exp(1, psi, r), GA_OK);
        assert_int_equal(ga_so3_compose(1, q + 7 * k + 3, r, out), GA_OK);
        memcpy(q + 7 * k + 3, out, sizeof out);
    }
    for (int i = 0; i < 18; ++i) {
        v[i] = 0.3 * sin(1.0 + i);
        qdd[i] = cos(2.0 * i);
    }
    for (int i = 0; i < 9; ++i)
        lambda[i] = 5.0 + 3.0 * sin(0.7 * i);
    const ga_status st = ga_check_derivatives(s, 0.0, q, v, qdd, lambda, NULL, 1e-6, &worst);
    if (st)
        print_error("%s\n", ga_last_error(s));
    assert_int_equal(st, GA_OK);
    print_message("  largest relative difference %.2e\n", worst);
    ga_free(s);
    dense_free(&d);
}

static double energy(const spatial_chain *c, const double *q, const double *v)
{
    double e = 0.0;
    for (int k = 0; k < c->bodies; ++k) {
        for (int i = 0; i < 3; ++i)
            e += 0.5 * c->mass * v[6 * k + i] * v[6 * k + i] +
                 0.5 * c->inertia[i] * v[6 * k + 3 + i] * v[6 * k + 3 + i];
        e += c->mass * c->gravity * q[7 * k + 2];
    }
    return e;
}

/* 8 bodies, h = 1e-3 to t = 0.5 (the chain falls through about a metre): the sparse run is
 * the dense one to round-off at every step, with the same Newton iterations, in index 3 and
 * in the stabilized index 2 */
static void test_sparse_run_is_the_dense_run(void **state)
{
    (void)state;
    enum { N = 8 };
    for (int form = 0; form < 2; ++form) {
        const int formulation = form ? GA_INDEX2_STABILIZED : GA_INDEX3;
        dense_chain d;
        dense_make(&d, N, 2.0);
        spatial_chain c = spatial_chain_make(N, 2.0);
        ga_solver *sp = NULL, *de = dense_solver(&d);
        assert_int_equal(spatial_chain_solver(&c, &sp), GA_OK);
        assert_int_equal(ga_set_linear_solver(sp, GA_LINEAR_SPARSE), GA_OK);
        assert_int_equal(ga_set_formulation(sp, formulation), GA_OK);
        assert_int_equal(ga_set_formulation(de, formulation), GA_OK);
        double q[7 * N], v[6 * N], qs[7 * N], qd[7 * N];
        spatial_chain_initial(&c, q, v);
        assert_int_equal(ga_init(sp, 0.0, q, v), GA_OK);
        assert_int_equal(ga_init(de, 0.0, q, v), GA_OK);
        assert_string_equal(ga_linear_solver_name(sp),
                            form ? "sparse KLU (stabilized index-2)" : "sparse KLU");
        double worst = 0.0;
        for (int k = 0; k < 500; ++k) {
            assert_int_equal(ga_step(sp, 1e-3), GA_OK);
            assert_int_equal(ga_step(de, 1e-3), GA_OK);
            assert_int_equal(ga_get_q(sp, qs), GA_OK);
            assert_int_equal(ga_get_q(de, qd), GA_OK);
            for (int i = 0; i < 7 * N; ++i)
                worst = fmax(worst, fabs(qs[i] - qd[i]));
        }
        long long ns, nd;
        assert_int_equal(ga_get_counter(sp, GA_COUNT_NEWTON_ITERS, &ns), GA_OK);
        assert_int_equal(ga_get_counter(de, GA_COUNT_NEWTON_ITERS, &nd), GA_OK);
        print_message("  index %d: sparse - dense %.2e in q; Newton iterations %lld / %lld; "
                      "lowest end at z = %.3f\n",
                      form ? 2 : 3, worst, ns, nd, qs[7 * (N - 1) + 2]);
        assert_true(worst < 1e-11);
        assert_int_equal(ns, nd);
        assert_true(qs[7 * (N - 1) + 2] < -0.5); /* it fell */
        ga_free(sp);
        ga_free(de);
        dense_free(&d);
    }
}

/* rho_inf = 1: no numerical dissipation, so the energy stays within the method's O(h^2)
 * error (measured over 1 s, 20 bodies: 1.9e-6 of the potential energy released at h = 2e-3,
 * 4.7e-7 at 1e-3: order 1.98), and the joints stay closed to round-off (index 3) */
static void test_energy_and_joints(void **state)
{
    (void)state;
    enum { N = 20 };
    double drift[2];
    for (int r = 0; r < 2; ++r) {
        const double h = r == 0 ? 2e-3 : 1e-3;
        spatial_chain c = spatial_chain_make(N, 2.0);
        ga_solver *s = NULL;
        assert_int_equal(spatial_chain_solver(&c, &s), GA_OK);
        assert_int_equal(ga_set_rho_inf(s, 1.0), GA_OK);
        double q[7 * N], v[6 * N], phi[3 * N];
        spatial_chain_initial(&c, q, v);
        const double e0 = energy(&c, q, v);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        double off = 0.0, released = 0.0, gap = 0.0;
        for (long k = 0; k < lround(1.0 / h); ++k) {
            assert_int_equal(ga_step(s, h), GA_OK);
            assert_int_equal(ga_get_q(s, q), GA_OK);
            assert_int_equal(ga_get_v(s, v), GA_OK);
            double pot = 0.0;
            for (int b = 0; b < N; ++b)
                pot += c.mass * c.gravity * q[7 * b + 2];
            released = fmax(released, -pot);
            off = fmax(off, fabs(energy(&c, q, v) - e0));
            spatial_chain_constraint(0.0, q, phi, &c);
            for (int i = 0; i < 3 * N; ++i)
                gap = fmax(gap, fabs(phi[i]));
        }
        drift[r] = off / released;
        print_message("  h = %g: energy within %.2e of the potential energy released (%.1f J); "
                      "joints closed to %.1e m\n",
                      h, drift[r], released, gap);
        assert_true(gap < 1e-12);
        ga_free(s);
    }
    const double order = log(drift[0] / drift[1]) / log(2.0);
    print_message("  energy error order %.2f\n", order);
    assert_true(drift[1] < 1e-6);
    assert_true(order > 1.8 && order < 2.2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_callbacks_are_their_derivatives),
        cmocka_unit_test(test_sparse_run_is_the_dense_run),
        cmocka_unit_test(test_energy_and_joints),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
