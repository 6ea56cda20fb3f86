/* First-order states y' = g(t, q, v, y) in the same solve (issue 19, docs/algorithms.md sec. 9):
 * the stiff limit measured by stepping galpha, order 2 in every quantity against an exact
 * solution (a matrix exponential computed here), Newton with and without the coupling blocks,
 * restart and checkpoints, and the API's refusals. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>

#include <cmocka.h>

#include "helpers.h"

/* ---- a scalar stiff state beside a trivial mechanism: x'' = -x, y' = mu y ---- */
static double g_mu;
static int one_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}
static int spring_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -q[0];
    return 0;
}
static int linear_rate(double t, const double *q, const double *v, const double *y,
                       double *ydot, void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    ydot[0] = g_mu * y[0];
    return 0;
}

/* On y' = mu y with h mu -> -infinity, y vanishes against y' and (y', w) follow a two-term
 * recursion whose roots are the method's at infinity. They are measured from four consecutive
 * y'_n by fitting y'_{n+2} = s y'_{n+1} - p y'_n (s, p: sum and product of the roots); with
 * rho_inf = 0 both roots are 0, and y' vanishes after two steps. */
static void stiff_limit_roots(double rho, double *root_modulus)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, one_mass, spring_force, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, 1, NULL, linear_rate), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, rho), GA_OK);
    assert_int_equal(ga_set_corrected_start(s, 0), GA_OK); /* w_0 = y'_0 */
    const double h = 0.1, q0 = 1.0, v0 = 0.0, y0 = 1.0;
    g_mu = -1e12 / h;
    assert_int_equal(ga_init_y(s, 0.0, &q0, &v0, &y0), GA_OK);
    double yd[8];
    assert_int_equal(ga_get_y(s, NULL, &yd[0]), GA_OK);
    for (int k = 1; k < 8; ++k) {
        assert_int_equal(ga_step(s, h), GA_OK);
        assert_int_equal(ga_get_y(s, NULL, &yd[k]), GA_OK);
    }
    if (rho == 0.0) {
        for (int k = 2; k < 8; ++k)
            assert_true(fabs(yd[k]) <= 1e-9 * fabs(yd[0]));
        *root_modulus = 0.0;
    } else {
        /* y'_{n+2} = sum y'_{n+1} - prod y'_n at n = 2 and 3 */
        const double a11 = yd[3], a12 = -yd[2], b1 = yd[4];
        const double a21 = yd[4], a22 = -yd[3], b2 = yd[5];
        const double det = a11 * a22 - a12 * a21;
        if (fabs(det) <= 1e-9 * (fabs(a11 * a22) + fabs(a12 * a21))) {
            /* y'_n geometric (the start did not excite the second mode): one root */
            const double root = yd[5] / yd[4];
            assert_true(fabs(root + rho) < 1e-6);
            assert_true(fabs(yd[4] / yd[3] - root) < 1e-9);
            *root_modulus = fabs(root);
            ga_free(s);
            return;
        }
        const double sum = (b1 * a22 - a12 * b2) / det, prod = (a11 * b2 - b1 * a21) / det;
        const double disc = sum * sum - 4.0 * prod;
        /* a double root -rho: sum = -2 rho, prod = rho^2, disc = 0 up to the fit's noise */
        assert_true(fabs(sum + 2.0 * rho) < 1e-6);
        assert_true(fabs(prod - rho * rho) < 1e-6);
        *root_modulus = disc >= 0 ? fmax(fabs(0.5 * (sum + sqrt(disc))),
                                         fabs(0.5 * (sum - sqrt(disc))))
                                  : sqrt(prod);
    }
    ga_free(s);
}

static void stiff_limit_has_spectral_radius_rho_inf(void **state)
{
    (void)state;
    const double rhos[] = {0.0, 0.5, 0.9, 1.0};
    for (int k = 0; k < 4; ++k) {
        double radius = -1.0;
        stiff_limit_roots(rhos[k], &radius);
        print_message("rho_inf %.1f: measured spectral radius at h mu = -1e12: %.9f\n", rhos[k],
                      radius);
        assert_true(fabs(radius - rhos[k]) < 1e-6);
    }
}

