/* The Newton stopping test keeps its meaning for every h. One step of the pendulum is
 * compared with the exact solution of the same discrete equations, computed here
 * independently in long double (64-bit mantissa). The paper's absolute test on the scaled
 * residual would accept the predictor itself once h is small (checked below), so a step
 * with lambda = 0 would pass; galpha's increment test must not accept anything short of the
 * discrete solution, down to h = 1e-7, where only round-off (eps |q| / (beta h^2)) limits
 * the multiplier. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <float.h>
#include <math.h>

#include <galpha.h>

#include "helpers.h"

static pendulum P = {1.0, 1.0, 9.81};

typedef struct step_data {
    double q[2], v[2], qdd[2], a[2], lambda;
} step_data;

/* The discrete equations of one generalized-alpha step for the pendulum (unknowns qdd1,
 * lambda1), solved by Newton in long double. */
static void reference_step(const step_data *n, double h, const double prm[4], long double qdd1[2],
                           long double *lam)
{
    const long double am = prm[0], af = prm[1], beta = prm[2];
    const long double m = P.mass, g = P.gravity, L = P.length, H = h;
    const long double c = H * H * beta * (1 - af) / (1 - am); /* d q1 / d qdd1 */
    qdd1[0] = n->qdd[0];
    qdd1[1] = n->qdd[1];
    *lam = n->lambda;
    for (int it = 0; it < 60; ++it) {
        long double q1[2];
        for (int i = 0; i < 2; ++i) {
            const long double a1 = (af * n->qdd[i] - am * n->a[i] + (1 - af) * qdd1[i]) / (1 - am);
            q1[i] = n->q[i] + H * n->v[i] + H * H * ((0.5L - beta) * n->a[i] + beta * a1);
        }
        const long double F[3] = {m * qdd1[0] + q1[0] * *lam, m * qdd1[1] + m * g + q1[1] * *lam,
                                  0.5L * (q1[0] * q1[0] + q1[1] * q1[1] - L * L)};
        /* J = [m + c lam, 0, q1x; 0, m + c lam, q1y; c q1x, c q1y, 0]: solve by elimination */
        const long double d = m + c * *lam;
        /* from rows 1, 2: dqdd_i = -(F_i + q1_i dl)/d; row 3: c (q1 . dqdd) = -F3 */
        const long double qq = q1[0] * q1[0] + q1[1] * q1[1];
        const long double dl = (F[2] * d / c - (q1[0] * F[0] + q1[1] * F[1])) / qq;
        qdd1[0] += -(F[0] + q1[0] * dl) / d;
        qdd1[1] += -(F[1] + q1[1] * dl) / d;
        *lam += dl;
    }
}

/* The pendulum after 20 steps of 1e-3 and then steps ten times shorter each, down to 10 h:
 * the step of h to be checked is at most ten times shorter than the one before (a step over a
 * hundred times shorter is a Taylor step, with accelerations and multipliers from the
 * acceleration-level equations instead of its own discrete ones; test_adaptive.c). */
static ga_solver *start(int pred, step_data *n, double h)
{
    ga_solver *s = NULL;
    double buf[CKPT_PENDULUM];
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &P),
                     GA_OK);
    assert_int_equal(ga_set_predictor(s, pred), GA_OK);
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK); /* the step's own solution */
    /* the reference below solves the scheme with a_n as stored (no rescaling to the new h) */
    assert_int_equal(ga_set_rescale(s, 0), GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, pendulum_constraint_accel), GA_OK);
    pendulum_state(&P, 1.0, 0.5, n->q, n->v);
    assert_int_equal(ga_init(s, 0.0, n->q, n->v), GA_OK);
    for (int i = 0; i < 20; ++i) /* leave the start-up so that a_n differs from qdd_n */
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
    for (double shorter = 1e-4; shorter > 5.0 * h; shorter /= 10.0)
        assert_int_equal(ga_step(s, shorter), GA_OK);
    assert_int_equal(ga_get_state(s, buf, sizeof buf / sizeof buf[0]), GA_OK);
    for (int i = 0; i < 2; ++i) {
        n->q[i] = buf[CKPT_HEADER + i];
        n->v[i] = buf[CKPT_HEADER + 2 + i];
        n->qdd[i] = buf[CKPT_HEADER + 4 + i];
        n->a[i] = buf[CKPT_HEADER + 7 + i];
    }
    n->lambda = buf[CKPT_HEADER + 6];
    return s;
}

