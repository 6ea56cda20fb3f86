/* Operating points of models on the sparse path: the static solve on [K_t, Phi_q^T; Phi_q, 0]
 * and ga_modes_near (shift-invert Lanczos). Oracles: the lattice's lowest frequencies from
 * LAPACK's dsyev on its dense K_t (the scene's own values, densified here) and its static
 * residual from the scene's force; the double pendulum's frequencies in closed form; uncoupled
 * oscillators whose omega^2 = k_i are known exactly, for which modes nearest a shift. Then
 * every refusal, with nothing written and the solver as it was. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "scenes/lattice.h"

extern void dsyev_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda,
                   double *w, double *work, const int *lwork, int *info);

static const double g_acc = 9.81;

static double max_abs(const double *x, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; ++i)
        m = fmax(m, fabs(x[i]));
    return m;
}

/* ---- the lattice ------------------------------------------------------------------------ */
static ga_solver *lattice_solver(lattice *l, int solver)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(l->n, 0, &s), GA_OK);
    assert_int_equal(lattice_declare_patterns(l, s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, lattice_mass, lattice_force, NULL, NULL, l), GA_OK);
    assert_int_equal(ga_set_tangents(s, lattice_stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, solver), GA_OK);
    return s;
}

/* The dense K_t of the scene at q: its CSR values scattered. */
static double *dense_stiffness(const lattice *l, const double *q)
{
    const int n = l->n;
    double *vals = malloc(sizeof(double) * (size_t)l->nnz);
    double *K = calloc((size_t)n * (size_t)n, sizeof(double));
    assert_non_null(vals);
    assert_non_null(K);
    lattice_stiffness_values(l, q, vals);
    for (int i = 0; i < n; ++i)
        for (int p = l->rowptr[i]; p < l->rowptr[i + 1]; ++p)
            K[i + (size_t)n * (size_t)l->colind[p]] += vals[p];
    free(vals);
    return K;
}