#include "electromech.h"

static ga_solver *em_solver(int formulation, int output, int exact_coupling, int with_callback)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, em_mass, NULL, em_constraint, em_jacobian, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, EM_R, em_force, em_rate), GA_OK);
    if (with_callback)
        assert_int_equal(ga_set_coupling(s, em_coupling), GA_OK);
    assert_int_equal(ga_set_coupling_exact(s, exact_coupling), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_output(s, output), GA_OK);
    const double q0[EM_N] = {0, 0}, v0[EM_N] = {0, 0}, y0[EM_R] = {0, 0};
    assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
    return s;
}

enum { kQ, kV, kA, kL, kY, kYD, kQuantities };
static const char *const kNames[kQuantities] = {"q", "v", "qdd", "lambda", "y", "y'"};

/* Errors at T = 1 of every quantity with N steps. */
static void em_errors(int formulation, int output, int N, double err[kQuantities])
{
    const double T = 1.0;
    ga_solver *s = em_solver(formulation, output, 1, 0);
    for (int k = 0; k < N; ++k)
        assert_int_equal(ga_step(s, T / N), GA_OK);
    double q[EM_N], v[EM_N], qdd[EM_N], lambda, y[EM_R], yd[EM_R];
    assert_int_equal(ga_get_q(s, q), GA_OK);
    assert_int_equal(ga_get_v(s, v), GA_OK);
    assert_int_equal(ga_get_qdd(s, qdd), GA_OK);
    assert_int_equal(ga_get_lambda(s, &lambda), GA_OK);
    assert_int_equal(ga_get_y(s, y, yd), GA_OK);
    const em_exact e = em_reference(T);
    err[kQ] = fmax(fabs(q[0] - e.x), fabs(q[1] - e.x));
    err[kV] = fmax(fabs(v[0] - e.v), fabs(v[1] - e.v));
    err[kA] = fmax(fabs(qdd[0] - e.a), fabs(qdd[1] - e.a));
    err[kL] = fabs(lambda - e.lambda);
    err[kY] = fmax(fabs(y[0] - e.i), fabs(y[1] - e.z));
    err[kYD] = fmax(fabs(yd[0] - e.idot), fabs(yd[1] - e.zdot));
    ga_free(s);
}

static void order_two_in_every_quantity(void **state)
{
    (void)state;
    const int steps[] = {200, 400, 800, 1600};
    const struct {
        int formulation, output;
        const char *name;
    } cases[] = {{GA_INDEX3, GA_OUTPUT_CONSISTENT, "index 3"},
                 {GA_INDEX3, GA_OUTPUT_STEP, "index 3, the step's own qdd, lambda"},
                 {GA_INDEX2_STABILIZED, GA_OUTPUT_CONSISTENT, "index 2"},
                 {GA_INDEX2_STABILIZED, GA_OUTPUT_STEP, "index 2, the step's own qdd, lambda"}};
    for (int c = 0; c < 4; ++c) {
        double h[4], e[kQuantities][4];
        for (int k = 0; k < 4; ++k) {
            double err[kQuantities];
            em_errors(cases[c].formulation, cases[c].output, steps[k], err);
            h[k] = 1.0 / steps[k];
            for (int j = 0; j < kQuantities; ++j)
                e[j][k] = err[j];
        }
        for (int j = 0; j < kQuantities; ++j) {
            const double p = fit_order(h, e[j], 4);
            print_message("%-36s %-7s errors %.2e ... %.2e  order %.3f\n", cases[c].name,
                          kNames[j], e[j][0], e[j][3], p);
            assert_true(p > 1.9 && p < 2.1);
        }
    }
}