/* What the paper's absolute test on the scaled residual sees at the predictor
 * qdd_{n+1} = 0, lambda_{n+1} = 0 (Algorithm 1, lines 1-7). */
static double paper_scaled_residual_at_zero_predictor(const step_data *n, double h,
                                                      const double prm[4])
{
    const double am = prm[0], af = prm[1], beta = prm[2];
    double q1[2];
    for (int i = 0; i < 2; ++i) {
        const double a1 = (af * n->qdd[i] - am * n->a[i]) / (1 - am);
        q1[i] = n->q[i] + h * n->v[i] + h * h * ((0.5 - beta) * n->a[i] + beta * a1);
    }
    const double rq = P.mass * P.gravity; /* M*0 - f + Phi_q^T 0 = (0, m g) */
    const double phi = 0.5 * (q1[0] * q1[0] + q1[1] * q1[1] - P.length * P.length);
    return sqrt(pow(beta * h * h * rq, 2) + phi * phi);
}

/* One step of h after start(pred, n, h) -- Newton tolerance tol (0: the default), full Newton
 * if asked -- against the long-double solution of the same step (reference_step). */
typedef struct checked_step {
    long long iterations;
    double prm[4];            /* alpha_m, alpha_f, beta, gamma */
    double lambda_error, qdd_error, lambda_ref;
    double floor;             /* round-off floor of the index-3 multiplier */
} checked_step;

static checked_step check_step(int pred, double h, double tol, int full_newton, step_data *n)
{
    checked_step r;
    double qdd[2], lambda;
    long long it0, it1;
    ga_solver *s = start(pred, n, h);
    if (tol > 0.0)
        assert_int_equal(ga_set_newton(s, tol, 20), GA_OK);
    if (full_newton)
        assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
    ga_get_params(s, &r.prm[0], &r.prm[1], &r.prm[2], &r.prm[3]);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it0);
    assert_int_equal(ga_step(s, h), GA_OK);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it1);
    ga_get_qdd(s, qdd);
    ga_get_lambda(s, &lambda);
    ga_free(s);
    long double rq[2], rl;
    reference_step(n, h, r.prm, rq, &rl);
    r.iterations = it1 - it0;
    r.lambda_ref = (double)rl;
    r.lambda_error = fabs(lambda - (double)rl);
    r.qdd_error = fmax(fabs(qdd[0] - (double)rq[0]), fabs(qdd[1] - (double)rq[1]));
    /* Phi is known to ~eps |q|^2, which moves q1 by eps |q| and lambda by that over
     * c = beta h^2 (1-af)/(1-am) */
    const double c = h * h * r.prm[2] * (1 - r.prm[1]) / (1 - r.prm[0]);
    r.floor = DBL_EPSILON / c;
    return r;
}

/* Below the round-off floor (tol 1e-15 against a floor of ~1e-12 |lambda| and more) a step
 * ends by the round-off exit; with a matrix factorized in the step, at the first position
 * increment at round-off (newton.cpp; the rule itself: test_convergence.cpp). Full Newton, a
 * matrix at every iterate, so that no contraction rate ends the iteration first: the result
 * must be as close to the long-double solution of the step as the floor allows (at h = 1e-3
 * the iteration stops after 2 increments where waiting for a second one at round-off took 3). */
static void roundoff_exit_keeps_the_floor(void **state)
{
    (void)state;
    const double hs[] = {1e-2, 1e-3, 1e-4};
    for (size_t k = 0; k < sizeof hs / sizeof hs[0]; ++k) {
        step_data n;
        const checked_step r = check_step(0, hs[k], 1e-15, 1, &n);
        printf("  h = %-6g tol 1e-15, full Newton: %lld iterations, |lambda - ref| = %.2e, "
               "|qdd - ref| = %.2e (floor %.1e)\n",
               hs[k], r.iterations, r.lambda_error, r.qdd_error, r.floor);
        assert_true(r.lambda_error <= 8.0 * r.floor);
        assert_true(r.qdd_error <= 8.0 * r.floor);
    }
}