static void test_lattice_sags_to_a_root_and_its_lowest_modes_equal_lapack(void **state)
{
    (void)state;
    lattice l;
    assert_int_equal(lattice_make(&l, 24, 6, 1e6, 10.0), 0);
    const int n = l.n;
    ga_solver *s = lattice_solver(&l, GA_LINEAR_AUTO);
    double *q = calloc((size_t)n, sizeof(double)), *f = malloc(sizeof(double) * (size_t)n);
    const ga_status st = ga_static_equilibrium(s, 0.0, q, NULL, 1e-13, 50);
    if (st)
        printf("  %s\n", ga_last_error(s));
    assert_int_equal(st, GA_OK);
    /* a root: the scene's own force balances to round-off of the spring forces */
    lattice_force(0.0, q, NULL, f, &l);
    double *K = dense_stiffness(&l, q);
    const double kmax = max_abs(K, n * n), qmax = max_abs(q, n);
    /* (the spring lengths come from node positions up to nx m: their round-off, times the
     * stiffness, is the floor) */
    const double floor = DBL_EPSILON * kmax * l.nx;
    printf("  lattice %d unknowns: tip sag %.6g m, |f| %.3g = %.2g eps |K| nx\n", n, q[n - 1],
           max_abs(f, n), max_abs(f, n) / floor);
    assert_true(qmax > 1e-3);
    assert_true(max_abs(f, n) <= 8 * floor);
    /* the dense path's null-space Newton finds the same rest */
    ga_solver *dense = lattice_solver(&l, GA_LINEAR_DENSE);
    double *qd = calloc((size_t)n, sizeof(double));
    assert_int_equal(ga_static_equilibrium(dense, 0.0, qd, NULL, 1e-13, 50), GA_OK);
    double diff = 0.0;
    for (int i = 0; i < n; ++i)
        diff = fmax(diff, fabs(q[i] - qd[i]));
    printf("  sparse and dense rests differ by %.3g of %.3g\n", diff, qmax);
    assert_true(diff <= 1e-10 * qmax);

    enum { count = 10 };
    double w2[count], *shapes = malloc(sizeof(double) * (size_t)n * count);
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, count, w2, shapes), GA_OK);
    /* LAPACK on the same matrices: K_t / mass (M = mass I) */
    double *A = malloc(sizeof(double) * (size_t)n * (size_t)n), *ev = malloc(sizeof(double) * n);
    for (size_t i = 0; i < (size_t)n * (size_t)n; ++i)
        A[i] = K[i] / l.mass;
    int lwork = -1, info = 0;
    double wq;
    dsyev_("N", "U", &n, A, &n, ev, &wq, &lwork, &info);
    lwork = (int)wq;
    double *work = malloc(sizeof(double) * (size_t)lwork);
    dsyev_("N", "U", &n, A, &n, ev, work, &lwork, &info);
    assert_int_equal(info, 0);
    double worst = 0.0;
    for (int k = 0; k < count; ++k)
        worst = fmax(worst, fabs(w2[k] - ev[k]) / ev[k]);
    printf("  10 lowest omega^2 %.6g .. %.6g, against dsyev %.3g relative\n", w2[0], w2[count - 1],
           worst);
    assert_true(worst <= 1e-8);
    /* the shapes: K x = omega^2 M x, unit modal mass */
    double res = 0.0;
    for (int k = 0; k < count; ++k) {
        const double *x = shapes + (size_t)n * k;
        double mm = 0.0;
        for (int i = 0; i < n; ++i) {
            double kx = 0.0;
            for (int j = 0; j < n; ++j)
                kx += K[i + (size_t)n * j] * x[j];
            res = fmax(res, fabs(kx - w2[k] * l.mass * x[i]) / (kmax * max_abs(x, n)));
            mm += l.mass * x[i] * x[i];
        }
        assert_true(fabs(mm - 1.0) <= 1e-12);
    }
    printf("  shapes: |K x - omega^2 M x| <= %.3g |K| |x|\n", res);
    assert_true(res <= 1e-10);
    free(work);
    free(ev);
    free(A);
    free(shapes);
    free(qd);
    free(K);
    free(f);
    free(q);
    ga_free(dense);
    ga_free(s);
    lattice_free(&l);
}

/* Newton's line search on the residual needs load steps where a stiff part rotates: the
 * two-material lattice at contrast 1e3 from its unstressed start (GA_ERR_NEWTON, nothing
 * written), then gravity in 100 steps, each from the last rest: a root. */
static void test_a_stiff_lattice_needs_load_steps(void **state)
{
    (void)state;
    lattice l;
    assert_int_equal(lattice_make(&l, 16, 4, 1e6, 1e3), 0);
    const int n = l.n;
    ga_solver *s = lattice_solver(&l, GA_LINEAR_AUTO);
    double *q = calloc((size_t)n, sizeof(double)), *f = malloc(sizeof(double) * (size_t)n);
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 50), GA_ERR_NEWTON);
    assert_non_null(strstr(ga_last_error(s), "no equilibrium"));
    for (int i = 0; i < n; ++i)
        assert_true(q[i] == 0.0);
    const double g = l.gravity;
    for (int k = 1; k <= 100; ++k) {
        l.gravity = g * k / 100.0;
        assert_int_equal(ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 50), GA_OK);
    }
    lattice_force(0.0, q, NULL, f, &l);
    double *K = dense_stiffness(&l, q);
    const double floor = DBL_EPSILON * max_abs(K, n * n) * l.nx;
    printf("  contrast 1e3 in 100 load steps: tip sag %.6g m, |f| = %.2g eps |K| nx\n",
           q[n - 1], max_abs(f, n) / floor);
    assert_true(max_abs(f, n) <= 8 * floor && fabs(q[n - 1]) > 1e-3);
    free(K);
    free(f);
    free(q);
    ga_free(s);
    lattice_free(&l);
}