/* Full Newton (a matrix at every iteration, tangents K_t, C_t by differences) with the exact
 * coupling blocks solves this linear model in one update per step (the second confirms it);
 * without g_q, g_v, f_y in the matrix the iteration only contracts. Finite differences and the
 * callback agree. */
static long long em_newton_iterations(int exact, int with_callback)
{
    ga_solver *s = em_solver(GA_INDEX3, GA_OUTPUT_CONSISTENT, exact, with_callback);
    assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
    assert_int_equal(ga_reset_counters(s), GA_OK);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(s, 0.01), GA_OK);
    long long iters = 0;
    assert_int_equal(ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters), GA_OK);
    ga_free(s);
    return iters;
}

static void exact_coupling_converges_in_one_update(void **state)
{
    (void)state;
    const long long fd = em_newton_iterations(1, 0), cb = em_newton_iterations(1, 1),
                    loose = em_newton_iterations(0, 1);
    print_message("Newton iterations over 100 steps: exact coupling %lld (differences), %lld "
                  "(callback); without the coupling blocks %lld\n",
                  fd, cb, loose);
    /* two updates per step with the callback; differences of the blocks (errors ~ sqrt(eps))
     * leave r^y at ~1e-7 after the first update, and a few steps take a third */
    assert_true(cb <= 200);
    assert_true(fd <= 220);
    assert_true(loose > 3 * cb);
}

static void checkpoint_continues_bit_for_bit(void **state)
{
    (void)state;
    ga_solver *a = em_solver(GA_INDEX2_STABILIZED, GA_OUTPUT_CONSISTENT, 1, 0);
    for (int k = 0; k < 10; ++k)
        assert_int_equal(ga_step(a, 0.01), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(a, &len), GA_OK);
    double *buf = malloc(len * sizeof(double));
    assert_non_null(buf);
    assert_int_equal(ga_get_state(a, buf, len), GA_OK);
    ga_solver *b = NULL;
    assert_int_equal(ga_create(EM_N, EM_M, &b), GA_OK);
    assert_int_equal(ga_set_callbacks(b, em_mass, NULL, em_constraint, em_jacobian, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(b, EM_R, em_force, em_rate), GA_OK);
    assert_int_equal(ga_set_formulation(b, GA_INDEX2_STABILIZED), GA_OK);
    assert_int_equal(ga_set_state(b, buf, len), GA_OK);
    /* a checkpoint of a solver without first-order states does not fit */
    ga_solver *plain = NULL;
    assert_int_equal(ga_create(EM_N, EM_M, &plain), GA_OK);
    assert_int_equal(ga_set_callbacks(plain, em_mass, NULL, em_constraint, em_jacobian, NULL),
                     GA_OK);
    assert_int_equal(ga_set_state(plain, buf, len), GA_ERR_ARG);
    ga_free(plain);
    for (int k = 0; k < 20; ++k) {
        assert_int_equal(ga_step(a, 0.01), GA_OK);
        assert_int_equal(ga_step(b, 0.01), GA_OK);
    }
    double ya[EM_R], yb[EM_R], qa[EM_N], qb[EM_N];
    assert_int_equal(ga_get_y(a, ya, NULL), GA_OK);
    assert_int_equal(ga_get_y(b, yb, NULL), GA_OK);
    assert_int_equal(ga_get_q(a, qa), GA_OK);
    assert_int_equal(ga_get_q(b, qb), GA_OK);
    assert_memory_equal(ya, yb, sizeof ya);
    assert_memory_equal(qa, qb, sizeof qa);
    free(buf);
    ga_free(a);
    ga_free(b);
}

/* After short (Taylor) steps, adaptive steps from the live solver and from its checkpoint
 * agree bit for bit (found by the random call sequences: the error estimate of y after a
 * Taylor step read the w of the first step's corrected start). Two free particles, a force y on
 * the first, y' = v_0 - y: the sequence the fuzzer built. */
static int particle_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    memset(M, 0, 16 * sizeof(double));
    for (int i = 0; i < 4; ++i)
        M[5 * i] = 1.0;
    return 0;
}
static int particle_force(double t, const double *q, const double *v, const double *y, double *f,
                          void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    for (int i = 0; i < 4; ++i)
        f[i] = i % 2 ? -9.81 : 0.0;
    f[0] += y[0];
    return 0;
}
static int particle_rate(double t, const double *q, const double *v, const double *y,
                         double *ydot, void *u)
{
    (void)t, (void)q, (void)u;
    ydot[0] = v[0] - y[0];
    return 0;
}