static void step_solution_is_converged_for_every_h(void **state)
{
    (void)state;
    const double hs[] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
    for (int pred = 0; pred < 2; ++pred) {
        for (size_t k = 0; k < sizeof hs / sizeof hs[0]; ++k) {
            step_data n;
            const checked_step r = check_step(pred, hs[k], 0.0, 0, &n);
            printf("  %s predictor h = %-6g: Newton it %lld, |lambda - ref| = %.2e, |qdd - ref| = "
                   "%.2e (round-off floor %.1e), paper's scaled residual at zero predictor "
                   "%.1e\n",
                   pred ? "zero    " : "constant", hs[k], r.iterations, r.lambda_error,
                   r.qdd_error, r.floor,
                   paper_scaled_residual_at_zero_predictor(&n, hs[k], r.prm));
            assert_true(r.lambda_error <= 1e-9 * fabs(r.lambda_ref) + 8.0 * r.floor);
            assert_true(r.qdd_error <= 1e-9 * 10.0 + 8.0 * r.floor);
        }
    }
}

/* The reason: at h = 1e-6 the paper's absolute test with tol = 1e-10 on the scaled residual
 * would already be satisfied by the zero predictor, whose multiplier is 0 instead of ~7. */
static void paper_test_on_scaled_residual_would_accept_the_predictor(void **state)
{
    (void)state;
    step_data n;
    double prm[4];
    ga_solver *s = start(GA_PREDICTOR_ZERO, &n, 1e-6);
    ga_get_params(s, &prm[0], &prm[1], &prm[2], &prm[3]);
    assert_true(paper_scaled_residual_at_zero_predictor(&n, 1e-6, prm) < 1e-10);
    assert_true(n.lambda > 5.0);
    ga_free(s);
}

/* q'' = -q, one step of h = 1 with rho_inf = 0 from q = 1, v = 0, qdd = -1, a = 0. The
 * simplified iteration (K_t neglected) contracts with rate 1/2, and its first increment moves
 * qdd from exactly 0 (an infinite relative increment): a rate measured against that infinity
 * would be 0 and accept the second iterate (q = 1/2; the discrete solution is q = 2/3). */
static int sdof_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}
static int sdof_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -q[0];
    return 0;
}

static int stiff_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -1e6 * q[0]; /* omega = 1e3 */
    return 0;
}

static void no_rate_is_measured_against_an_infinite_increment(void **state)
{
    (void)state;
    /* rho_inf = 0: alpha_m = -1, alpha_f = 0, beta = 1 (eq. 24). The step's equations are
     * linear in qdd1: a1 = (alpha_f qdd0 - alpha_m a0 + (1 - alpha_f) qdd1) / (1 - alpha_m)
     * (eq. 3), q1 = q0 + h v0 + h^2 ((1/2 - beta) a0 + beta a1) (eq. 4), qdd1 = -q1. */
    const double am = -1.0, af = 0.0, beta = 1.0, h = 1.0;
    const double q0 = 1.0, v0 = 0.0, qdd0 = -1.0, a0 = 0.0;
    /* q1 = c0 + c1 qdd1 with */
    const double c0 = q0 + h * v0 + h * h * ((0.5 - beta) * a0 +
                                             beta * (af * qdd0 - am * a0) / (1.0 - am));
    const double c1 = h * h * beta * (1.0 - af) / (1.0 - am);
    const double q1 = c0 / (1.0 + c1); /* qdd1 = -q1 */
    assert_true(fabs(q1 - 2.0 / 3.0) < 1e-15);
    for (int mode = GA_TANGENT_AUTO; mode <= GA_TANGENT_NEGLECT; ++mode) {
        ga_solver *s = NULL;
        /* a layout-2 checkpoint (read as a restart): this state, after a step of h */
        double buf[14] = {26465.0, 2.0, 1, 0, 0.0, h, 0.0, 1.0, 0.0, q0, v0, qdd0, a0, a0};
        double q;
        assert_int_equal(ga_create(1, 0, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, sdof_mass, sdof_force, NULL, NULL, NULL), GA_OK);
        assert_int_equal(ga_set_rho_inf(s, 0.0), GA_OK);
        assert_int_equal(ga_set_newton(s, 1e-12, 80), GA_OK);
        assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
        assert_int_equal(ga_set_state(s, buf, 14), GA_OK);
        assert_int_equal(ga_step(s, h), GA_OK);
        assert_int_equal(ga_get_q(s, &q), GA_OK);
        assert_true(fabs(q - q1) < 1e-11);
        ga_free(s);
    }
}

