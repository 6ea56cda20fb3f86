/* Accuracy on demand: variable steps (a_n rescaled), the stabilized index-2 formulation,
 * corrected starting values, the local error estimate and controller, ga_advance and dense
 * output. Oracles: the mathematics of docs/algorithms.md (secs. 1, 2.6, 6.5) and independent RK4
 * solutions; none of the expected values comes from galpha. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "helpers.h"
#include "scene_run.h"
#include "scenes/andrews.h"
#include "scenes/index1_rk4.h"
#include "scenes/slider_crank.h"

static pendulum P = {1.0, 1.0, 9.81};
static const double TH0 = 1.0, OM0 = 0.5;

/* Exact pendulum, advanced incrementally (RK4 on the angle with substeps of at most 1e-5). */
typedef struct exact_pendulum {
    double t, th, om;
} exact_pendulum;

static void exact_advance(exact_pendulum *e, double t_to)
{
    const long n = (long)ceil((t_to - e->t) / 1e-5 - 1e-9);
    const double h = n > 0 ? (t_to - e->t) / n : 0.0, w2 = P.gravity / P.length;
    for (long i = 0; i < n; ++i) {
        const double k1t = e->om, k1o = -w2 * sin(e->th);
        const double k2t = e->om + 0.5 * h * k1o, k2o = -w2 * sin(e->th + 0.5 * h * k1t);
        const double k3t = e->om + 0.5 * h * k2o, k3o = -w2 * sin(e->th + 0.5 * h * k2t);
        const double k4t = e->om + h * k3o, k4o = -w2 * sin(e->th + h * k3t);
        e->th += h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t);
        e->om += h / 6.0 * (k1o + 2 * k2o + 2 * k3o + k4o);
    }
    e->t = t_to;
}

static double exact_lambda(const exact_pendulum *e)
{
    return P.mass * (P.length * P.length * e->om * e->om + P.gravity * P.length * cos(e->th)) /
           (P.length * P.length);
}

static ga_solver *pendulum_solver(double rho, int formulation, int rescale, int corrected)
{
    ga_solver *s = NULL;
    double q[2], v[2];
    pendulum_state(&P, TH0, OM0, q, v);
    s = pendulum_new_solver(&P, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_constraint_accel(s, pendulum_constraint_accel), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, rho), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_rescale(s, rescale), GA_OK);
    assert_int_equal(ga_set_corrected_start(s, corrected), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 20), GA_OK);
    /* these tests are about the method's own multipliers, not consistent output */
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    return s;
}

/* ---- variable steps: rescaling a_n keeps order 2 (docs/algorithms.md 1.1-1.2) -------------------- */
/* A fixed pseudo-random pattern of 20 step ratios in [0.5, 1.5], normalized to sum to 1 and
 * repeated 2^k times at 2^-k of the size: h changes at (almost) every step, at every level. */
static void run_random_steps(int rescale, int level, double *eq, double *ev, double *el)
{
    enum { PATTERN = 20 };
    double ratio[PATTERN], sum = 0.0;
    unsigned state = 12345u;
    for (int i = 0; i < PATTERN; ++i) {
        state = state * 1103515245u + 12345u;
        ratio[i] = 0.5 + (double)((state >> 8) & 0xffff) / 65535.0;
        sum += ratio[i];
    }
    ga_solver *s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, rescale, 1);
    const int repeats = 1 << level;
    for (int r = 0; r < repeats; ++r)
        for (int i = 0; i < PATTERN; ++i)
            assert_int_equal(ga_step(s, ratio[i] / sum / repeats), GA_OK);
    double t, q[2], v[2], lambda;
    ga_get_t(s, &t);
    ga_get_q(s, q);
    ga_get_v(s, v);
    ga_get_lambda(s, &lambda);
    const pendulum_exact ex = pendulum_reference(&P, TH0, OM0, t, 200000);
    *eq = max_abs_diff(q, ex.q, 2);
    *ev = max_abs_diff(v, ex.v, 2);
    *el = fabs(lambda - ex.lambda);
    ga_free(s);
}

static void rescaling_keeps_order_two_under_random_steps(void **state)
{
    (void)state;
    enum { K = 4 };
    double hs[K], e[3][K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 1.0 / (20.0 * (1 << (k + 2)));
        run_random_steps(1, k + 2, &e[0][k], &e[1][k], &e[2][k]);
    }
    const double oq = fit_order(hs, e[0], K), ov = fit_order(hs, e[1], K);
    const double ol = fit_order(hs, e[2], K);
    printf("  random steps (ratios 0.5 to 1.5), index-2, a_n rescaled: order q %.2f v %.2f "
           "lambda %.2f\n",
           oq, ov, ol);
    assert_true(oq > 1.8 && ov > 1.8 && ol > 1.8);
}

/* The same ODE as docs/algorithms.md 1.1, theta'' = -9.81 sin(theta) from theta = 1 at rest, steps
 * h, 2h, h, 2h, ... to t = 1: without rescaling the order drops towards 1. */
static int pend_ode_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}
static int pend_ode_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -9.81 * sin(q[0]);
    return 0;
}

static void without_rescaling_alternating_steps_lose_an_order(void **state)
{
    (void)state;
    enum { K = 4 };
    pendulum unit = {1.0, 1.0, 9.81};
    const pendulum_exact ex = pendulum_reference(&unit, 1.0, 0.0, 1.0, 200000);
    const double exact = atan2(ex.q[0], -ex.q[1]);
    double hs[K], err[2][K];
    for (int r = 0; r < 2; ++r)
        for (int k = 0; k < K; ++k) {
            ga_solver *s = NULL;
            double q = 1.0, v = 0.0;
            hs[k] = 1.0 / (30.0 * (1 << k));
            assert_int_equal(ga_create(1, 0, &s), GA_OK);
            assert_int_equal(ga_set_callbacks(s, pend_ode_mass, pend_ode_force, NULL, NULL, NULL),
                             GA_OK);
            assert_int_equal(ga_set_rescale(s, r), GA_OK);
            assert_int_equal(ga_set_newton(s, 1e-13, 20), GA_OK);
            assert_int_equal(ga_init(s, 0.0, &q, &v), GA_OK);
            for (long i = 0; i < lround(1.0 / (3.0 * hs[k])); ++i) {
                assert_int_equal(ga_step(s, hs[k]), GA_OK);
                assert_int_equal(ga_step(s, 2.0 * hs[k]), GA_OK);
            }
            ga_get_q(s, &q);
            err[r][k] = fabs(q - exact);
            ga_free(s);
        }
    const double on = fit_order(hs, err[1], K), off = fit_order(hs, err[0], K);
    printf("  steps h, 2h, h, ... on theta'' = -g sin(theta): order %.2f with rescaling, %.2f "
           "without (error at the finest h %.1e vs %.1e)\n",
           on, off, err[1][K - 1], err[0][K - 1]);
    assert_true(on > 1.9);
    assert_true(off < 1.6);
    assert_true(err[0][K - 1] > 2.0 * err[1][K - 1]);
}