static void adaptive_after_short_steps_repeats_from_a_checkpoint(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(4, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, particle_mass, NULL, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, 1, particle_force, particle_rate), GA_OK);
    const double q0[4] = {0.5, -0.8, 1.5, -0.8}, v0[4] = {0.0}, y0[1] = {0.3};
    assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
    assert_int_equal(ga_step(s, 1000.0), GA_OK);
    assert_int_equal(ga_step(s, 1.0), GA_OK); /* Taylor steps: over 100 times shorter */
    assert_int_equal(ga_step(s, 1e-4), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *ckpt = malloc(3 * len * sizeof(double));
    assert_non_null(ckpt);
    double *end[2] = {ckpt + len, ckpt + 2 * len};
    assert_int_equal(ga_get_state(s, ckpt, len), GA_OK);
    for (int run = 0; run < 2; ++run) {
        if (run == 1)
            assert_int_equal(ga_set_state(s, ckpt, len), GA_OK);
        double t = 0.0;
        ga_get_t(s, &t);
        assert_int_equal(ga_step_adaptive(s, t + 1e-3), GA_OK);
        ga_get_t(s, &t);
        assert_int_equal(ga_step_adaptive(s, t + 1e-2), GA_OK);
        assert_int_equal(ga_get_state(s, end[run], len), GA_OK);
    }
    assert_memory_equal(end[0], end[1], len * sizeof(double));
    free(ckpt);
    ga_free(s);
}

/* Dense output of y against the exact solution inside a step: third-order local accuracy of
 * the cubic Hermite, so at h = 1e-2 its error is the step's own (order 2) and no larger. */
static void dense_output_of_y(void **state)
{
    (void)state;
    ga_solver *s = em_solver(GA_INDEX3, GA_OUTPUT_CONSISTENT, 1, 0);
    const int N = 100;
    double worst = 0.0;
    for (int k = 0; k < N; ++k) {
        assert_int_equal(ga_step(s, 1.0 / N), GA_OK);
        for (int j = 1; j < 4; ++j) {
            const double t = (k + 0.25 * j) / N;
            double y[EM_R], yd[EM_R];
            assert_int_equal(ga_interpolate_y(s, t, y, yd), GA_OK);
            const em_exact e = em_reference(t);
            worst = fmax(worst, fabs(y[0] - e.i) / 3.0);  /* |i| up to about 3 */
        }
    }
    double y[EM_R];
    assert_int_equal(ga_interpolate_y(s, 2.0, y, NULL), GA_ERR_ARG);
    print_message("dense output of the current, h = 1e-2: largest error %.2e\n", worst * 3.0);
    double err[kQuantities];
    em_errors(GA_INDEX3, GA_OUTPUT_CONSISTENT, N, err);
    assert_true(worst * 3.0 < 3.0 * err[kY] + 1e-3);
    ga_free(s);
}

/* Adaptive steps: the global error of q, v, y and y' at T = 1 follows the tolerance (log-log
 * slope in [0.85, 1.15] over rtol = atol = 1e-3 ... 1e-7, error / tol within a band of 30),
 * y in the error estimate (first_order.cpp), both formulations. */