/* ---- the double pendulum, declared sparse ------------------------------------------------ */
typedef struct {
    double m[2], L[2];
    int redundant; /* a third row repeating the second */
    int fail_force;
} Pend;

static int pd_mass(double t, const double *q, double *M, void *u)
{
    const Pend *p = u;
    (void)t, (void)q;
    for (int i = 0; i < 4; ++i)
        M[i] = p->m[i / 2];
    return 0;
}

static int pd_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Pend *p = u;
    (void)t, (void)q, (void)v;
    if (p->fail_force)
        return -1;
    f[0] = f[2] = 0.0;
    f[1] = -p->m[0] * g_acc;
    f[3] = -p->m[1] * g_acc;
    return 0;
}

static int pd_phi(double t, const double *q, double *phi, void *u)
{
    const Pend *p = u;
    (void)t;
    const double dx = q[2] - q[0], dy = q[3] - q[1];
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p->L[0] * p->L[0]);
    phi[1] = 0.5 * (dx * dx + dy * dy - p->L[1] * p->L[1]);
    if (p->redundant)
        phi[2] = phi[1];
    return 0;
}

/* pattern (row, col): row 0 at cols 0, 1; row 1 (and 2) at cols 0..3 */
static const int pd_jrow[10] = {0, 0, 1, 1, 1, 1, 2, 2, 2, 2};
static const int pd_jcol[10] = {0, 1, 0, 1, 2, 3, 0, 1, 2, 3};

static int pd_jac(double t, const double *q, double *J, void *u)
{
    const Pend *p = u;
    (void)t;
    const double dx = q[2] - q[0], dy = q[3] - q[1];
    J[0] = q[0];
    J[1] = q[1];
    J[2] = -dx;
    J[3] = -dy;
    J[4] = dx;
    J[5] = dy;
    if (p->redundant)
        memcpy(J + 6, J + 2, 4 * sizeof(double));
    return 0;
}

/* K_t = sum lambda_i Phi_i'' (gravity does not depend on q), dense 4 x 4 in the pattern of
 * every (row, col), column-major */
static int pd_stiffness(double t, const double *q, const double *v, const double *qdd,
                        const double *lambda, double *K, void *u)
{
    const Pend *p = u;
    (void)t, (void)q, (void)v, (void)qdd;
    const double l0 = lambda[0], l1 = lambda[1] + (p->redundant ? lambda[2] : 0.0);
    memset(K, 0, 16 * sizeof(double));
    for (int d = 0; d < 2; ++d) {
        K[d + 4 * d] = l0 + l1;
        K[(2 + d) + 4 * (2 + d)] = l1;
        K[d + 4 * (2 + d)] = -l1;
        K[(2 + d) + 4 * d] = -l1;
    }
    return 0;
}