/* The largest |lambda - exact lambda| over `steps` steps of size h from the solver's state
 * (the exact pendulum e advanced along). */
static double max_lambda_error(ga_solver *s, exact_pendulum *e, double h, long steps)
{
    double worst = 0.0, t, lambda;
    for (long k = 0; k < steps; ++k) {
        assert_int_equal(ga_step(s, h), GA_OK);
        ga_get_t(s, &t);
        ga_get_lambda(s, &lambda);
        exact_advance(e, t);
        worst = fmax(worst, fabs(lambda - exact_lambda(e)));
    }
    return worst;
}

/* ---- multipliers across a step change (docs/algorithms.md 1.4) ------------------------------------ */
static double lambda_error_after_change(int formulation, double h)
{
    /* h until t = 0.5, then 2h; max |lambda error| over (0.5, 0.6] */
    ga_solver *s = pendulum_solver(0.8, formulation, 1, 1);
    exact_pendulum e = {0.0, TH0, OM0};
    const long n1 = lround(0.5 / h), n2 = lround(0.1 / (2 * h));
    for (long k = 0; k < n1; ++k)
        assert_int_equal(ga_step(s, h), GA_OK);
    const double worst = max_lambda_error(s, &e, 2 * h, n2);
    ga_free(s);
    return worst;
}

static void index2_multipliers_stay_second_order_across_step_changes(void **state)
{
    (void)state;
    enum { K = 4 };
    double hs[K], e2[K], e3[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 0.01 / (1 << k);
        e2[k] = lambda_error_after_change(GA_INDEX2_STABILIZED, hs[k]);
        e3[k] = lambda_error_after_change(GA_INDEX3, hs[k]);
    }
    const double o2 = fit_order(hs, e2, K), o3 = fit_order(hs, e3, K);
    printf("  lambda error just after h -> 2h: index-2 %.1e ... %.1e (order %.2f); index-3 %.1e "
           "... %.1e (order %.2f)\n",
           e2[0], e2[K - 1], o2, e3[0], e3[K - 1], o3);
    assert_true(o2 > 1.8);
    assert_true(o3 < 1.3);
}

/* ---- start-up transient (docs/algorithms.md 2.6) ---------------------------------------------- */
static double startup_lambda_error_rho(double rho, int corrected, double h, double t_end)
{
    ga_solver *s = pendulum_solver(rho, GA_INDEX3, 1, corrected);
    exact_pendulum e = {0.0, TH0, OM0};
    const double worst = max_lambda_error(s, &e, h, lround(t_end / h));
    ga_free(s);
    return worst;
}
static double startup_lambda_error(int corrected, double h)
{
    return startup_lambda_error_rho(0.9, corrected, h, 0.1);
}

static void corrected_start_removes_the_first_order_transient(void **state)
{
    (void)state;
    enum { K = 4 };
    double hs[K], on[K], off[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 0.01 / (1 << k);
        on[k] = startup_lambda_error(1, hs[k]);
        off[k] = startup_lambda_error(0, hs[k]);
    }
    const double o_on = fit_order(hs, on, K), o_off = fit_order(hs, off, K);
    printf("  max lambda error over [0, 0.1]: corrected start %.1e (order %.2f), a_0 = qdd_0 "
           "%.1e (order %.2f)\n",
           on[K - 1], o_on, off[K - 1], o_off);
    assert_true(o_on > 1.8);
    assert_true(o_off < 1.3);
    assert_true(off[K - 1] > 10.0 * on[K - 1]);
}

/* rho_inf = 1 (no numerical damping, the trapezoidal rule): the start-up oscillation of lambda
 * never decays, and without corrected starting values lambda does not converge at all
 * (docs/algorithms.md 2.6: error about 9 on [0, 1] for every h); the corrected start restores
 * order 2. */
static void rho_one_needs_the_corrected_start(void **state)
{
    (void)state;
    enum { K = 4 };
    double hs[K], on[K], off[K];
    for (int k = 0; k < K; ++k) {
        hs[k] = 0.01 / (1 << k);
        on[k] = startup_lambda_error_rho(1.0, 1, hs[k], 1.0);
        off[k] = startup_lambda_error_rho(1.0, 0, hs[k], 1.0);
        printf("  rho_inf = 1, h = %.5f: max lambda error on [0, 1] %.2e corrected, %.2e not\n",
               hs[k], on[k], off[k]);
    }
    const double o_on = fit_order(hs, on, K), o_off = fit_order(hs, off, K);
    printf("  orders: %.2f corrected, %.2f not\n", o_on, o_off);
    assert_true(o_on > 1.8);
    assert_true(fabs(o_off) < 0.2); /* no convergence */
    for (int k = 0; k < K; ++k)
        assert_true(off[k] > 1.0);
}

/* ---- the error estimate against the true local error (docs/algorithms.md 1.5, 6.5) -------------- */
static int ode_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}
static int ode_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -9.81 * sin(q[0]);
    return 0;
}

/* One adaptive step of size h of theta'' = -9.81 sin(theta) from smooth starting values (a_n,
 * a_{n-1} on the shifted acceleration of docs/algorithms.md sec. 0, constant step h); returns
 * GA_INFO_ERROR_ESTIMATE and, through *truth, the same weighted norm of the true local errors
 * (numerical minus RK4). Tolerances 1 make the weights 1 + max(|y_n|, |y_n+1|). */