static void adaptive_error_follows_the_tolerance(void **state)
{
    (void)state;
    const double tols[5] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double e[4][5];
        for (int k = 0; k < 5; ++k) {
            ga_solver *s = NULL;
            assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
            assert_int_equal(ga_set_callbacks(s, em_mass, NULL, em_constraint, em_jacobian, NULL),
                             GA_OK);
            assert_int_equal(ga_set_first_order(s, EM_R, em_force, em_rate), GA_OK);
            assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
            assert_int_equal(ga_set_tolerances(s, tols[k], tols[k]), GA_OK);
            const double q0[EM_N] = {0, 0}, v0[EM_N] = {0, 0}, y0[EM_R] = {0, 0};
            assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
            assert_int_equal(ga_advance(s, 1.0), GA_OK);
            double q[EM_N], v[EM_N], y[EM_R], yd[EM_R];
            assert_int_equal(ga_get_q(s, q), GA_OK);
            assert_int_equal(ga_get_v(s, v), GA_OK);
            assert_int_equal(ga_get_y(s, y, yd), GA_OK);
            const em_exact x = em_reference(1.0);
            /* relative to each quantity's size over the run (|x| < 1.1, |v| < 4, |i| < 30,
             * |i'| < 600) */
            e[0][k] = fabs(q[0] - x.x) / 1.1;
            e[1][k] = fabs(v[0] - x.v) / 4.0;
            e[2][k] = fmax(fabs(y[0] - x.i) / 30.0, fabs(y[1] - x.z));
            e[3][k] = fmax(fabs(yd[0] - x.idot) / 600.0, fabs(yd[1] - x.zdot));
            ga_free(s);
        }
        const char *names[4] = {"q", "v", "y", "y'"};
        for (int j = 0; j < 4; ++j) {
            const double slope = fit_order(tols, e[j], 5);
            double lo = INFINITY, hi = 0.0;
            for (int k = 0; k < 5; ++k) {
                lo = fmin(lo, e[j][k] / tols[k]);
                hi = fmax(hi, e[j][k] / tols[k]);
            }
            print_message("%s adaptive %-3s error/tol %.2f ... %.2f, slope %.3f\n",
                          formulation == GA_INDEX3 ? "index 3" : "index 2", names[j], lo, hi,
                          slope);
            assert_true(slope > 0.85 && slope < 1.15);
            assert_true(hi / lo <= 30.0);
        }
    }
}

/* Events on the first-order states (ga_set_events_y): the current reaches 20 A (rising) at a
 * time found by bisection on the exact solution; located on the dense output, the error
 * shrinks at order 2 with h. */
static int current_limit(double t, const double *q, const double *v, const double *y,
                         const double *lambda, double *g, void *u)
{
    (void)t, (void)q, (void)v, (void)lambda, (void)u;
    g[0] = y[0] - 20.0;
    return 0;
}

static void events_on_the_states(void **state)
{
    (void)state;
    double lo = 0.0, hi = 0.095; /* i(0) = 0 < 20, i(0.095) = 24.9 > 20 */
    assert_true(em_reference(hi).i > 20.0);
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (em_reference(mid).i < 20.0)
            lo = mid;
        else
            hi = mid;
    }
    const double t_exact = 0.5 * (lo + hi);
    const int steps[3] = {200, 400, 800};
    double h[3], e[3];
    for (int k = 0; k < 3; ++k) {
        ga_solver *s = em_solver(GA_INDEX3, GA_OUTPUT_CONSISTENT, 1, 0);
        const int rising = GA_EVENT_RISING;
        assert_int_equal(ga_set_events_y(s, 1, current_limit, &rising, NULL, 0), GA_OK);
        ga_status st = GA_OK;
        int taken = 0;
        while (st == GA_OK && taken < steps[k]) {
            st = ga_step(s, 1.0 / steps[k]);
            ++taken;
        }
        assert_int_equal(st, GA_EVENT);
        double te = 0.0, y[EM_R];
        assert_int_equal(ga_get_event(s, 0, &te, NULL, NULL), GA_OK);
        assert_int_equal(ga_interpolate_y(s, te, y, NULL), GA_OK);
        assert_true(fabs(y[0] - 20.0) < 1e-9);
        h[k] = 1.0 / steps[k];
        e[k] = fabs(te - t_exact);
        ga_free(s);
    }
    const double p = fit_order(h, e, 3);
    print_message("current reaches 20 A at t = %.9f; errors %.2e %.2e %.2e, order %.2f\n",
                  t_exact, e[0], e[1], e[2], p);
    assert_true(p > 1.8 && p < 2.2);

    /* functions of y need the states declared first, and then fix them */
    ga_solver *s = NULL;
    assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, em_mass, NULL, em_constraint, em_jacobian, NULL), GA_OK);
    assert_int_equal(ga_set_events_y(s, 1, current_limit, NULL, NULL, 0), GA_ERR_STATE);
    assert_int_equal(ga_set_first_order(s, EM_R, em_force, em_rate), GA_OK);
    assert_int_equal(ga_set_events_y(s, 1, current_limit, NULL, NULL, 0), GA_OK);
    assert_int_equal(ga_set_first_order(s, 1, em_force, em_rate), GA_ERR_STATE);
    ga_free(s);
}