static ga_solver *pend_solver(Pend *p)
{
    const int m = p->redundant ? 3 : 2;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(4, m, &s), GA_OK);
    const int diag[4] = {0, 1, 2, 3};
    int krow[16], kcol[16];
    for (int e = 0; e < 16; ++e) {
        krow[e] = e % 4;
        kcol[e] = e / 4;
    }
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 4, diag, diag), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, m == 3 ? 10 : 6, pd_jrow, pd_jcol),
                     GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, 16, krow, kcol), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pd_mass, pd_force, pd_phi, pd_jac, p), GA_OK);
    assert_int_equal(ga_set_tangents(s, pd_stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    return s;
}

static void test_double_pendulum_on_the_sparse_path_in_closed_form(void **state)
{
    (void)state;
    Pend p = {{1.3, 0.6}, {0.9, 1.4}, 0, 0};
    ga_solver *s = pend_solver(&p);
    double q[4] = {0.3, -0.8, 0.9, -2.0}, lambda[2];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_OK);
    const double want_q[4] = {0.0, -0.9, 0.0, -2.3};
    for (int i = 0; i < 4; ++i)
        assert_true(fabs(q[i] - want_q[i]) <= 1e-14);
    /* hanging: Phi_q^T lambda = f, lambda_0 L0 = (m0 + m1) g ... by hand */
    const double l1 = p.m[1] * g_acc / p.L[1], l0 = (p.m[0] + p.m[1]) * g_acc / p.L[0];
    assert_true(fabs(lambda[0] - l0) <= 1e-13 * l0);
    assert_true(fabs(lambda[1] - l1) <= 1e-13 * l1);
    /* frequencies: m1 m2 L1^2 L2^2 w^4 - (m1 + m2) m2 g L1 L2 (L1 + L2) w^2
     *              + (m1 + m2) m2 g^2 L1 L2 = 0 */
    const double m1 = p.m[0], m2 = p.m[1], L1 = p.L[0], L2 = p.L[1];
    const double a = m1 * m2 * L1 * L1 * L2 * L2, b = -(m1 + m2) * m2 * g_acc * L1 * L2 * (L1 + L2),
                 c = (m1 + m2) * m2 * g_acc * g_acc * L1 * L2;
    const double disc = sqrt(b * b - 4 * a * c);
    const double want[2] = {(-b - disc) / (2 * a), (-b + disc) / (2 * a)};
    double w2[2], shapes[8];
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 2, w2, shapes), GA_OK);
    for (int k = 0; k < 2; ++k) {
        printf("  omega^2 %.15g against %.15g\n", w2[k], want[k]);
        assert_true(fabs(w2[k] - want[k]) <= 1e-10 * want[k]);
        /* on the constraints' tangent: Phi_q x = 0 at the rest (x horizontal) */
        assert_true(fabs(shapes[1 + 4 * k]) <= 1e-13 && fabs(shapes[3 + 4 * k]) <= 1e-13);
    }
    /* the same with the multipliers given, and a shift between the two picks the nearer */
    assert_int_equal(ga_modes_near(s, 0.0, q, lambda, 0.0, 2, w2, NULL), GA_OK);
    assert_true(fabs(w2[0] - want[0]) <= 1e-10 * want[0]);
    assert_int_equal(ga_modes_near(s, 0.0, q, lambda, 0.9 * want[1], 1, w2, NULL), GA_OK);
    assert_true(fabs(w2[0] - want[1]) <= 1e-10 * want[1]);
    /* refusals on this model: lambda unbalanced, off the constraints, not an equilibrium */
    double bad[2] = {lambda[0] * 1.01, lambda[1]}, w = 0.0;
    assert_int_equal(ga_modes_near(s, 0.0, q, bad, 0.0, 1, &w, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "does not balance"));
    double off[4] = {0.0, -0.95, 0.0, -2.3};
    assert_int_equal(ga_modes_near(s, 0.0, off, NULL, 0.0, 1, &w, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "off the constraints"));
    const double th = 0.3;
    double swung[4] = {L1 * sin(th), -L1 * cos(th), L1 * sin(th), -L1 * cos(th) - L2};
    assert_int_equal(ga_modes_near(s, 0.0, swung, NULL, 0.0, 1, &w, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "not an equilibrium"));
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 3, &w, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "2 degrees of freedom"));
    assert_true(w == 0.0); /* (nothing written by the refusals) */
    ga_free(s);
}

static void test_redundant_constraints_are_refused_on_the_sparse_path(void **state)
{
    (void)state;
    Pend p = {{1.3, 0.6}, {0.9, 1.4}, 1, 0};
    ga_solver *s = pend_solver(&p);
    double q[4] = {0.3, -0.8, 0.9, -2.0}, keep[4], lambda[3] = {7, 7, 7}, w = 0.0;
    memcpy(keep, q, sizeof q);
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "redundant"));
    assert_memory_equal(q, keep, sizeof q);
    assert_true(lambda[0] == 7 && lambda[1] == 7 && lambda[2] == 7);
    double rest[4] = {0.0, -0.9, 0.0, -2.3};
    assert_int_equal(ga_modes_near(s, 0.0, rest, NULL, 0.0, 1, &w, NULL), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "redundant"));
    ga_free(s);
}