static double estimate_vs_truth(double h, double *truth)
{
    const double th = 0.7, om = 0.3, g = 9.81;
    double am, af, beta, gamma;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, ode_mass, ode_force, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-14, 20), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1.0, 1.0), GA_OK);
    ga_get_params(s, &am, &af, &beta, &gamma);
    const double da = am - af;
    /* derivatives of theta at t_n */
    const double a2 = -g * sin(th), a3 = -g * cos(th) * om;
    const double a4 = g * sin(th) * om * om - g * cos(th) * a2;
    const double a5 = g * cos(th) * om * om * om + 3 * g * sin(th) * om * a2 - g * cos(th) * a3;
    /* a(t) = qdd(t + da h) + da (am - 1/2) h^2 qdddd(t + ...): shifted accelerations */
    double buf[9 + 5 * 1 + 0]; /* layout 2 (galpha 0.2), still read */
    buf[0] = 26465.0, buf[1] = 2.0, buf[2] = 1.0, buf[3] = 0.0;
    buf[4] = 0.0, buf[5] = h, buf[6] = h, buf[7] = 1.0, buf[8] = 0.0;
    buf[9] = th, buf[10] = om, buf[11] = a2;
    buf[12] = a2 + da * h * a3 + (0.5 * da * da + da * (am - 0.5)) * h * h * a4;
    buf[13] = (a2 - h * a3 + 0.5 * h * h * a4) + da * h * (a3 - h * a4) +
              (0.5 * da * da + da * (am - 0.5)) * h * h * (a4 - h * a5);
    assert_int_equal(ga_set_state(s, buf, 14), GA_OK);
    assert_int_equal(ga_step_adaptive(s, 1.0), GA_OK);
    double h_taken, est, q, v;
    ga_get_h_last(s, &h_taken);
    assert_true(fabs(h_taken - h) < 1e-15);
    ga_get_info(s, GA_INFO_ERROR_ESTIMATE, &est);
    ga_get_q(s, &q);
    ga_get_v(s, &v);
    /* exact one-step solution */
    double y[2] = {th, om};
    const long n = 20000;
    const double k = h / n;
    for (long i = 0; i < n; ++i) {
        const double k1t = y[1], k1o = -g * sin(y[0]);
        const double k2t = y[1] + 0.5 * k * k1o, k2o = -g * sin(y[0] + 0.5 * k * k1t);
        const double k3t = y[1] + 0.5 * k * k2o, k3o = -g * sin(y[0] + 0.5 * k * k2t);
        const double k4t = y[1] + k * k3o, k4o = -g * sin(y[0] + k * k3t);
        y[0] += k / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t);
        y[1] += k / 6.0 * (k1o + 2 * k2o + 2 * k3o + k4o);
    }
    const double wq = 1.0 + fmax(fabs(th), fabs(q)), wv = 1.0 + fmax(fabs(om), fabs(v));
    *truth = sqrt(0.5 * (pow((q - y[0]) / wq, 2) + pow((v - y[1]) / wv, 2)));
    ga_free(s);
    /* the error test's weights are scaled by 0.5 sqrt(rtol) = 0.5 (ga_set_tolerances) */
    return 0.5 * est;
}

static void error_estimate_tends_to_the_true_local_error(void **state)
{
    (void)state;
    double ratio[3];
    for (int k = 0; k < 3; ++k) {
        const double h = 0.02 / (1 << k);
        double truth;
        const double est = estimate_vs_truth(h, &truth);
        ratio[k] = est / truth;
        printf("  h = %-6g estimate %.3e, true local error %.3e, ratio %.3f\n", h, est, truth,
               ratio[k]);
    }
    assert_true(fabs(ratio[2] - 1.0) < 0.15);
    assert_true(fabs(ratio[2] - 1.0) <= fabs(ratio[0] - 1.0) + 0.02);
}

/* ---- ga_advance and dense output --------------------------------------------------------- */
static void advance_lands_on_every_output_time(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    exact_pendulum e = {0.0, TH0, OM0};
    for (int k = 1; k <= 10; ++k) {
        const double t_out = 0.1 * k;
        double t, q[2], ex[2], dummy[2];
        assert_int_equal(ga_advance(s, t_out), GA_OK);
        ga_get_t(s, &t);
        assert_true(t == t_out); /* exactly */
        ga_get_q(s, q);
        exact_advance(&e, t_out);
        pendulum_state(&P, e.th, e.om, ex, dummy);
        assert_true(max_abs_diff(q, ex, 2) < 1e-3); /* global error at the tolerance's scale */
    }
    long long steps, rejected;
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    ga_get_counter(s, GA_COUNT_REJECTED_STEPS, &rejected);
    printf("  pendulum to t = 1 with rtol = atol = 1e-6: %lld steps, %lld rejected\n", steps,
           rejected);
    ga_free(s);
}

static void interpolation_agrees_with_a_step_ending_there(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
    assert_int_equal(ga_set_tolerances(s, 1e-5, 1e-5), GA_OK);
    double ckpt[CKPT_PENDULUM], t0, t1;
    for (int k = 0; k < 25; ++k)
        assert_int_equal(ga_step_adaptive(s, 10.0), GA_OK);
    assert_int_equal(ga_get_state(s, ckpt, CKPT_PENDULUM), GA_OK);
    ga_get_t(s, &t0);
    assert_int_equal(ga_step_adaptive(s, 10.0), GA_OK);
    ga_get_t(s, &t1);
    /* ends of the interval: the interpolant is exact there */
    double qa[2], qb[2], q[2], v[2], lam, est;
    assert_int_equal(ga_interpolate(s, t1, qa, NULL, NULL), GA_OK);
    ga_get_q(s, qb);
    assert_true(max_abs_diff(qa, qb, 2) < 1e-15);
    assert_int_equal(ga_interpolate(s, t0 - 1.0, q, v, &lam), GA_ERR_ARG);
    /* inside: against a step from t0 that ends at tau */
    const double tau = t0 + 0.37 * (t1 - t0);
    assert_int_equal(ga_interpolate(s, tau, q, v, &lam), GA_OK);
    ga_get_info(s, GA_INFO_ERROR_ESTIMATE, &est);
    ga_solver *r = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
    assert_int_equal(ga_set_state(r, ckpt, CKPT_PENDULUM), GA_OK);
    assert_int_equal(ga_step(r, tau - t0), GA_OK);
    double qr[2], vr[2];
    ga_get_q(r, qr);
    ga_get_v(r, vr);
    const double scale = 1e-5 * (1.0 + 1.0); /* atol + rtol |q|: the estimate's unit */
    printf("  interpolated vs stepped to tau: |dq| = %.1e, |dv| = %.1e (error estimate %.2f x "
           "%.0e)\n",
           max_abs_diff(q, qr, 2), max_abs_diff(v, vr, 2), est, scale);
    assert_true(max_abs_diff(q, qr, 2) < 10.0 * scale);
    assert_true(max_abs_diff(v, vr, 2) < 10.0 * scale);
    ga_free(r);
    ga_free(s);
}

/* ---- whole runs ----------------------------------------------------------------------------- */
static void slider_crank_runs_adaptively_to_its_end(void **state)
{
    (void)state;
    slider_crank p = slider_crank_paper();
    double q[SC_N], v[SC_N], qr[SC_N], vr[SC_N];
    sc_initial(&p, M_PI / 2, q, v);
    memcpy(qr, q, sizeof q);
    memcpy(vr, v, sizeof v);
    rk4_model md = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &p};
    assert_int_equal(index1_rk4(&md, 0.0, 1.0, 200000, qr, vr, NULL, NULL), 0);
    for (int form = 0; form < 2; ++form) {
        ga_solver *s = NULL;
        assert_int_equal(ga_create(SC_N, SC_M, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, sc_mass, sc_force, sc_constraint, sc_jacobian, &p),
                         GA_OK);
        assert_int_equal(ga_set_tangents(s, sc_stiffness, NULL), GA_OK);
        assert_int_equal(ga_set_formulation(s, form), GA_OK);
        assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        assert_int_equal(ga_advance(s, 1.0), GA_OK);
        double qe[SC_N], phi[SC_M], t;
        ga_get_t(s, &t);
        ga_get_q(s, qe);
        sc_constraint(t, qe, phi, &p);
        long long steps;
        ga_get_counter(s, GA_COUNT_STEPS, &steps);
        const double e = fabs(qe[SC_TH1] - qr[SC_TH1]) / fabs(qr[SC_TH1]);
        printf("  slider-crank, %s, rtol 1e-6: %lld steps, crank angle error %.1e\n",
               form ? "index-2" : "index-3", steps, e);
        assert_true(t == 1.0);
        assert_true(e < 1e-3);
        for (int i = 0; i < SC_M; ++i)
            assert_true(fabs(phi[i]) < 1e-12);
        ga_free(s);
    }
}