/* GA_TANGENT_AUTO without tangent callbacks: finite-difference tangents only where they matter.
 * Pendulum, h = 1e-3: beta' M dominates beta h^2 K_t, the simplified iteration contracts
 * fast, and no tangent is evaluated. q'' = -omega^2 q with omega h = 10: it contracts at
 * ~ (omega h)^2 beta > 1 without K_t, so the tangent comes in. Either way the step is the
 * discrete solution: the same as with finite-difference tangents throughout (GA_TANGENT_FD). */
static void run_tangents(int mode, int stiff, double h, double *q_end, long long *tangent_evals)
{
    ga_solver *s = NULL;
    double q[2], v[2] = {0.0, 0.0};
    if (stiff) {
        assert_int_equal(ga_create(1, 0, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, sdof_mass, stiff_force, NULL, NULL, NULL), GA_OK);
        q[0] = 1.0;
    } else {
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                          pendulum_jacobian, &P),
                         GA_OK);
        pendulum_state(&P, 1.0, 0.5, q, v);
    }
    assert_int_equal(ga_set_rho_inf(s, 0.9), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 40), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < 50; ++k)
        assert_int_equal(ga_step(s, h), GA_OK);
    assert_int_equal(ga_get_q(s, q_end), GA_OK);
    assert_int_equal(ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, tangent_evals), GA_OK);
    ga_free(s);
}

static void missing_tangents_are_computed_only_where_they_matter(void **state)
{
    (void)state;
    double q_auto[2], q_fd[2];
    long long n_auto, n_fd;
    run_tangents(GA_TANGENT_AUTO, 0, 1e-3, q_auto, &n_auto);
    run_tangents(GA_TANGENT_FD, 0, 1e-3, q_fd, &n_fd);
    printf("  pendulum, h = 1e-3: %lld tangent evaluations (finite differences throughout: "
           "%lld), |dq| = %.2e\n",
           n_auto, n_fd, max_abs_diff(q_auto, q_fd, 2));
    assert_int_equal(n_auto, 0);
    assert_true(n_fd > 0);
    assert_true(max_abs_diff(q_auto, q_fd, 2) < 1e-10);
    run_tangents(GA_TANGENT_AUTO, 1, 1e-2, q_auto, &n_auto);
    run_tangents(GA_TANGENT_FD, 1, 1e-2, q_fd, &n_fd);
    printf("  q'' = -omega^2 q, omega h = 10: %lld tangent evaluations (%lld), |dq| = %.2e\n",
           n_auto, n_fd, fabs(q_auto[0] - q_fd[0]));
    assert_true(n_auto > 0);
    assert_true(fabs(q_auto[0] - q_fd[0]) < 1e-12);
}

/* Velocity-dependent forces: three damped oscillators q_i'' = -k_i q_i - c_i q_i' (m = 0) with
 * c_i h up to 10, where the damping tangent C_t = diag(c) dominates the iteration matrix
 * beta' M + gamma' C_t + K_t. The steps are linear, so their exact solution is the recurrence
 * of eqs. (3)-(5) solved by hand below; galpha must reach it with C_t from the callback, from
 * dense finite differences (one force call per column) and from sparse ones on a declared
 * diagonal pattern (one force call for all columns; both computed only once the simplified
 * iteration without C_t has failed, GA_TANGENT_AUTO), and cannot without C_t. */