/* ---- what the API refuses, and failures that leave the solver as it was ---- */
static int g_fail_rate_after, g_always_fail;
static int failing_rate(double t, const double *q, const double *v, const double *y,
                        double *ydot, void *u)
{
    if (g_always_fail || g_fail_rate_after-- == 0)
        return 1;
    return em_rate(t, q, v, y, ydot, u);
}

static void refusals_and_failures(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, em_mass, NULL, em_constraint, em_jacobian, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, -1, NULL, em_rate), GA_ERR_ARG);
    assert_int_equal(ga_set_first_order(s, 2, em_force, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "rate"));
    assert_int_equal(ga_set_first_order(s, EM_R, em_force, failing_rate), GA_OK);
    const double q0[EM_N] = {0, 0}, v0[EM_N] = {0, 0}, y0[EM_R] = {0, 0};
    const double bad[EM_R] = {0, NAN};
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_ERR_STATE); /* y0 never given */
    assert_non_null(strstr(ga_last_error(s), "ga_init_y"));
    assert_int_equal(ga_init_y(s, 0.0, q0, v0, NULL), GA_ERR_ARG);
    assert_int_equal(ga_init_y(s, 0.0, q0, v0, bad), GA_ERR_ARG);
    g_fail_rate_after = 1000000;
    assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
    assert_int_equal(ga_set_first_order(s, 1, em_force, em_rate), GA_ERR_STATE);
    for (int k = 0; k < 5; ++k)
        assert_int_equal(ga_step(s, 0.01), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *before = malloc(len * sizeof(double)), *after = malloc(len * sizeof(double));
    assert_non_null(before);
    assert_non_null(after);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    g_fail_rate_after = 0;
    assert_int_equal(ga_step(s, 0.01), GA_ERR_CALLBACK_RETRY);
    assert_non_null(strstr(ga_last_error(s), "rate"));
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_true(ckpt_same_state(before, after));
    assert_memory_equal(before + len - 6 * EM_R, after + len - 6 * EM_R, 4 * EM_R * sizeof(double));
    g_fail_rate_after = 1000000;
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    /* a rate that keeps failing in adaptive steps: the steps shrink below h_min, and the
     * status says which callback made them (it said "step size fell below the minimum" only) */
    assert_int_equal(ga_set_step_limits(s, 1e-4, 0.0), GA_OK);
    {
        ga_status st = GA_OK;
        double t_before, t_after;
        assert_int_equal(ga_get_t(s, &t_before), GA_OK);
        g_always_fail = 1;
        st = ga_step_adaptive(s, 1.0);
        g_always_fail = 0;
        assert_int_equal(st, GA_ERR_STEP_SIZE);
        assert_non_null(strstr(ga_last_error(s), "fell below the minimum"));
        assert_non_null(strstr(ga_last_error(s), "the last attempt failed: rate callback "
                                                 "returned 1 (recoverable)"));
        assert_int_equal(ga_get_t(s, &t_after), GA_OK);
        assert_true(t_after == t_before);
        g_fail_rate_after = 1000000;
    }
    /* a restart by ga_init keeps the states it holds */
    double y_now[EM_R], y_restart[EM_R];
    assert_int_equal(ga_get_y(s, y_now, NULL), GA_OK);
    assert_int_equal(ga_init(s, 0.06, q0, v0), GA_OK);
    assert_int_equal(ga_get_y(s, y_restart, NULL), GA_OK);
    assert_memory_equal(y_now, y_restart, sizeof y_now);
    free(before);
    free(after);
    ga_free(s);
}

