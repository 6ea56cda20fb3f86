/* Consistent start (ga_init): qdd0 and lambda0 from the saddle-point system, projection of
 * inconsistent q0 and v0 onto the constraints (minimum-norm corrections), and the finite-
 * difference constraint acceleration term, including a time-dependent (rheonomic) constraint.
 * Oracles: closed-form pendulum relations and the geometry of the circle. */
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

static ga_solver *make(pendulum *p, int with_accel_callback)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, p),
                     GA_OK);
    if (with_accel_callback)
        assert_int_equal(ga_set_constraint_accel(s, pendulum_constraint_accel), GA_OK);
    return s;
}

/* At theta with rate omega: lambda = m (L^2 omega^2 - g y) / L^2 and the tangential
 * acceleration -g sin(theta), i.e. the qdd of pendulum_reference at t = 0. */
static void accelerations_and_multiplier_are_consistent(void **state)
{
    (void)state;
    pendulum p = {2.0, 1.5, 9.81};
    for (int cb = 0; cb < 2; ++cb) {
        ga_solver *s = make(&p, cb);
        double q[2], v[2], qdd[2], lambda, a[2];
        pendulum_state(&p, 0.8, -1.3, q, v);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        const pendulum_exact ex = pendulum_reference(&p, 0.8, -1.3, 0.0, 1);
        long long accel = 0;
        ga_get_counter(s, GA_COUNT_ACCEL_EVALS, &accel);
        assert_int_equal(accel, 1);
        ga_get_qdd(s, qdd);
        ga_get_lambda(s, &lambda);
        ga_get_a(s, a);
        const double tol = cb ? 1e-12 : 1e-7; /* finite differences: O(eps^(2/3)) */
        assert_true(max_abs_diff(qdd, ex.qdd, 2) < tol * 10.0);
        assert_true(fabs(lambda - ex.lambda) < tol * fabs(ex.lambda));
        assert_memory_equal(a, qdd, sizeof a); /* eq. (3): a_0 = qdd_0 */
        ga_free(s);
    }
}

/* Minimum-norm projection onto the circle x^2 + y^2 = L^2 is radial: q0 L / |q0|. The
 * velocity correction removes the radial component of v0. */
static void inconsistent_positions_and_velocities_are_projected(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = make(&p, 1);
    double q0[2] = {0.9, -0.7}, v0[2] = {0.4, 0.5}, q[2], v[2];
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    ga_get_q(s, q);
    ga_get_v(s, v);
    const double r = hypot(q0[0], q0[1]);
    const double expected_q[2] = {q0[0] / r, q0[1] / r};
    assert_true(max_abs_diff(q, expected_q, 2) < 1e-15);
    const double vr = v0[0] * expected_q[0] + v0[1] * expected_q[1];
    const double expected_v[2] = {v0[0] - vr * expected_q[0], v0[1] - vr * expected_q[1]};
    assert_true(max_abs_diff(v, expected_v, 2) < 1e-15);
    ga_free(s);
}

/* Within init_tol the given values are kept as they are, bit for bit. */
static void consistent_values_are_kept(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = make(&p, 1);
    double q0[2], v0[2], q[2], v[2];
    pendulum_state(&p, 0.3, 0.2, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    ga_get_q(s, q);
    ga_get_v(s, v);
    assert_memory_equal(q, q0, sizeof q);
    assert_memory_equal(v, v0, sizeof v);
    ga_free(s);
}

/* A failed re-initialization keeps the previous state. */
/* Unconstrained, with M declared diagonal: M qdd = f is solved by division, without the
 * saddle-point factorization (on the sparse path it had the pattern of the step's matrix, a
 * lattice's K_t and its fill). Oracle: qdd = f / M by hand, and the dense twin. */
typedef struct springs3 {
    double mass[4]; /* the values written, in the declared order: (0,0) (1,1) (2,2) (1,1) */
} springs3;
static const int kDiagRows[4] = {0, 1, 2, 1}, kKRows[7] = {0, 0, 1, 1, 1, 2, 2},
                 kKCols[7] = {0, 1, 0, 1, 2, 1, 2};
static int s3_mass_sparse(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q;
    memcpy(M, ((const springs3 *)u)->mass, sizeof(double) * 4);
    return 0;
}
static int s3_mass_dense(double t, const double *q, double *M, void *u)
{
    const double *m = ((const springs3 *)u)->mass;
    (void)t, (void)q;
    memset(M, 0, sizeof(double) * 9);
    M[0] = m[0], M[4] = m[1] + m[3], M[8] = m[2];
    return 0;
}
/* a chain of three unit springs fixed at both ends, plus constant loads */
static int s3_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -2.0 * q[0] + q[1] + 1.0;
    f[1] = q[0] - 2.0 * q[1] + q[2] - 2.0;
    f[2] = q[1] - 2.0 * q[2] + 8.0;
    return 0;
}
static int s3_stiffness_sparse(double t, const double *q, const double *v, const double *qdd,
                               const double *l, double *K, void *u)
{
    (void)t, (void)q, (void)v, (void)qdd, (void)l, (void)u;
    const double k[7] = {2, -1, -1, 2, -1, -1, 2}; /* K_t = -df/dq */
    memcpy(K, k, sizeof k);
    return 0;
}
static ga_solver *s3_solver(springs3 *m, int sparse)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(3, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, sparse ? s3_mass_sparse : s3_mass_dense, s3_force, NULL,
                                      NULL, m),
                     GA_OK);
    if (sparse) {
        assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 4, kDiagRows, kDiagRows), GA_OK);
        assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, 7, kKRows, kKCols), GA_OK);
        assert_int_equal(ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL), GA_OK);
        assert_int_equal(ga_set_tangents(s, s3_stiffness_sparse, NULL), GA_OK);
        assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    }
    return s;
}