enum { NOSC = 3 };
typedef struct oscillators {
    double k[NOSC], c[NOSC];
    int sparse; /* matrices as the values of diagonal patterns instead of dense n x n */
} oscillators;

static void write_diagonal(const oscillators *o, const double *d, double *out)
{
    for (int i = 0; i < NOSC * NOSC && !o->sparse; ++i)
        out[i] = 0.0;
    for (int i = 0; i < NOSC; ++i)
        out[o->sparse ? i : i * (NOSC + 1)] = d[i];
}
static int osc_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q;
    const double one[NOSC] = {1.0, 1.0, 1.0};
    write_diagonal(u, one, M);
    return 0;
}
static int osc_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t;
    const oscillators *o = u;
    for (int i = 0; i < NOSC; ++i)
        f[i] = -o->k[i] * q[i] - o->c[i] * v[i];
    return 0;
}
static int osc_stiffness(double t, const double *q, const double *v, const double *qdd,
                         const double *lambda, double *K, void *u)
{
    (void)t, (void)q, (void)v, (void)qdd, (void)lambda;
    write_diagonal(u, ((const oscillators *)u)->k, K);
    return 0;
}
static int osc_damping(double t, const double *q, const double *v, double *C, void *u)
{
    (void)t, (void)q, (void)v;
    write_diagonal(u, ((const oscillators *)u)->c, C);
    return 0;
}

typedef struct damped_run {
    ga_status status;
    double q[NOSC], v[NOSC];
    long long newton, damping_evals, force_evals, residuals, steps;
} damped_run;

static damped_run run_damped(oscillators *o, ga_damping_fn damping, int mode, double h,
                             int steps)
{
    damped_run r = {0};
    ga_solver *s = NULL;
    const double q0[NOSC] = {1.0, 1.0, 1.0}, v0[NOSC] = {0.0, 0.0, 0.0};
    assert_int_equal(ga_create(NOSC, 0, &s), GA_OK);
    if (o->sparse) {
        const int diag[NOSC] = {0, 1, 2};
        for (int w = GA_MATRIX_MASS; w <= GA_MATRIX_DAMPING; ++w)
            if (w != GA_MATRIX_JACOBIAN)
                assert_int_equal(ga_set_pattern(s, w, NOSC, diag, diag), GA_OK);
        assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    }
    assert_int_equal(ga_set_callbacks(s, osc_mass, osc_force, NULL, NULL, o), GA_OK);
    assert_int_equal(ga_set_tangents(s, osc_stiffness, damping), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, 0.8), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-12, 10), GA_OK);
    assert_int_equal(ga_set_corrected_start(s, 0), GA_OK); /* a_0 = qdd_0, as below */
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    for (int k = 0; k < steps && !r.status; ++k)
        r.status = ga_step(s, h);
    ga_get_q(s, r.q);
    ga_get_v(s, r.v);
    ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &r.newton);
    ga_get_counter(s, GA_COUNT_DAMPING_EVALS, &r.damping_evals);
    ga_get_counter(s, GA_COUNT_FORCE_EVALS, &r.force_evals);
    ga_get_counter(s, GA_COUNT_RESIDUALS, &r.residuals);
    ga_free(s);
    return r;
}