/* Andrews' mechanism (7 angles) in adaptive mode to t = 0.03; newton_tol 0: the default. */
static void andrews_adaptive(int formulation, double rtol, double newton_tol, double *err,
                             long long *residuals)
{
    ga_solver *s = NULL;
    double v0[7] = {0}, q[7];
    assert_int_equal(ga_create(7, 6, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, an7_mass, an7_force, an7_constraint, an7_jacobian,
                                      NULL),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, an7_constraint_accel), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_tolerances(s, rtol, rtol), GA_OK);
    if (newton_tol > 0.0)
        assert_int_equal(ga_set_newton(s, newton_tol, 20), GA_OK);
    assert_int_equal(ga_init(s, 0.0, andrews_q0, v0), GA_OK);
    assert_int_equal(ga_advance(s, andrews_t_end), GA_OK);
    ga_get_q(s, q);
    *err = andrews_angle_error(q);
    ga_get_counter(s, GA_COUNT_RESIDUALS, residuals);
    ga_free(s);
}

static void andrews_error_follows_the_tolerance(void **state)
{
    (void)state;
    enum { K = 6 };
    double rtol[K], err[K];
    long long res[K];
    for (int k = 0; k < K; ++k) {
        rtol[k] = pow(10.0, -2.0 - k);
        andrews_adaptive(GA_INDEX2_STABILIZED, rtol[k], 0.0, &err[k], &res[k]);
        printf("  Andrews, index-2, rtol %.0e: angle error %.2e, %lld residual evaluations\n",
               rtol[k], err[k], res[k]);
    }
    const double slope = fit_order(rtol, err, K);
    printf("  tolerance proportionality: slope of log(error) against log(rtol) = %.2f\n", slope);
    assert_true(slope >= 0.7 && slope <= 1.3);
}

/* The default Newton tolerance of adaptive steps follows the local error tolerance (a tenth of
 * it): the same answer as a 1e-10 Newton tolerance to well within the error asked for, with
 * at least 10 % less work. */
static void adaptive_newton_tolerance_follows_rtol(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        const double rtol = 1e-4;
        double err_auto, err_tight;
        long long res_auto, res_tight;
        andrews_adaptive(formulation, rtol, 0.0, &err_auto, &res_auto);
        andrews_adaptive(formulation, rtol, 1e-10, &err_tight, &res_tight);
        printf("  Andrews, %s, rtol %.0e: Newton tol 1e-2 rtol: error %.3e, %lld residuals; "
               "1e-10: error %.3e, %lld residuals\n",
               formulation == GA_INDEX3 ? "index-3" : "index-2", rtol, err_auto, res_auto,
               err_tight, res_tight);
        assert_true(fabs(err_auto - err_tight) <= 0.1 * rtol);
        assert_true((double)res_auto <= 0.9 * (double)res_tight);
    }
}

/* max_i |q_i - q_ref,i| / |q_ref,i| at t = 0.03 against the published reference: the error of
 * docs/perf/wp_andrews.csv */
static double andrews_max_relative_error(const double *q)
{
    double e = 0.0;
    for (int i = 0; i < 7; ++i)
        e = fmax(e, fabs(q[i] - andrews_q_ref[i]) / fabs(andrews_q_ref[i]));
    return e;
}

/* On Andrews' mechanism at an angle error of 1e-4 at t = 0.03, adaptive steps (stabilized
 * index 2, default settings, rtol = atol = 3e-4) need at least 2.5 times fewer residual
 * evaluations than the best fixed step (index 3, default tangents, Newton
 * tolerance as in bench/ida_workprecision.c). Fixed steps are swept over half octaves of h
 * (whole numbers of steps to t = 0.03) until one reaches 1e-4; the best fixed step for exactly
 * 1e-4 is interpolated between it and the one before (log-log, error ~ h^2 in between), so
 * that the coarseness of the sweep does not favour the adaptive run. Residual counts do not
 * depend on the machine. */
static void andrews_adaptive_needs_2_5x_fewer_residuals_than_fixed_steps(void **state)
{
    (void)state;
    const double target = 1e-4, v0[7] = {0};
    double q[7];
    ga_solver *s = NULL;
    assert_int_equal(ga_create(7, 6, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, an7_mass, an7_force, an7_constraint, an7_jacobian,
                                      NULL),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, an7_constraint_accel), GA_OK);
    assert_int_equal(ga_set_constraint_dt(s, an7_constraint_dt), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
    assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 3e-4, 3e-4), GA_OK);
    assert_int_equal(ga_init(s, 0.0, andrews_q0, v0), GA_OK);
    assert_int_equal(ga_advance(s, andrews_t_end), GA_OK);
    ga_get_q(s, q);
    const double err_adaptive = andrews_max_relative_error(q);
    long long res_adaptive = 0;
    ga_get_counter(s, GA_COUNT_RESIDUALS, &res_adaptive);
    ga_free(s);
    assert_true(err_adaptive <= target);

    double err_prev = 0.0, res_prev = 0.0, res_fixed = 0.0;
    for (int k = 0; k < 24 && res_fixed == 0.0; ++k) {
        const long steps = lround(andrews_t_end / (1.2e-3 / pow(2.0, 0.5 * k)));
        const double h = andrews_t_end / (double)steps;
        assert_int_equal(ga_create(7, 6, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, an7_mass, an7_force, an7_constraint,
                                          an7_jacobian, NULL),
                         GA_OK);
        assert_int_equal(ga_set_constraint_accel(s, an7_constraint_accel), GA_OK);
        assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
        assert_int_equal(ga_set_newton(s, fmin(1e-6, 1e-4 * (h / 3e-4) * (h / 3e-4)), 20),
                         GA_OK);
        ga_status st = ga_init(s, 0.0, andrews_q0, v0);
        for (long i = 0; i < steps && !st; ++i)
            st = ga_step(s, h);
        long long res = 0;
        ga_get_counter(s, GA_COUNT_RESIDUALS, &res);
        ga_get_q(s, q);
        ga_free(s);
        if (st) /* too coarse a step for Newton: no point on the curve */
            continue;
        const double err = andrews_max_relative_error(q);
        if (err <= target) {
            res_fixed = (double)res;
            if (err_prev > target) /* interpolate to the error target */
                res_fixed = exp(log(res_prev) + (log(target) - log(err_prev)) /
                                                    (log(err) - log(err_prev)) *
                                                    (log((double)res) - log(res_prev)));
            printf("  fixed: h = %.3e reaches %.2e with %lld residuals; best fixed step for "
                   "%.0e: %.0f residuals\n",
                   h, err, res, target, res_fixed);
        }
        err_prev = err;
        res_prev = (double)res;
    }
    printf("  adaptive (index 2, rtol 3e-4): %.2e with %lld residuals: %.2f times fewer\n",
           err_adaptive, res_adaptive, res_fixed / (double)res_adaptive);
    assert_true(res_fixed > 0.0);
    assert_true(res_fixed >= 2.5 * (double)res_adaptive);
}