/* The sparse path (declared patterns, KLU) gives the dense path's solution: the first-order
 * states leave the mechanical matrix as it is, in both formulations. */
static void sparse_path_gives_the_dense_solution(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double q[2][EM_N], l[2][EM_M], y[2][EM_R];
        for (int sparse = 0; sparse < 2; ++sparse) {
            ga_solver *s = NULL;
            assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
            if (sparse)
                assert_int_equal(em_declare_sparse(s), GA_OK);
            assert_int_equal(ga_set_callbacks(s, sparse ? em_mass_diag : em_mass, NULL,
                                              em_constraint,
                                              sparse ? em_jacobian_values : em_jacobian, NULL),
                             GA_OK);
            assert_int_equal(ga_set_first_order(s, EM_R, em_force, em_rate), GA_OK);
            assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
            assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
            const double q0[EM_N] = {0, 0}, v0[EM_N] = {0, 0}, y0[EM_R] = {0, 0};
            assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
            if (sparse)
                assert_non_null(strstr(ga_linear_solver_name(s), "sparse"));
            for (int k = 0; k < 200; ++k)
                assert_int_equal(ga_step(s, 5e-3), GA_OK);
            assert_int_equal(ga_get_q(s, q[sparse]), GA_OK);
            assert_int_equal(ga_get_lambda(s, l[sparse]), GA_OK);
            assert_int_equal(ga_get_y(s, y[sparse], NULL), GA_OK);
            ga_free(s);
        }
        const double dq = max_abs_diff(q[0], q[1], EM_N), dl = fabs(l[0][0] - l[1][0]),
                     dy = max_abs_diff(y[0], y[1], EM_R);
        print_message("%s: sparse against dense: q %.1e, lambda %.1e, y %.1e\n",
                      formulation == GA_INDEX3 ? "index 3" : "index 2", dq, dl, dy);
        assert_true(dq < 1e-12 && dl < 1e-10 && dy < 1e-10);
    }
}

/* ---- a stiff state started off its equilibrium: tau' = (u(t) - tau) / T, u = -6 cos t ---- */
/* tau0 = 0 against u(0) = -6: the start's rate 6 / T is no rate the step can follow at
 * h / T = 1e1 ... 1e10 (h = 1e-2). Carried into the first step it put tau - u at -3 755 (T =
 * 1e-6) and made Newton fail from T = 1e-7 on. The first step absorbs it: at rho_inf = 0 tau
 * moves monotonically towards u, else |tau - u| never grows and falls by rho_inf per step;
 * afterwards order 2 against the exact solution
 *     tau(t) = A (cos t + T sin t) / (1 + T^2) - A / (1 + T^2) exp(-t / T),  A = -6. */
static double g_tau_T;
static int tau_rate(double t, const double *q, const double *v, const double *y,
                    double *ydot, void *u)
{
    (void)q, (void)v, (void)u;
    ydot[0] = (-6.0 * cos(t) - y[0]) / g_tau_T;
    return 0;
}
static int no_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    f[0] = 0.0;
    return 0;
}
static double tau_exact(double t, double T)
{
    const double A = -6.0, decay = t / T < 700.0 ? exp(-t / T) : 0.0;
    return A * (cos(t) + T * sin(t)) / (1.0 + T * T) - A / (1.0 + T * T) * decay;
}
/* tau at t = 1 after steps of h; the largest |tau - u| over the steps after the first, and
 * |tau_1 - u_1|, with tau_1 between tau_0 and u_1 at rho_inf = 0 */