static void damping_tangent_from_callback_or_differences(void **state)
{
    (void)state;
    oscillators o = {{100.0, 400.0, 2500.0}, {50.0, 200.0, 20.0}, 0};
    const double h = 0.05;
    const int steps = 40;
    /* alpha_m, alpha_f, beta, gamma from rho_inf = 0.8 (eq. 24) */
    const double rho = 0.8, am = (2 * rho - 1) / (rho + 1), af = rho / (rho + 1);
    const double gamma = 0.5 + af - am, beta = 0.25 * (gamma + 0.5) * (gamma + 0.5);
    double q_ref[NOSC], v_ref[NOSC];
    for (int i = 0; i < NOSC; ++i) {
        double q = 1.0, v = 0.0, qdd = -o.k[i], a = qdd;
        for (int n = 0; n < steps; ++n) {
            /* a1 = A0 + A1 qdd1, q1 = Q0 + h^2 beta A1 qdd1, v1 = V0 + h gamma A1 qdd1 */
            const double A0 = (af * qdd - am * a) / (1 - am), A1 = (1 - af) / (1 - am);
            const double Q0 = q + h * v + h * h * ((0.5 - beta) * a + beta * A0);
            const double V0 = v + h * ((1 - gamma) * a + gamma * A0);
            const double qdd1 = (-o.k[i] * Q0 - o.c[i] * V0) /
                                (1 + (o.k[i] * h * h * beta + o.c[i] * h * gamma) * A1);
            const double a1 = A0 + A1 * qdd1;
            q = Q0 + h * h * beta * A1 * qdd1;
            v = V0 + h * gamma * A1 * qdd1;
            qdd = qdd1;
            a = a1;
        }
        q_ref[i] = q;
        v_ref[i] = v;
    }
    const damped_run exact = run_damped(&o, osc_damping, GA_TANGENT_AUTO, h, steps);
    const damped_run dense_fd = run_damped(&o, NULL, GA_TANGENT_AUTO, h, steps);
    o.sparse = 1;
    const damped_run sparse_fd = run_damped(&o, NULL, GA_TANGENT_AUTO, h, steps);
    const damped_run sparse_exact = run_damped(&o, osc_damping, GA_TANGENT_AUTO, h, steps);
    o.sparse = 0;
    const damped_run neglected = run_damped(&o, osc_damping, GA_TANGENT_NEGLECT, h, steps);
    const damped_run *runs[] = {&exact, &dense_fd, &sparse_fd, &sparse_exact};
    const char *names[] = {"C_t by callback", "dense differences", "sparse differences",
                           "sparse, by callback"};
    for (int r = 0; r < 4; ++r) {
        const damped_run *x = runs[r];
        printf("  %-20s %lld Newton iterations, %lld C_t evaluations, %lld force calls, "
               "%lld residuals, |q - q_ref| = %.1e, |v - v_ref| = %.1e\n",
               names[r], x->newton, x->damping_evals, x->force_evals, x->residuals,
               max_abs_diff(x->q, q_ref, NOSC), max_abs_diff(x->v, v_ref, NOSC));
        assert_int_equal(x->status, GA_OK);
        assert_true(max_abs_diff(x->q, q_ref, NOSC) < 1e-12);
        assert_true(max_abs_diff(x->v, v_ref, NOSC) < 1e-10);
        assert_true(x->damping_evals >= 1);
        assert_true(x->newton <= 2 * steps + 2); /* a linear step: one correction, one check */
        /* force calls: ga_init's one, one per residual, and those of the differences: a
         * column at a time in a dense C_t, all three columns of the diagonal pattern at once */
        const long long per_difference = r == 1 ? NOSC : r == 2 ? 1 : 0;
        assert_int_equal(x->force_evals, 1 + x->residuals + per_difference * x->damping_evals);
    }
    printf("  C_t neglected: status %d after %lld steps\n", neglected.status, neglected.steps);
    assert_int_equal(neglected.status, GA_ERR_NEWTON);
}

/* GA_REUSE_NEVER is Algorithm 1 as printed: a fresh tangent and factorization in every
 * iteration. The default keeps the factorization and makes fewer; both reach the same
 * discrete solution. GA_INFO_NEWTON_ITERS is the last step's share of the counter, and
 * ga_reset_counters starts them all again from zero. */