static void step_size_floor_is_reported(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(0.9, GA_INDEX3, 1, 1);
    double before[CKPT_PENDULUM], after[CKPT_PENDULUM];
    assert_int_equal(ga_set_tolerances(s, 1e-12, 1e-12), GA_OK);
    assert_int_equal(ga_set_step_limits(s, 0.05, 0.0), GA_OK);
    assert_int_equal(ga_set_initial_step(s, 0.05), GA_OK);
    assert_int_equal(ga_get_state(s, before, CKPT_PENDULUM), GA_OK);
    assert_int_equal(ga_advance(s, 1.0), GA_ERR_STEP_SIZE);
    assert_non_null(strstr(ga_last_error(s), "fell below the minimum"));
    assert_int_equal(ga_get_state(s, after, CKPT_PENDULUM), GA_OK);
    assert_true(ckpt_same_state(before, after));
    assert_int_equal(ga_set_step_limits(s, 0.2, 0.1), GA_ERR_ARG);
    assert_int_equal(ga_set_tolerances(s, 0.0, 1e-6), GA_ERR_ARG);
    assert_int_equal(ga_advance(s, -1.0), GA_ERR_ARG);
    assert_int_equal(ga_step_adaptive(s, 0.0), GA_ERR_ARG);
    ga_free(s);
}

/* A step too short to move t is refused whatever minimum the user set (found by the random
 * call sequences: at t = -1e300 with h_max = 1 a step of 1 was accepted with t unchanged, and
 * the solver then refused its own checkpoint). */
static void a_step_that_does_not_move_t_is_refused(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL; /* a free particle under gravity: every step solves at once */
    assert_int_equal(ga_create(2, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, NULL, NULL, &p), GA_OK);
    const double q[2] = {0.5, -0.8}, v[2] = {0.0, 0.0};
    assert_int_equal(ga_init(s, -1e300, q, v), GA_OK);
    assert_int_equal(ga_set_step_limits(s, 1e-3, 1.0), GA_OK);
    assert_int_equal(ga_set_initial_step(s, 1.0), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double before[512], after[512];
    assert_true(len <= 512);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    assert_int_equal(ga_step_adaptive(s, 1e300), GA_ERR_STEP_SIZE);
    assert_non_null(strstr(ga_last_error(s), "fell below the minimum"));
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_true(ckpt_same_state(before, after));
    assert_int_equal(ga_set_state(s, after, len), GA_OK);
    ga_free(s);
}

/* ---- failures inside adaptive steps: retried smaller, or reported with the state kept ----- */
/* The pendulum with a force callback that refuses (returns > 0, recoverable) to evaluate
 * positions further than max_move from the last accepted ones, as a material model refuses
 * too large a strain increment; or fails for good (< 0) from t_fatal on. */
typedef struct guarded_pendulum {
    pendulum p;
    double q_accepted[2], max_move, t_fatal;
    long long refusals;
} guarded_pendulum;

static int guarded_force(double t, const double *q, const double *v, double *f, void *u)
{
    guarded_pendulum *g = u;
    pendulum_force(t, q, v, f, &g->p);
    if (t >= g->t_fatal)
        return -2;
    if (fmax(fabs(q[0] - g->q_accepted[0]), fabs(q[1] - g->q_accepted[1])) > g->max_move) {
        ++g->refusals;
        return 1;
    }
    return 0;
}

static ga_solver *guarded_solver(guarded_pendulum *g, double rtol)
{
    ga_solver *s = NULL;
    double v[2];
    pendulum_state(&g->p, TH0, OM0, g->q_accepted, v);
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, guarded_force, pendulum_constraint,
                                      pendulum_jacobian, g),
                     GA_OK);
    assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
    assert_int_equal(ga_set_tolerances(s, rtol, rtol), GA_OK);
    assert_int_equal(ga_init(s, 0.0, g->q_accepted, v), GA_OK);
    return s;
}

static void adaptive_steps_retry_after_recoverable_failures(void **state)
{
    (void)state;
    /* unguarded, rtol = 1e-5: the steps move the bob by up to this much */
    guarded_pendulum free_run = {P, {0, 0}, INFINITY, INFINITY, 0};
    ga_solver *s = guarded_solver(&free_run, 1e-5);
    double largest = 0.0, q[2];
    while (ga_step_adaptive(s, 1.0) == GA_OK) {
        ga_get_q(s, q);
        largest = fmax(largest, max_abs_diff(q, free_run.q_accepted, 2));
        memcpy(free_run.q_accepted, q, sizeof q);
        double t;
        ga_get_t(s, &t);
        if (t == 1.0)
            break;
    }
    ga_free(s);
    /* guarded at half of that: the controller's proposals are refused again and again */
    guarded_pendulum g = {P, {0, 0}, 0.5 * largest, INFINITY, 0};
    s = guarded_solver(&g, 1e-5);
    double t = 0.0;
    while (t < 1.0) {
        assert_int_equal(ga_step_adaptive(s, 1.0), GA_OK);
        ga_get_q(s, q);
        assert_true(max_abs_diff(q, g.q_accepted, 2) <= g.max_move); /* an accepted step */
        memcpy(g.q_accepted, q, sizeof q);
        ga_get_t(s, &t);
    }
    assert_true(t == 1.0);
    long long failed, steps;
    ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed);
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    exact_pendulum e = {0.0, TH0, OM0};
    double ex[2], dummy[2];
    exact_advance(&e, 1.0);
    pendulum_state(&P, e.th, e.om, ex, dummy);
    printf("  largest move per step %.3f unguarded; guarded at %.3f: %lld steps, %lld failed "
           "(%lld refusals), |q - q_exact| = %.1e\n",
           largest, g.max_move, steps, failed, g.refusals, max_abs_diff(q, ex, 2));
    assert_true(failed > 0);
    assert_true(failed <= g.refusals); /* each failed attempt saw at least one refusal */
    assert_true(max_abs_diff(q, ex, 2) < 1e-3);
    ga_free(s);
}

/* A fatal failure ends ga_advance with the state of the last accepted step; once the cause is
 * gone the run goes on. */