static void unconstrained_diagonal_mass_needs_no_factorization(void **state)
{
    (void)state;
    springs3 m = {{2.0, 3.0, 4.0, 1.0}}; /* M = diag(2, 4, 4) */
    const double q0[3] = {0.5, -0.25, 1.0}, v0[3] = {0.0, 1.0, 0.0};
    /* f(q0) by hand: (-1 - 0.25 + 1, 0.5 + 0.5 + 1 - 2, -0.25 - 2 + 8) = (-0.25, 0, 5.75);
     * qdd0 = f / M */
    const double expected[3] = {-0.125, 0.0, 1.4375};
    ga_solver *s = s3_solver(&m, 1), *dense = s3_solver(&m, 0);
    if (ga_init(s, 0.0, q0, v0) != GA_OK)
        fail_msg("%s", ga_last_error(s));
    assert_int_equal(ga_init(dense, 0.0, q0, v0), GA_OK);
    double qdd[3], qdd_dense[3], q[3], q_dense[3];
    long long factorizations = -1;
    assert_int_equal(ga_get_qdd(s, qdd), GA_OK);
    assert_int_equal(ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &factorizations), GA_OK);
    assert_true(factorizations == 0);
    for (int i = 0; i < 3; ++i)
        assert_true(fabs(qdd[i] - expected[i]) <= 1e-15 * fabs(expected[i]));
    assert_int_equal(ga_get_qdd(dense, qdd_dense), GA_OK);
    for (int k = 0; k < 20; ++k) {
        assert_int_equal(ga_step(s, 0.05), GA_OK);
        assert_int_equal(ga_step(dense, 0.05), GA_OK);
    }
    ga_get_q(s, q);
    ga_get_q(dense, q_dense);
    for (int i = 0; i < 3; ++i) {
        assert_true(fabs(qdd_dense[i] - expected[i]) <= 1e-15 * fabs(expected[i]));
        assert_true(fabs(q[i] - q_dense[i]) <= 1e-12 * (1.0 + fabs(q_dense[i])));
    }

    /* a zero on the diagonal: refused by name, and the solver keeps the run it had */
    double t_before, q_before[3], qdd_before[3];
    ga_get_t(s, &t_before);
    ga_get_q(s, q_before);
    ga_get_qdd(s, qdd_before);
    m.mass[1] = 0.0, m.mass[3] = 0.0;
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_ERR_SINGULAR);
    assert_non_null(strstr(ga_last_error(s), "M[1][1]"));
    double t_after;
    ga_get_t(s, &t_after);
    ga_get_q(s, q);
    assert_true(t_after == t_before);
    assert_memory_equal(q, q_before, sizeof q);
    m.mass[1] = 3.0, m.mass[3] = 1.0; /* (consistent output is computed from the model) */
    assert_int_equal(ga_get_qdd(s, qdd), GA_OK);
    assert_memory_equal(qdd, qdd_before, sizeof qdd);
    ga_free(s);
    ga_free(dense);
}