static void full_newton_factorizes_every_iteration(void **state)
{
    (void)state;
    double q_end[2][2];
    long long iters[2], facts[2];
    for (int mode = GA_REUSE_AUTO; mode <= GA_REUSE_NEVER; ++mode) {
        double q[2], v[2], info;
        pendulum_state(&P, 1.0, 0.5, q, v);
        ga_solver *s = pendulum_new_solver(&P, 1);
        assert_non_null(s);
        assert_int_equal(ga_set_newton(s, 1e-12, 20), GA_OK);
        assert_int_equal(ga_set_jacobian_reuse(s, mode), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        assert_int_equal(ga_reset_counters(s), GA_OK); /* drop ga_init's work */
        for (int c = 0; c < GA_COUNTER_COUNT; ++c) {
            long long value = -1;
            assert_int_equal(ga_get_counter(s, c, &value), GA_OK);
            assert_int_equal(value, 0);
        }
        long long it_before = 0, it_after, fa_before = 0, fa_after, stiff;
        for (int k = 0; k < 100; ++k) {
            assert_int_equal(ga_step(s, 1e-2), GA_OK);
            ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it_after);
            ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &fa_after);
            assert_int_equal(ga_get_info(s, GA_INFO_NEWTON_ITERS, &info), GA_OK);
            assert_true(info == (double)(it_after - it_before));
            assert_int_equal(ga_get_info(s, GA_INFO_NEWTON_RATIO, &info), GA_OK);
            assert_true(info >= 0.0 && isfinite(info));
            /* (the first step's corrected start factorizes for solves of its own) */
            if (mode == GA_REUSE_NEVER && k > 0)
                assert_int_equal(fa_after - fa_before, it_after - it_before);
            it_before = it_after;
            fa_before = fa_after;
        }
        ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &stiff);
        ga_get_q(s, q_end[mode]);
        iters[mode] = it_before;
        facts[mode] = fa_before;
        if (mode == GA_REUSE_NEVER)
            assert_int_equal(stiff, iters[mode]); /* a tangent in every iteration */
        ga_free(s);
    }
    printf("  100 pendulum steps: reuse %lld factorizations / %lld iterations, full Newton "
           "%lld / %lld, |dq| = %.1e\n",
           facts[0], iters[0], facts[1], iters[1], max_abs_diff(q_end[0], q_end[1], 2));
    assert_true(facts[0] < facts[1]);
    assert_true(max_abs_diff(q_end[0], q_end[1], 2) < 1e-10);
}

/* The scaling (10): the condition number of the unscaled iteration matrix grows like h^-4,
 * that of the scaled one stays bounded (pendulum, h from 1e-1 to 1e-3); both give the same
 * steps where the unscaled matrix is still usable, and at h = 1e-6 only the scaled one is. */
static double condition_after_a_step(int scaling, double h, double *q)
{
    ga_solver *s = NULL;
    double v[2], rcond;
    pendulum_state(&P, 1.0, 0.5, q, v);
    s = pendulum_new_solver(&P, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_scaling(s, scaling), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(ga_step(s, h), GA_OK);
    assert_int_equal(ga_get_info(s, GA_INFO_RCOND, &rcond), GA_OK);
    ga_get_q(s, q);
    ga_free(s);
    return 1.0 / rcond;
}

static void scaling_keeps_the_condition_bounded(void **state)
{
    (void)state;
    enum { K = 5 };
    double h[K], cond[2][K], q_on[2], q_off[2];
    for (int k = 0; k < K; ++k) {
        h[k] = pow(10.0, -1.0 - 0.5 * k);
        cond[1][k] = condition_after_a_step(1, h[k], q_on);
        cond[0][k] = condition_after_a_step(0, h[k], q_off);
        printf("  h = %.0e: condition %.2e scaled, %.2e unscaled, |dq| = %.1e\n", h[k],
               cond[1][k], cond[0][k], max_abs_diff(q_on, q_off, 2));
        assert_true(max_abs_diff(q_on, q_off, 2) < 1e-12);
    }
    const double slope_on = fit_order(h, cond[1], K), slope_off = fit_order(h, cond[0], K);
    printf("  log-log slope of the condition against h: %.2f scaled, %.2f unscaled\n", slope_on,
           slope_off);
    assert_true(fabs(slope_on) < 0.3);
    assert_true(slope_off < -3.7 && slope_off > -4.3);
    /* where the unscaled matrix is singular to working precision, the scaled one is fine */
    const double cond_small_h = condition_after_a_step(1, 1e-6, q_on);
    printf("  h = 1e-6: condition %.2e scaled\n", cond_small_h);
    assert_true(cond_small_h < 10.0 * cond[1][0]);
    ga_solver *s = NULL;
    double q[2], v[2];
    pendulum_state(&P, 1.0, 0.5, q, v);
    s = pendulum_new_solver(&P, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_scaling(s, 0), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(ga_step(s, 1e-6), GA_ERR_SINGULAR);
    ga_free(s);
}

/* Full Newton (GA_REUSE_NEVER, exact K_t) on a fast pendulum, 0.2 rad per step: the
 * stabilized index-2 iteration converges like the index-3 one only with the curvature of the
 * velocity constraint, Z = d(Phi_q v)/dq, in its matrix (docs/algorithms.md sec. 2.2); without it
 * the iteration contracts linearly, at about h |v| / L = 0.2 per iteration. The tolerance,
 * 1e-10, is above the round-off floor of the accelerations (eps |q| / (beta h^2) ~ 1e-11
 * relative): below it the counts would measure the round-off exits, which differ between the
 * formulations by design (index 2 also waits for its Newmark increment), not the convergence. */
static double full_newton_iterations_per_step(int formulation)
{
    ga_solver *s = NULL;
    double q[2], v[2];
    pendulum_state(&P, 1.0, 20.0, q, v);
    s = pendulum_new_solver(&P, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-10, 30), GA_OK);
    assert_int_equal(ga_set_rho_inf(s, 0.5), GA_OK); /* index 3 stays stable at 0.2 rad/step */
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    long long iters;
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters);
    ga_free(s);
    return iters / 100.0;
}