static void adaptive_fatal_failure_keeps_the_last_accepted_step(void **state)
{
    (void)state;
    guarded_pendulum g = {P, {0, 0}, INFINITY, 0.5, 0};
    ga_solver *s = guarded_solver(&g, 1e-6);
    double t, t_before, h_last, before[CKPT_PENDULUM], after[CKPT_PENDULUM];
    assert_int_equal(ga_advance(s, 1.0), GA_ERR_CALLBACK);
    assert_non_null(strstr(ga_last_error(s), "force callback returned -2"));
    ga_get_t(s, &t);
    ga_get_h_last(s, &h_last);
    assert_true(t < 0.5 && t + h_last > 0.4); /* stopped at the last step before the fault */
    long long failed;
    ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed);
    assert_int_equal(failed, 1);
    assert_int_equal(ga_get_state(s, before, CKPT_PENDULUM), GA_OK);
    t_before = t;
    assert_int_equal(ga_step_adaptive(s, 1.0), GA_ERR_CALLBACK); /* the same again */
    assert_int_equal(ga_get_state(s, after, CKPT_PENDULUM), GA_OK);
    assert_true(ckpt_same_state(before, after));
    g.t_fatal = INFINITY;
    assert_int_equal(ga_advance(s, 1.0), GA_OK);
    ga_get_t(s, &t);
    assert_true(t == 1.0 && t_before < 0.5);
    ga_free(s);
}

/* Newton failures in adaptive mode: at most 2 iterations per step, and a first step of 0.5
 * (a quarter swing): the step is retried smaller until the iteration converges. */
static void adaptive_steps_retry_after_newton_failures(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
    assert_int_equal(ga_set_newton(s, 1e-8, 2), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-4, 1e-4), GA_OK);
    assert_int_equal(ga_set_initial_step(s, 0.5), GA_OK);
    assert_int_equal(ga_advance(s, 1.0), GA_OK);
    long long failed, steps;
    ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed);
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    double q[2], ex[2], dummy[2];
    ga_get_q(s, q);
    exact_pendulum e = {0.0, TH0, OM0};
    exact_advance(&e, 1.0);
    pendulum_state(&P, e.th, e.om, ex, dummy);
    printf("  Newton limited to 2 iterations, first step 0.5: %lld steps, %lld failed, "
           "|q - q_exact| = %.1e\n", steps, failed, max_abs_diff(q, ex, 2));
    assert_true(failed >= 1);
    assert_true(max_abs_diff(q, ex, 2) < 1e-2);
    ga_free(s);
}

/* h_max bounds every step, and the controller proposes no more (GA_INFO_H_NEXT); without the
 * bound the same run takes longer steps. Each accepted step is the size proposed after the
 * previous one unless a rejection or the approach to the end of the interval intervened. */
static void step_size_ceiling_and_proposals(void **state)
{
    (void)state;
    double h_top[2] = {0.0, 0.0};
    for (int bounded = 0; bounded < 2; ++bounded) {
        ga_solver *s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
        assert_int_equal(ga_set_tolerances(s, 1e-2, 1e-2), GA_OK);
        if (bounded)
            assert_int_equal(ga_set_step_limits(s, 0.0, 0.01), GA_OK);
        double t = 0.0, h, h_next = 0.0, t_prev;
        long long seen = 0, kept = 0, rejected_before = 0;
        while (t < 1.0) {
            t_prev = t;
            assert_int_equal(ga_step_adaptive(s, 1.0), GA_OK);
            long long rejected, failed;
            ga_get_counter(s, GA_COUNT_REJECTED_STEPS, &rejected);
            ga_get_counter(s, GA_COUNT_FAILED_STEPS, &failed);
            ga_get_t(s, &t);
            ga_get_h_last(s, &h);
            h_top[bounded] = fmax(h_top[bounded], h);
            /* within 2 proposed steps of the end, the steps are stretched or split to land */
            if (h_next > 0.0 && rejected == rejected_before && failed == 0 &&
                t_prev + 2.0 * h_next < 1.0) {
                ++seen;
                kept += h == h_next;
            }
            rejected_before = rejected;
            assert_int_equal(ga_get_info(s, GA_INFO_H_NEXT, &h_next), GA_OK);
            assert_true(h_next > 0.0);
            if (bounded)
                assert_true(h <= 0.01 && h_next <= 0.01);
        }
        printf("  %s: longest step %.4f, %lld of %lld steps as proposed\n",
               bounded ? "h_max = 0.01" : "no h_max", h_top[bounded], kept, seen);
        assert_true(seen > 10 && kept == seen);
        ga_free(s);
    }
    assert_true(h_top[0] > 0.02);
    assert_true(h_top[1] > 0.0099);
}

/* The pendulum, 1 000 steps of 1e-3 with `count` sliver steps of s inserted after step 500
 * (as a caller landing on an output time makes): q at the end (t = 1 + count s) and the
 * multiplier. */
static ga_status pendulum_with_sliver(int formulation, double sliver, int count, double *q,
                                      double *lambda, double *lambda_after_sliver,
                                      double *consistent)
{
    pendulum p = {1.0, 1.0, 9.81};
    double v[2];
    ga_solver *s = pendulum_new_solver(&p, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    pendulum_state(&p, 1.0, 0.5, q, v);
    ga_status st = ga_init(s, 0.0, q, v);
    for (int k = 0; k < 1000 && !st; ++k) {
        st = ga_step(s, 1e-3);
        if (k == 499 && sliver > 0.0 && !st) {
            for (int i = 0; i < count && !st; ++i)
                st = ga_step(s, sliver);
            /* the multiplier of the state (q, v) reached: m (|v|^2 - g y) / L^2 */
            ga_get_q(s, q);
            ga_get_v(s, v);
            ga_get_lambda(s, lambda_after_sliver);
            *consistent = p.mass * (v[0] * v[0] + v[1] * v[1] - p.gravity * q[1]) /
                          (p.length * p.length);
        }
    }
    ga_get_q(s, q);
    ga_get_lambda(s, lambda);
    ga_free(s);
    return st;
}

/* A step far shorter than the one before it is a Taylor step (velocities projected,
 * accelerations and multipliers from the acceleration-level equations): without that, its
 * discrete equations (index 3: an impulse of O(h_last^2 / h) absorbing the velocity-constraint
 * residual; index 2: accelerations known only to eps |v| / h) derailed the run - a sliver of
 * 1e-8 put the index-3 pendulum 1.5 off its path, 1e-14 made a later step fail as singular,
 * and in index 2 a sliver of 1e-14 put it 1.4 off. Now the run ends where the run without the
 * sliver does, up to the sliver's own time shift (|v| <= 3.2 here), and the multiplier right
 * after the sliver is the one of its state. */
static void sliver_steps_do_not_derail_the_run(void **state)
{
    (void)state;
    const double slivers[] = {1e-16, 1e-14, 1e-12, 1e-10, 1e-8, 1e-6};
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double q0[2], lambda0, unused;
        assert_int_equal(
            pendulum_with_sliver(formulation, 0.0, 0, q0, &lambda0, &unused, &unused), GA_OK);
        for (size_t k = 0; k < sizeof slivers / sizeof slivers[0]; ++k)
            for (int count = 1; count <= 2; ++count) {
                double q[2], lambda, after, consistent;
                const ga_status st = pendulum_with_sliver(formulation, slivers[k], count, q,
                                                          &lambda, &after, &consistent);
                const double dq = max_abs_diff(q, q0, 2);
                printf("  %s, %d sliver(s) of %.0e: %s, |q - q without| = %.1e, lambda after "
                       "them off by %.1e\n",
                       formulation == GA_INDEX3 ? "index 3" : "index 2", count, slivers[k],
                       ga_strerror(st), dq, fabs(after - consistent));
                assert_int_equal(st, GA_OK);
                assert_true(dq <= 3.2 * count * slivers[k] + 1e-7);
                assert_true(fabs(lambda - lambda0) <=
                            1e-5 * fabs(lambda0) + 100.0 * count * slivers[k]);
                assert_true(fabs(after - consistent) <= 1e-9 * fabs(consistent));
            }
    }
}