/* ---- uncoupled oscillators: omega^2 = k_i exactly ---------------------------------------- */
enum { NOSC = 12 };
typedef struct {
    double mass;      /* every one's */
    double circulate; /* f_0 += circulate q_1: a non-symmetric K_t */
    int no_root;      /* f = -(1 + q^2): no equilibrium anywhere */
    int zero_k;       /* f = 1: nothing restrains */
} Osc;

static int osc_mass(double t, const double *q, double *M, void *u)
{
    const Osc *o = u;
    (void)t, (void)q;
    for (int i = 0; i < NOSC; ++i)
        M[i] = o->mass;
    return 0;
}

static int osc_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Osc *o = u;
    (void)t, (void)v;
    for (int i = 0; i < NOSC; ++i)
        f[i] = o->no_root ? -(1.0 + q[i] * q[i]) : o->zero_k ? 1.0 : -(i + 1.0) * q[i];
    f[0] += o->circulate * q[1];
    return 0;
}

static ga_solver *osc_solver(Osc *o)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(NOSC, 0, &s), GA_OK);
    int diag[NOSC], krow[NOSC + 1], kcol[NOSC + 1];
    for (int i = 0; i < NOSC; ++i)
        diag[i] = krow[i] = kcol[i] = i;
    krow[NOSC] = 0; /* (0, 1): the circulatory entry */
    kcol[NOSC] = 1;
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, NOSC, diag, diag), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, NOSC + 1, krow, kcol), GA_OK);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_callbacks(s, osc_mass, osc_force, NULL, NULL, o), GA_OK);
    return s; /* K_t by differences grouped by its pattern; AUTO takes the sparse path */
}

static void test_modes_nearest_a_shift_are_the_nearest(void **state)
{
    (void)state;
    Osc o = {1.0, 0.0, 0, 0};
    ga_solver *s = osc_solver(&o);
    double q[NOSC] = {0}, w2[3], shapes[3 * NOSC];
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 3, w2, shapes), GA_OK);
    for (int k = 0; k < 3; ++k) {
        assert_true(fabs(w2[k] - (k + 1.0)) <= 1e-9 * (k + 1.0)); /* K_t by differences */
        for (int i = 0; i < NOSC; ++i) /* unit modal mass, largest entry positive: e_k */
            assert_true(fabs(shapes[i + NOSC * k] - (i == k)) <= 1e-9);
    }
    /* nearest 6.4: 6, 7 (0.6 away) and 5 (1.4), not 8 (1.6); ascending */
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 6.4, 3, w2, NULL), GA_OK);
    for (int k = 0; k < 3; ++k)
        assert_true(fabs(w2[k] - (5.0 + k)) <= 1e-9 * 7.0);
    /* all of them, and a shift above them all */
    double all[NOSC];
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 100.0, NOSC, all, NULL), GA_OK);
    for (int k = 0; k < NOSC; ++k)
        assert_true(fabs(all[k] - (k + 1.0)) <= 1e-9 * NOSC);
    /* the shift an eigenvalue: K - sigma M singular, named */
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 2.0, 1, w2, NULL), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "sigma is an eigenvalue"));
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, NOSC + 1, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "12 degrees of freedom"));
    ga_free(s);
}