static void failed_init_keeps_previous_state(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = make(&p, 1);
    double q0[2], v0[2], q[2], t;
    pendulum_state(&p, 0.3, 0.2, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    assert_int_equal(ga_set_init_mode(s, GA_INIT_REFUSE, 1e-10), GA_OK);
    double bad[2] = {3.0, 0.0};
    assert_int_equal(ga_init(s, 5.0, bad, v0), GA_ERR_INCONSISTENT);
    ga_get_t(s, &t);
    ga_get_q(s, q);
    assert_true(t == 0.01);
    assert_true(fabs(q[0] * q[0] + q[1] * q[1] - 1.0) < 1e-14);
    ga_free(s);
}

/* D7: a restart refused for its arguments (NaN in q0) dropped the kept iteration matrix and
 * the pivots before it looked at q0: the checkpoint differed right after the refusal, and the
 * run continued differed from an untouched twin's. Now both are the twin's, bit for bit. */
static void refused_restart_leaves_the_run_as_it_was(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = make(&p, 1), *twin = make(&p, 1);
    double q0[2], v0[2];
    pendulum_state(&p, 0.3, 0.2, q0, v0);
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    assert_int_equal(ga_init(twin, 0.0, q0, v0), GA_OK);
    for (int i = 0; i < 10; ++i) {
        assert_int_equal(ga_step(s, 0.01), GA_OK);
        assert_int_equal(ga_step(twin, 0.01), GA_OK);
    }
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *before = malloc(len * sizeof(double)), *after = malloc(len * sizeof(double));
    assert_non_null(before);
    assert_non_null(after);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    const double bad[2] = {NAN, 0.0};
    assert_int_equal(ga_init(s, 5.0, bad, v0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "NaN or Inf"));
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_memory_equal(before, after, len * sizeof(double));
    for (int i = 0; i < 10; ++i) {
        assert_int_equal(ga_step(s, 0.01), GA_OK);
        assert_int_equal(ga_step(twin, 0.01), GA_OK);
    }
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    assert_int_equal(ga_get_state(twin, after, len), GA_OK);
    assert_memory_equal(before, after, len * sizeof(double));
    free(before);
    free(after);
    ga_free(s);
    ga_free(twin);
}

/* Rheonomic pendulum: the rod length follows L(t) = L0 + A sin(w t).
 * Phi = (x^2 + y^2 - L(t)^2)/2, Phi_t = -L L', Phi_tt = -(L'^2 + L L''), Phi_qt = 0. */
typedef struct rheonomic {
    pendulum p;
    double L0, A, w;
} rheonomic;

static double rl(const rheonomic *r, double t, int d)
{
    const double s = sin(r->w * t), c = cos(r->w * t);
    return d == 0 ? r->L0 + r->A * s : d == 1 ? r->A * r->w * c : -r->A * r->w * r->w * s;
}
static int rh_constraint(double t, const double *q, double *phi, void *u)
{
    const rheonomic *r = u;
    const double L = rl(r, t, 0);
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - L * L);
    return 0;
}
static int rh_jacobian(double t, const double *q, double *J, void *u)
{
    return pendulum_jacobian(t, q, J, u);
}
static int rh_mass(double t, const double *q, double *M, void *u)
{
    return pendulum_mass(t, q, M, &((rheonomic *)u)->p);
}
static int rh_force(double t, const double *q, const double *v, double *f, void *u)
{
    return pendulum_force(t, q, v, f, &((rheonomic *)u)->p);
}
static int rh_accel(double t, const double *q, const double *v, double *out, void *u)
{
    const rheonomic *r = u;
    (void)q;
    const double L = rl(r, t, 0), Ld = rl(r, t, 1), Ldd = rl(r, t, 2);
    out[0] = v[0] * v[0] + v[1] * v[1] - (Ld * Ld + L * Ldd);
    return 0;
}

static int rh_dt(double t, const double *q, double *out, void *u)
{
    const rheonomic *r = u;
    (void)q;
    out[0] = -rl(r, t, 0) * rl(r, t, 1); /* Phi_t = -L L' */
    return 0;
}