static double tau_run(double T, double rho, double h, double *first, double *later,
                      int *monotone)
{
    g_tau_T = T;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, one_mass, no_force, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, 1, NULL, tau_rate), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, rho), GA_OK);
    const double q0 = 0.0, v0 = 0.0, y0 = 0.0;
    assert_int_equal(ga_init_y(s, 0.0, &q0, &v0, &y0), GA_OK);
    const int steps = (int)lround(1.0 / h);
    double tau = 0.0;
    *later = 0.0;
    for (int k = 1; k <= steps; ++k) {
        const ga_status st = ga_step(s, h);
        if (st != GA_OK)
            print_error("T = %g, rho_inf %g, step %d: %s\n", T, rho, k, ga_last_error(s));
        assert_int_equal(st, GA_OK);
        assert_int_equal(ga_get_y(s, &tau, NULL), GA_OK);
        const double off = fabs(tau - (-6.0 * cos(k * h)));
        if (k == 1) {
            *first = off;
            *monotone = tau <= 0.0 && tau >= -6.0 * cos(h);
        } else {
            *later = fmax(*later, off);
        }
    }
    ga_free(s);
    return tau;
}
static void a_stiff_state_off_its_equilibrium_is_absorbed(void **state)
{
    (void)state;
    const double rhos[] = {0.0, 0.5, 0.9, 1.0};
    for (double T = 1e-3; T >= 1e-12 * 0.99; T *= 1e-3)
        for (size_t r = 0; r < 4; ++r) {
            double first = 0.0, later = 0.0, e[3];
            int monotone = 0;
            for (int i = 0; i < 3; ++i) {
                const double h = 2e-2 / (1 << i);
                e[i] = fabs(tau_run(T, rhos[r], h, &first, &later, &monotone) -
                            tau_exact(1.0, T));
                if (i == 1) {  /* h = 1e-2 */
                    printf("  T = %.0e, rho_inf %.1f, h = 1e-2: |tau - u| 6 at t0, %.2g after "
                           "step 1, at most %.2g after\n", T, rhos[r], first, later);
                    assert_true(first < 6.0);
                    /* (rho_inf = 1 keeps it: modulus 1, and u's own drift beside it) */
                    assert_true(later <= (rhos[r] < 1.0 ? 1.0 : 1.01) * first);
                    if (rhos[r] == 0.0)
                        assert_true(monotone);
                }
            }
            printf("    error at t = 1 for h = 2e-2, 1e-2, 5e-3: %.2g %.2g %.2g\n", e[0], e[1],
                   e[2]);
            if (rhos[r] < 1.0)  /* order 2, or the start's transient damped faster still */
                assert_true(e[1] <= 0.3 * e[0] + 1e-13 && e[2] <= 0.3 * e[1] + 1e-13);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(stiff_limit_has_spectral_radius_rho_inf),
        cmocka_unit_test(order_two_in_every_quantity),
        cmocka_unit_test(exact_coupling_converges_in_one_update),
        cmocka_unit_test(checkpoint_continues_bit_for_bit),
        cmocka_unit_test(adaptive_after_short_steps_repeats_from_a_checkpoint),
        cmocka_unit_test(dense_output_of_y),
        cmocka_unit_test(adaptive_error_follows_the_tolerance),
        cmocka_unit_test(events_on_the_states),
        cmocka_unit_test(refusals_and_failures),
        cmocka_unit_test(sparse_path_gives_the_dense_solution),
        cmocka_unit_test(a_stiff_state_off_its_equilibrium_is_absorbed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