/* A caller who lowers h for good (here 200 times: steps of 1e-2, then of 5e-5) gets steps of
 * Algorithm 1: only the first short steps, up to 1/100 of the long one, are Taylor steps.
 * All of them were, because a sliver leaves h_last: 10 000 steps without a Newton iteration,
 * with the constraint drifting. */
static void lowering_h_for_good_gives_algorithm_1_steps(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double q[2], v[2], t, h_last, phi;
        long long iters0, iters1;
        ga_solver *s = pendulum_new_solver(&p, 1);
        assert_non_null(s);
        assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
        pendulum_state(&p, 1.0, 0.5, q, v);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        for (int k = 0; k < 50; ++k)
            assert_int_equal(ga_step(s, 1e-2), GA_OK);
        ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters0);
        /* what the short steps should do: those of a solver started (ga_init) there */
        double t_half, q_fresh[2];
        ga_solver *fresh = pendulum_new_solver(&p, 1);
        assert_non_null(fresh);
        assert_int_equal(ga_set_formulation(fresh, formulation), GA_OK);
        ga_get_t(s, &t_half);
        ga_get_q(s, q);
        ga_get_v(s, v);
        assert_int_equal(ga_init(fresh, t_half, q, v), GA_OK);
        for (int k = 0; k < 10000; ++k) {
            assert_int_equal(ga_step(s, 5e-5), GA_OK);
            assert_int_equal(ga_step(fresh, 5e-5), GA_OK);
        }
        ga_get_q(fresh, q_fresh);
        ga_free(fresh);
        ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters1);
        ga_get_t(s, &t);
        ga_get_q(s, q);
        ga_get_h_last(s, &h_last);
        pendulum_constraint(t, q, &phi, &p);
        const pendulum_exact r = pendulum_reference(&p, 1.0, 0.5, t, 200000);
        const double eq = max_abs_diff(q, r.q, 2), eq_fresh = max_abs_diff(q_fresh, r.q, 2);
        printf("  %s: %lld Newton iterations in 10 000 short steps, h_last %g, |Phi| %.1e, "
               "error in q %.3e (a solver started at t = 0.5: %.3e)\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", iters1 - iters0, h_last,
               fabs(phi), eq, eq_fresh);
        assert_true(iters1 - iters0 >= 10000 - 2); /* two slivers: 1e-4 is 1/100 of 1e-2 */
        assert_true(h_last == 5e-5);
        assert_true(fabs(phi) <= 1e-12);
        assert_true(eq <= 1.01 * eq_fresh);
        ga_free(s);
    }
}

/* The pendulum (exact K_t): `count` steps of h1, then steps of h2 up to about t = 1; the
 * errors in q and lambda at the end against the RK4 reference of helpers.h. */
static void pendulum_two_step_sizes(int formulation, int count, double h1, double h2,
                                    double *err_q, double *err_lambda)
{
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2], lambda, t;
    ga_solver *s = pendulum_new_solver(&p, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    pendulum_state(&p, 1.0, 0.5, q, v);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < count; ++k)
        assert_int_equal(ga_step(s, h1), GA_OK);
    const int rest = (int)floor((1.0 - count * h1) / h2);
    for (int k = 0; k < rest; ++k)
        assert_int_equal(ga_step(s, h2), GA_OK);
    ga_get_t(s, &t);
    ga_get_q(s, q);
    ga_get_lambda(s, &lambda);
    const pendulum_exact r = pendulum_reference(&p, 1.0, 0.5, t, 200000);
    *err_q = max_abs_diff(q, r.q, 2);
    *err_lambda = fabs(lambda - r.lambda);
    ga_free(s);
}

/* A step over 100 times longer than the one before starts like a first one (corrected
 * starting values from consistent accelerations): rescaling a_n - qdd_n by h / h_last = 1e4
 * multiplied its round-off (in index 3 the multiplier of steps of 1e-6 is known only to
 * eps / (beta h^2) ~ 1e-3), and the index-3 multiplier was still 0.3 off after 99 more steps.
 * It starts from consistent accelerations and multipliers too: those of index-3 steps of 1e-10
 * are known only to eps / (beta h^2), far beyond their own size, and steps of 1e-2 after
 * 1 000 of them ended 1.1 off in q. Now 1 000 steps of 1e-6, 1e-8 or 1e-10 and then steps of 1e-2 end with
 * the errors of steps of 1e-2. */
static void long_step_after_short_ones_starts_afresh(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        double eq_uniform, el_uniform, eq, el;
        pendulum_two_step_sizes(formulation, 0, 1e-2, 1e-2, &eq_uniform, &el_uniform);
        for (double h_short = 1e-6; h_short > 1e-11; h_short *= 1e-2) {
            pendulum_two_step_sizes(formulation, 1000, h_short, 1e-2, &eq, &el);
            printf("  %s: steps of 1e-2: errors %.1e in q, %.1e in lambda; after 1000 of %g: "
                   "%.1e, %.1e\n",
                   formulation == GA_INDEX3 ? "index 3" : "index 2", eq_uniform, el_uniform,
                   h_short, eq, el);
            assert_true(eq <= 2.0 * eq_uniform);
            assert_true(el <= 2.0 * el_uniform);
        }
    }
}

/* A step shortened to land on t_stop was not the controller's choice: the step after it is
 * the one planned before. Output every 1e-3 by ga_advance, with steps of about 2e-3 planned,
 * takes one step per output interval (it took two: every landing step of 1e-3 made the next
 * proposal from itself); a landing sliver of 1e-13 (a t_stop that close) is followed by the
 * step planned before it (the next steps restarted from 1e-13 and needed ~80 steps to grow
 * back). */