static void time_dependent_constraint_start(void **state)
{
    (void)state;
    rheonomic r = {{1.0, 1.0, 9.81}, 1.0, 0.2, 3.0};
    const double t0 = 0.4;
    double results[3][5];
    for (int cb = 0; cb < 3; ++cb) {
        ga_solver *s = NULL;
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, rh_mass, rh_force, rh_constraint, rh_jacobian, &r),
                         GA_OK);
        if (cb)
            assert_int_equal(ga_set_constraint_accel(s, rh_accel), GA_OK);
        if (cb == 2)
            assert_int_equal(ga_set_constraint_dt(s, rh_dt), GA_OK);
        /* position on the circle of radius L(t0), velocity purely tangential: the projection
         * must add the radial rate L'(t0) (that is what Phi_t brings in) */
        const double L = rl(&r, t0, 0), th = 0.5;
        double q[2] = {L * sin(th), -L * cos(th)}, v[2] = {cos(th), sin(th)};
        assert_int_equal(ga_init(s, t0, q, v), GA_OK);
        ga_get_v(s, v);
        const double radial = (v[0] * q[0] + v[1] * q[1]) / L;
        /* Phi_t by extrapolated differences in t or exact */
        assert_true(fabs(radial - rl(&r, t0, 1)) < (cb == 2 ? 1e-14 : 1e-8));
        ga_get_qdd(s, results[cb]);
        ga_get_lambda(s, results[cb] + 2);
        ga_free(s);
    }
    /* finite-difference term (nested differences in t) against the analytic callback */
    assert_true(fabs(results[0][2] - results[1][2]) < 1e-6 * fabs(results[1][2]));
    assert_true(max_abs_diff(results[0], results[1], 2) < 1e-5);
    assert_true(max_abs_diff(results[2], results[1], 2) < 1e-8);
}

/* The stabilized index-2 formulation keeps Phi_q v + Phi_t = 0 at every step; with an exact
 * Phi_t callback to round-off against the exact Phi_t, with extrapolated differences to their
 * error (~ eps |Phi| / d, d = 2^-13), and the callback spares the four constraint calls per
 * Newton iteration that the differences cost. */
static void index2_velocity_constraint_with_exact_phi_t(void **state)
{
    (void)state;
    rheonomic r = {{1.0, 1.0, 9.81}, 1.0, 0.2, 3.0};
    const double t0 = 0.4, h = 1e-3;
    double worst[2] = {0.0, 0.0}, qs[2][2];
    long long cons[2], res[2], dt[2];
    for (int cb = 0; cb < 2; ++cb) {
        ga_solver *s = NULL;
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, rh_mass, rh_force, rh_constraint, rh_jacobian, &r),
                         GA_OK);
        assert_int_equal(ga_set_constraint_accel(s, rh_accel), GA_OK);
        if (cb)
            assert_int_equal(ga_set_constraint_dt(s, rh_dt), GA_OK);
        assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
        assert_int_equal(ga_set_newton(s, 1e-12, 20), GA_OK);
        const double L = rl(&r, t0, 0), th = 0.5;
        double q[2] = {L * sin(th), -L * cos(th)}, v[2] = {cos(th), sin(th)}, t = t0;
        assert_int_equal(ga_init(s, t0, q, v), GA_OK);
        for (int k = 0; k < 500; ++k) {
            assert_int_equal(ga_step(s, h), GA_OK);
            ga_get_t(s, &t);
            ga_get_q(s, q);
            ga_get_v(s, v);
            const double velocity_constraint =
                q[0] * v[0] + q[1] * v[1] - rl(&r, t, 0) * rl(&r, t, 1);
            worst[cb] = fmax(worst[cb], fabs(velocity_constraint));
        }
        qs[cb][0] = q[0];
        qs[cb][1] = q[1];
        ga_get_counter(s, GA_COUNT_CONSTRAINT_EVALS, &cons[cb]);
        ga_get_counter(s, GA_COUNT_RESIDUALS, &res[cb]);
        ga_get_counter(s, GA_COUNT_CONSTRAINT_DT_EVALS, &dt[cb]);
        ga_free(s);
    }
    printf("  max |Phi_q v + Phi_t| over 500 index-2 steps: %.1e with differences in t, "
           "%.1e with the callback; constraint calls %lld against %lld (%lld Phi_t "
           "evaluations)\n",
           worst[0], worst[1], cons[0], cons[1], dt[1]);
    assert_true(worst[1] < 1e-13);
    /* extrapolated differences: 4.0e-12 (a single central difference: 5.9e-11) */
    assert_true(worst[0] < 1e-11);
    assert_true(max_abs_diff(qs[0], qs[1], 2) < 1e-8);
    assert_true(dt[1] >= res[1]); /* one Phi_t per Newton iteration, and the start's */
    /* the differences' calls are the whole difference */
    assert_true(cons[0] - 4 * dt[0] - res[0] == cons[1] - res[1]);
}

/* A first start that fails -- a refused argument, a singular start, a refused checkpoint --
 * leaves the solver as it was: not set up, so that what set-up fixes can still be declared
 * (they were refused "after the solver was set up"), and the run that follows is that of a
 * solver that never made the failed call, bit for bit. */