static void index2_newton_converges_like_index3(void **state)
{
    (void)state;
    const double i3 = full_newton_iterations_per_step(GA_INDEX3);
    const double i2 = full_newton_iterations_per_step(GA_INDEX2_STABILIZED);
    printf("  full Newton, 0.2 rad per step: %.2f iterations per step in index 3, %.2f in "
           "index 2\n", i3, i2);
    assert_true(i2 <= i3 + 0.5);
}

/* ga_set_constant_mass: M is evaluated once - at ga_init, not again by the corrected start's
 * consistent accelerations, the steps, the index-2 system or the adaptive error projection -
 * and once more after an option that drops the matrix; without it, at every residual. */
static long long mass_evaluations(int constant, int formulation)
{
    ga_solver *s = NULL;
    double q[2], v[2];
    long long evals = 0, residuals = 0;
    pendulum_state(&P, 1.0, 0.5, q, v);
    s = pendulum_new_solver(&P, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_constant_mass(s, constant), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    for (int k = 0; k < 50; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_advance(s, 1.0), GA_OK);
    ga_get_counter(s, GA_COUNT_MASS_EVALS, &evals);
    ga_get_counter(s, GA_COUNT_RESIDUALS, &residuals);
    if (!constant)
        assert_true(evals > residuals);
    if (constant) { /* an option that changes the iteration matrix re-reads M once */
        long long after = 0;
        assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
        assert_int_equal(ga_advance(s, 1.5), GA_OK);
        ga_get_counter(s, GA_COUNT_MASS_EVALS, &after);
        assert_int_equal(after, evals + 1);
    }
    ga_free(s);
    return evals;
}

static void constant_mass_is_evaluated_once(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        const long long once = mass_evaluations(1, formulation);
        const long long every = mass_evaluations(0, formulation);
        printf("  %s: M evaluated %lld times (constant), %lld (not)\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", once, every);
        assert_int_equal(once, 1);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(step_solution_is_converged_for_every_h),
        cmocka_unit_test(roundoff_exit_keeps_the_floor),
        cmocka_unit_test(paper_test_on_scaled_residual_would_accept_the_predictor),
        cmocka_unit_test(no_rate_is_measured_against_an_infinite_increment),
        cmocka_unit_test(missing_tangents_are_computed_only_where_they_matter),
        cmocka_unit_test(damping_tangent_from_callback_or_differences),
        cmocka_unit_test(full_newton_factorizes_every_iteration),
        cmocka_unit_test(scaling_keeps_the_condition_bounded),
        cmocka_unit_test(index2_newton_converges_like_index3),
        cmocka_unit_test(constant_mass_is_evaluated_once),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