static void test_refusals_leave_the_solver_as_it_was(void **state)
{
    (void)state;
    Osc o = {1.0, 0.0, 0, 0};
    ga_solver *s = osc_solver(&o);
    double q0[NOSC], v0[NOSC] = {0};
    for (int i = 0; i < NOSC; ++i)
        q0[i] = 0.01 * (i + 1);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    for (int i = 0; i < 5; ++i)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *before = malloc(len * sizeof(double)), *after = malloc(len * sizeof(double));
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    double q[NOSC] = {0}, w2[NOSC], keep[NOSC];
    for (int i = 0; i < NOSC; ++i)
        w2[i] = keep[i] = -3.0;
    /* arguments */
    assert_int_equal(ga_modes_near(s, 0.0, NULL, NULL, 0.0, 1, w2, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 1, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 0, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "count = 0"));
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, NAN, 1, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "sigma = nan"));
    assert_int_equal(ga_modes_near(s, INFINITY, q, NULL, 0.0, 1, w2, NULL), GA_ERR_ARG);
    double nan_q[NOSC] = {NAN};
    assert_int_equal(ga_modes_near(s, 0.0, nan_q, NULL, 0.0, 1, w2, NULL), GA_ERR_ARG);
    /* not an equilibrium */
    assert_int_equal(ga_modes_near(s, 0.0, q0, NULL, 0.0, 1, w2, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "not an equilibrium"));
    /* a non-conservative force */
    o.circulate = 0.5;
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 2, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "not symmetric"));
    o.circulate = 0.0;
    /* a mass that is not positive */
    o.mass = -1.0;
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 2, w2, NULL), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "not positive definite"));
    o.mass = 1.0;
    /* statics: no root anywhere, nothing restrains */
    o.no_root = 1;
    double q_nr[NOSC];
    for (int i = 0; i < NOSC; ++i)
        q_nr[i] = 0.25;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q_nr, NULL, 1e-12, 50), GA_ERR_NEWTON);
    assert_non_null(strstr(ga_last_error(s), "no equilibrium"));
    for (int i = 0; i < NOSC; ++i)
        assert_true(q_nr[i] == 0.25);
    o.no_root = 0;
    o.zero_k = 1;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 50), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "singular"));
    o.zero_k = 0;
    for (int i = 0; i < NOSC; ++i) {
        assert_true(q[i] == 0.0);
        assert_true(w2[i] == keep[i]);
    }
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_memory_equal(before, after, len * sizeof(double));
    /* and it steps on as a twin that was never asked */
    ga_solver *twin = osc_solver(&o);
    assert_int_equal(ga_init(twin, 0.0, q0, v0), GA_OK);
    for (int i = 0; i < 5; ++i)
        assert_int_equal(ga_step(twin, 1e-2), GA_OK);
    for (int i = 0; i < 5; ++i) {
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
        assert_int_equal(ga_step(twin, 1e-2), GA_OK);
    }
    double a[NOSC], b[NOSC];
    ga_get_q(s, a);
    ga_get_q(twin, b);
    assert_memory_equal(a, b, sizeof a);
    free(before);
    free(after);
    ga_free(twin);
    ga_free(s);
}

static void test_callback_errors_pass_through(void **state)
{
    (void)state;
    Pend p = {{1.3, 0.6}, {0.9, 1.4}, 0, 1};
    ga_solver *s = pend_solver(&p);
    double q[4] = {0.0, -0.9, 0.0, -2.3}, w = 0.0;
    assert_int_equal(ga_modes_near(s, 0.0, q, NULL, 0.0, 1, &w, NULL), GA_ERR_CALLBACK);
    assert_non_null(strstr(ga_last_error(s), "force"));
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 50), GA_ERR_CALLBACK);
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lattice_sags_to_a_root_and_its_lowest_modes_equal_lapack),
        cmocka_unit_test(test_a_stiff_lattice_needs_load_steps),
        cmocka_unit_test(test_double_pendulum_on_the_sparse_path_in_closed_form),
        cmocka_unit_test(test_redundant_constraints_are_refused_on_the_sparse_path),
        cmocka_unit_test(test_modes_nearest_a_shift_are_the_nearest),
        cmocka_unit_test(test_refusals_leave_the_solver_as_it_was),
        cmocka_unit_test(test_callback_errors_pass_through),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