static int zero_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                     void *user)
{
    (void)t, (void)q, (void)v, (void)user;
    ydot[0] = -y[0];
    return 0;
}
static int force_y(double t, const double *q, const double *v, const double *y, double *f,
                   void *user)
{
    (void)y;
    return pendulum_force(t, q, v, f, user);
}
static int massless(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    memset(M, 0, 4 * sizeof(double));
    return 0;
}
static void failed_first_start_leaves_the_setup_open(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2], bad[2], y0 = 0.5, nan_y = NAN, end[2][2];
    pendulum_state(&p, 0.6, 0.2, q, v);
    bad[0] = NAN, bad[1] = q[1];
    for (int run = 0; run < 2; ++run) {
        ga_solver *s = make(&p, 0);
        assert_int_equal(ga_set_first_order(s, 1, force_y, zero_rate), GA_OK);
        if (run == 1) {
            assert_int_equal(ga_init_y(s, 0.0, bad, v, &y0), GA_ERR_ARG);
            assert_int_equal(ga_init_y(s, 0.0, q, v, &nan_y), GA_ERR_ARG);
            assert_non_null(strstr(ga_last_error(s), "y0"));
            /* a singular start */
            assert_int_equal(ga_set_callbacks(s, massless, pendulum_force, pendulum_constraint,
                                              pendulum_jacobian, &p),
                             GA_OK);
            assert_int_equal(ga_init_y(s, 0.0, q, v, &y0), GA_ERR_SINGULAR);
            assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force,
                                              pendulum_constraint, pendulum_jacobian, &p),
                             GA_OK);
            /* a checkpoint refused after set-up (pivots of a sparse LU that is not there) */
            size_t len = 0;
            assert_int_equal(ga_state_size(s, &len), GA_OK);
            double ckpt[256] = {0};
            assert_true(len <= 256);
            {
                ga_solver *other = make(&p, 0);
                assert_int_equal(ga_set_first_order(other, 1, force_y, zero_rate), GA_OK);
                assert_int_equal(ga_init_y(other, 0.0, q, v, &y0), GA_OK);
                assert_int_equal(ga_get_state(other, ckpt, len), GA_OK);
                ga_free(other);
            }
            /* the first pivot block (layout 4: after 21 + 7 n + m header and state entries,
             * 4 n + m of the kept matrix, m flags): its "kept" flag neither 0 nor 1, found
             * only once the solver is set up */
            ckpt[21 + 7 * 2 + 1 + 4 * 2 + 1 + 1] = 0.5;
            assert_int_equal(ga_set_state(s, ckpt, len), GA_ERR_ARG);
            assert_non_null(strstr(ga_last_error(s), "pivots"));
            /* what set-up fixes is open still */
            assert_int_equal(ga_set_first_order(s, 1, force_y, zero_rate), GA_OK);
            assert_int_equal(ga_set_redundant_constraints(s, GA_REDUNDANT_REFUSE), GA_OK);
            assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_AUTO), GA_OK);
            const int rows[1] = {0}, cols[1] = {0};
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_V, 0, rows, cols),
                             GA_OK);
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_Q, 0, rows, cols),
                             GA_OK);
        } else {
            const int rows[1] = {0}, cols[1] = {0};
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_V, 0, rows, cols),
                             GA_OK);
            assert_int_equal(ga_set_coupling_pattern(s, GA_COUPLING_G_Q, 0, rows, cols),
                             GA_OK);
        }
        assert_int_equal(ga_init_y(s, 0.0, q, v, &y0), GA_OK);
        for (int k = 0; k < 20; ++k)
            assert_int_equal(ga_step(s, 1e-2), GA_OK);
        assert_int_equal(ga_get_q(s, end[run]), GA_OK);
        /* set up now: fixed */
        assert_int_equal(ga_set_first_order(s, 1, force_y, zero_rate), GA_ERR_STATE);
        ga_free(s);
    }
    assert_memory_equal(end[0], end[1], sizeof end[0]);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(accelerations_and_multiplier_are_consistent),
        cmocka_unit_test(inconsistent_positions_and_velocities_are_projected),
        cmocka_unit_test(consistent_values_are_kept),
        cmocka_unit_test(failed_init_keeps_previous_state),
        cmocka_unit_test(refused_restart_leaves_the_run_as_it_was),
        cmocka_unit_test(failed_first_start_leaves_the_setup_open),
        cmocka_unit_test(unconstrained_diagonal_mass_needs_no_factorization),
        cmocka_unit_test(time_dependent_constraint_start),
        cmocka_unit_test(index2_velocity_constraint_with_exact_phi_t),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