static void landing_on_t_stop_keeps_the_planned_step(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2];
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        ga_solver *s = pendulum_new_solver(&p, 1);
        assert_non_null(s);
        assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
        assert_int_equal(ga_set_tolerances(s, 2e-4, 2e-4), GA_OK);
        pendulum_state(&p, 1.0, 0.5, q, v);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        for (int k = 0; k < 500; ++k)
            assert_int_equal(ga_advance(s, 1e-3 * (k + 1)), GA_OK);
        long long steps = 0;
        double planned = 0.0, t = 0.0, h = 0.0;
        ga_get_counter(s, GA_COUNT_STEPS, &steps);
        ga_get_info(s, GA_INFO_H_NEXT, &planned);
        printf("  %s: 500 output intervals of 1e-3 in %lld steps, step planned %.2e\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", steps, planned);
        assert_true(planned > 1e-3);
        assert_true(steps <= 510);
        ga_get_t(s, &t);
        double h_before = 0.0;
        ga_get_h_last(s, &h_before);
        assert_int_equal(ga_step_adaptive(s, t + 1e-13), GA_OK); /* the sliver */
        ga_get_h_last(s, &h);
        assert_true(h == h_before); /* a Taylor step: h_last stays that of the step before */
        assert_int_equal(ga_step_adaptive(s, 1.0), GA_OK);
        ga_get_h_last(s, &h);
        assert_true(h == planned);
        ga_free(s);
    }
}

/* ---- rho_inf = 1: no adaptive steps in index 3 (docs/algorithms.md 1.4, 6.2) ------------------- */
/* In index 3 a change of h starts a transient of qdd and lambda with the double root -rho_inf:
 * at rho_inf = 1 it never decays and the error estimate shrinks the steps without end (a
 * double pendulum took 11 million steps to t = 0.36 before GA_ERR_STEP_SIZE). The call is
 * refused before any work; index 2, and a system without constraints, run at rho_inf = 1 in
 * about as many steps as at 0.9. */
static long long adaptive_steps_to(ga_solver *s, double t_end)
{
    long long steps = -1;
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_advance(s, t_end), GA_OK);
    assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, &steps), GA_OK);
    return steps;
}

/* the pendulum ODE of the rescaling test above, without constraints */
static long long oscillator_steps(double rho)
{
    ga_solver *s = NULL;
    double q = 1.0, v = 0.0;
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pend_ode_mass, pend_ode_force, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, rho), GA_OK);
    assert_int_equal(ga_init(s, 0.0, &q, &v), GA_OK);
    const long long steps = adaptive_steps_to(s, 5.0);
    ga_free(s);
    return steps;
}

static void rho_one_adaptive_needs_index2_or_no_constraints(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(1.0, GA_INDEX3, 1, 1);
    double before[CKPT_PENDULUM], after[CKPT_PENDULUM];
    long long residuals = -1, steps = -1;
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_get_state(s, before, CKPT_PENDULUM), GA_OK);
    assert_int_equal(ga_step_adaptive(s, 1.0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "need rho_inf < 1"));
    assert_int_equal(ga_advance(s, 1.0), GA_ERR_ARG);
    assert_int_equal(ga_get_state(s, after, CKPT_PENDULUM), GA_OK);
    assert_memory_equal(before, after, sizeof before);
    assert_int_equal(ga_get_counter(s, GA_COUNT_RESIDUALS, &residuals), GA_OK);
    assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, &steps), GA_OK);
    assert_true(residuals == 0 && steps == 0);
    /* fixed steps stay allowed: with the corrected start they converge (test above) */
    assert_int_equal(ga_step(s, 1e-3), GA_OK);
    ga_free(s);

    s = pendulum_solver(1.0, GA_INDEX2_STABILIZED, 1, 1);
    const long long i2_rho1 = adaptive_steps_to(s, 1.0);
    ga_free(s);
    s = pendulum_solver(0.9, GA_INDEX2_STABILIZED, 1, 1);
    const long long i2_rho09 = adaptive_steps_to(s, 1.0);
    ga_free(s);
    const long long osc_rho1 = oscillator_steps(1.0), osc_rho09 = oscillator_steps(0.9);
    printf("  adaptive steps at rho_inf = 1 (0.9): pendulum in index 2 %lld (%lld), oscillator "
           "without constraints %lld (%lld)\n", i2_rho1, i2_rho09, osc_rho1, osc_rho09);
    assert_true(i2_rho1 <= 2 * i2_rho09);
    assert_true(osc_rho1 <= 2 * osc_rho09);
}

/* Adaptive steps after fixed ones, index 3: the pendulum after 50 steps of 1e-2, then rtol 1e-6
 * to t = 1. A version of the index-3 estimate's check from a that subtracted a's round-off made
 * the error jump between 0 and O(1) after each growth of h; the predictive controller read
 * that as an error growing fast and shrank h fivefold each time: 2.5 million steps for this
 * half second. Error control at rtol 1e-6 over half a swing of an order-2 method needs about a
 * thousand. */
static void adaptive_after_fixed_steps_keeps_its_steps(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2];
    pendulum_state(&p, 1.0, 0.5, q, v);
    ga_solver *s = pendulum_new_solver(&p, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < 50; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_advance(s, 1.0), GA_OK);
    long long steps = 0;
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    printf("  pendulum, 50 fixed steps then rtol 1e-6 to t = 1: %lld steps\n", steps);
    assert_true(steps < 5000);
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(rescaling_keeps_order_two_under_random_steps),
        cmocka_unit_test(a_step_that_does_not_move_t_is_refused),
        cmocka_unit_test(without_rescaling_alternating_steps_lose_an_order),
        cmocka_unit_test(index2_multipliers_stay_second_order_across_step_changes),
        cmocka_unit_test(corrected_start_removes_the_first_order_transient),
        cmocka_unit_test(rho_one_needs_the_corrected_start),
        cmocka_unit_test(rho_one_adaptive_needs_index2_or_no_constraints),
        cmocka_unit_test(sliver_steps_do_not_derail_the_run),
        cmocka_unit_test(lowering_h_for_good_gives_algorithm_1_steps),
        cmocka_unit_test(landing_on_t_stop_keeps_the_planned_step),
        cmocka_unit_test(long_step_after_short_ones_starts_afresh),
        cmocka_unit_test(error_estimate_tends_to_the_true_local_error),
        cmocka_unit_test(advance_lands_on_every_output_time),
        cmocka_unit_test(interpolation_agrees_with_a_step_ending_there),
        cmocka_unit_test(slider_crank_runs_adaptively_to_its_end),
        cmocka_unit_test(andrews_error_follows_the_tolerance),
        cmocka_unit_test(andrews_adaptive_needs_2_5x_fewer_residuals_than_fixed_steps),
        cmocka_unit_test(adaptive_newton_tolerance_follows_rtol),
        cmocka_unit_test(step_size_floor_is_reported),
        cmocka_unit_test(adaptive_steps_retry_after_recoverable_failures),
        cmocka_unit_test(adaptive_fatal_failure_keeps_the_last_accepted_step),
        cmocka_unit_test(adaptive_steps_retry_after_newton_failures),
        cmocka_unit_test(step_size_ceiling_and_proposals),
        cmocka_unit_test(adaptive_after_fixed_steps_keeps_its_steps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
