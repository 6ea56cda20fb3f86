/* The discrete adjoint (ga_adjoint_gradient) against the forward sensitivities of the same run
 * (issue 20). A terminal cost linear in the final state, c . x_N, makes dJ/dp = c . sigma_N the
 * dot-product identity of the tangent map and its transpose: equal to round-off. Running costs
 * (the kinetic energy, a multiplier squared) against the forward sensitivities summed with the
 * same trapezoidal weights. Pendulum, slider-crank, sparse chain; index 3 and 2; fixed and
 * adaptive steps. Refusals and a full record. */
#include <limits.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "scene_catalog.h"

enum { kMaxP = 3, kMaxSteps = 5000 };

typedef struct setup {
    int scene, formulation, adaptive, steps;
    double t_end, tol;
    int np, depends;
    double *(*params)(void);
} setup;

static double *pendulum_gravity(void) { return &g_catalog_pendulum.gravity; }
static double *crank_masses_torque(void) { return &g_catalog_crank.m3; }
static double *chain_link(void) { return &g_catalog_chain.mass; }

/* the cost's weights: c . (q, v, qdd, lambda) at the end; running: |v|^2 / 2 + lambda_0^2 */
static double g_c[4][kCatalogMaxN];
static int g_n, g_m, g_np;

static int terminal_linear(double t, const double *q, const double *v, const double *qdd,
                           const double *lambda, double *value, double *d_q, double *d_v,
                           double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)user;
    double J = 0;
    for (int i = 0; i < g_n; ++i) {
        J += g_c[0][i] * q[i] + g_c[1][i] * v[i] + g_c[2][i] * qdd[i];
        d_q[i] = g_c[0][i], d_v[i] = g_c[1][i], d_qdd[i] = g_c[2][i];
    }
    for (int i = 0; i < g_m; ++i) {
        J += g_c[3][i] * lambda[i];
        d_lambda[i] = g_c[3][i];
    }
    for (int j = 0; j < g_np; ++j)
        d_p[j] = 0.0;
    *value = J;
    return 0;
}

static int running_energy_multiplier(double t, const double *q, const double *v,
                                     const double *qdd, const double *lambda, double *value,
                                     double *d_q, double *d_v, double *d_qdd, double *d_lambda,
                                     double *d_p, void *user)
{
    (void)t, (void)q, (void)qdd, (void)user;
    double J = 0;
    for (int i = 0; i < g_n; ++i) {
        J += 0.5 * v[i] * v[i];
        d_q[i] = 0.0, d_v[i] = v[i], d_qdd[i] = 0.0;
    }
    for (int i = 0; i < g_m; ++i)
        d_lambda[i] = 0.0;
    J += lambda[0] * lambda[0];
    d_lambda[0] = 2.0 * lambda[0];
    for (int j = 0; j < g_np; ++j)
        d_p[j] = 0.0;
    *value = J;
    return 0;
}

/* One run with forward sensitivities and the adjoint record: the adjoint's J and dJ/dp for the
 * terminal and the running cost, and the same from the forward sensitivities. */
static void compare(const setup *u, const char *label)
{
    catalog_scene sc = catalog_make(u->scene);
    g_n = sc.n, g_m = sc.m, g_np = u->np;
    srand(7);
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < kCatalogMaxN; ++i)
            g_c[k][i] = (double)rand() / RAND_MAX - 0.5;
    ga_solver *s = catalog_solver(&sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, u->formulation), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, u->np, u->params(), NULL, u->depends), GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT,
                                               kMaxSteps),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    if (u->adaptive)
        assert_int_equal(ga_set_tolerances(s, u->tol, u->tol), GA_OK);
    /* forward: dJ/dp of the running cost by the trapezoidal rule over the steps */
    double fwd_run[kMaxP] = {0}, run_prev[kMaxP], J_run = 0, L_prev = 0, t = 0, t_prev = 0;
    double q[kCatalogMaxN], v[kCatalogMaxN], qdd[kCatalogMaxN], lam[kCatalogMaxN];
    double d[4][kCatalogMaxN], grad[4][kCatalogMaxN], dp[kMaxP], L;
    int steps = 0;
    for (;;) {
        assert_int_equal(ga_get_q(s, q), GA_OK);
        assert_int_equal(ga_get_v(s, v), GA_OK);
        assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
        assert_int_equal(ga_get_qdd(s, qdd), GA_OK);
        assert_int_equal(ga_get_lambda(s, lam), GA_OK);
        running_energy_multiplier(t, q, v, qdd, lam, &L, grad[0], grad[1], grad[2], grad[3], dp,
                                  NULL);
        for (int j = 0; j < u->np; ++j) {
            assert_int_equal(ga_get_sensitivity(s, j, d[0], d[1], d[2], d[3]), GA_OK);
            double dL = 0;
            for (int k = 0; k < 4; ++k)
                for (int i = 0; i < (k == 3 ? sc.m : sc.n); ++i)
                    dL += grad[k][i] * d[k][i];
            if (steps > 0)
                fwd_run[j] += 0.5 * (t - t_prev) * (run_prev[j] + dL);
            run_prev[j] = dL;
        }
        if (steps > 0)
            J_run += 0.5 * (t - t_prev) * (L_prev + L);
        L_prev = L;
        t_prev = t;
        if (t >= (u->t_end > 0 ? u->t_end : sc.t_end) * (1 - 1e-12))
            break;
        const ga_status st = u->adaptive ? ga_step_adaptive(s, u->t_end) : ga_step(s, u->t_end / u->steps);
        assert_int_equal(st, GA_OK);
        assert_int_equal(ga_get_t(s, &t), GA_OK);
        ++steps;
    }
    /* c . sigma_N, with c on (q, v) only and on (q, v, qdd, lambda): the latter carries the
     * round-off of the step's qdd and lambda, eps / (beta h^2) relative to them in index 3 and
     * eps / (gamma h) in index 2 (paper, sec. 3.3) at each step, in each sweep: 3e-10 per step
     * at the adaptive pendulum's h = 1.6e-3 in index 3, over 600 steps */
    for (int full = 0; full < 2; ++full) {
        if (!full)
            for (int i = 0; i < kCatalogMaxN; ++i)
                g_c[2][i] = g_c[3][i] = 0.0;
        else
            for (int k = 2; k < 4; ++k)
                for (int i = 0; i < kCatalogMaxN; ++i)
                    g_c[k][i] = (double)rand() / RAND_MAX - 0.5;
        double fwd_lin[kMaxP] = {0};
        for (int j = 0; j < u->np; ++j) {
            assert_int_equal(ga_get_sensitivity(s, j, d[0], d[1], d[2], d[3]), GA_OK);
            for (int k = 0; k < 4; ++k)
                for (int i = 0; i < (k == 3 ? sc.m : sc.n); ++i)
                    fwd_lin[j] += g_c[k][i] * d[k][i];
        }
        double J, adj[kMaxP];
        assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, adj), GA_OK);
        const double bound = !full ? 1e-12 : u->formulation == GA_INDEX3 ? 1e-8 : 1e-10;
        for (int j = 0; j < u->np; ++j) {
            const double rel = fabs(adj[j] - fwd_lin[j]) / fmax(fabs(fwd_lin[j]), 1e-300);
            printf("  %-34s p%d  c.sigma_N (%s): forward %+.15e adjoint %+.15e (%.1e)\n", label,
                   j, full ? "q, v, qdd, lambda" : "q, v", fwd_lin[j], adj[j], rel);
            assert_true(rel < bound);
        }
    }
    double J, adj[kMaxP];
    assert_int_equal(ga_adjoint_gradient(s, running_energy_multiplier, NULL, &J, adj), GA_OK);
    assert_true(fabs(J - J_run) <= 1e-12 * fabs(J_run));
    for (int j = 0; j < u->np; ++j) {
        const double rel = fabs(adj[j] - fwd_run[j]) / fmax(fabs(fwd_run[j]), 1e-300);
        printf("  %-34s p%d  int(|v|^2/2 + lambda_0^2): forward %+.12e adjoint %+.12e (%.1e)\n",
               label, j, fwd_run[j], adj[j], rel);
        assert_true(rel < 1e-9);
    }
    printf("  %-34s %d steps\n", label, steps);
    ga_free(s);
}

static void run_list(const setup *list, int count, const char *name)
{
    for (int k = 0; k < count; ++k) {
        char label[80];
        snprintf(label, sizeof label, "%s %s %s", name,
                 list[k].formulation == GA_INDEX3 ? "index 3" : "index 2",
                 list[k].adaptive ? "adaptive" : "fixed");
        compare(&list[k], label);
    }
}

static void pendulum_adjoint(void **state)
{
    (void)state;
    const setup list[] = {
        {0, GA_INDEX3, 0, 200, 1.0, 0, 1, GA_DEPENDS_FORCE, pendulum_gravity},
        {0, GA_INDEX2_STABILIZED, 0, 200, 1.0, 0, 1, GA_DEPENDS_FORCE, pendulum_gravity},
        {0, GA_INDEX3, 1, 0, 1.0, 1e-4, 1, GA_DEPENDS_FORCE, pendulum_gravity},
        {0, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-5, 1, GA_DEPENDS_FORCE, pendulum_gravity},
    };
    run_list(list, 4, "pendulum gravity");
}

static void crank_adjoint(void **state)
{
    (void)state;
    const int md = GA_DEPENDS_FORCE | GA_DEPENDS_MASS;
    const setup list[] = {
        {1, GA_INDEX3, 0, 100, 0.5, 0, 3, md, crank_masses_torque},
        {1, GA_INDEX2_STABILIZED, 0, 100, 0.5, 0, 3, md, crank_masses_torque},
        {1, GA_INDEX2_STABILIZED, 1, 0, 0.5, 1e-5, 3, md, crank_masses_torque},
    };
    run_list(list, 3, "slider-crank");
}

static void chain_adjoint(void **state)
{
    (void)state;
    const int md = GA_DEPENDS_FORCE | GA_DEPENDS_MASS;
    const setup list[] = {
        {4, GA_INDEX3, 0, 100, 1.0, 0, 3, md, chain_link},
        {4, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-5, 3, md, chain_link},
    };
    run_list(list, 2, "chain (sparse)");
}


/* ---- refusals, a full record, steps the sweep does not cover ---- */
static int failing_cost(double t, const double *q, const double *v, const double *qdd,
                        const double *lambda, double *value, double *d_q, double *d_v,
                        double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    terminal_linear(t, q, v, qdd, lambda, value, d_q, d_v, d_qdd, d_lambda, d_p, user);
    return -2;
}

static ga_solver *pendulum_solver(int methods, long max_steps)
{
    catalog_scene sc = catalog_make(0);
    g_n = sc.n, g_m = sc.m, g_np = 1;
    ga_solver *s = catalog_solver(&sc);
    assert_int_equal(ga_set_sensitivity(s, 1, &g_catalog_pendulum.gravity, NULL,
                                        GA_DEPENDS_FORCE),
                     GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, methods, max_steps), GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    return s;
}

/* A free particle in gravity, exact for the scheme, in one step of 1e153: its state is finite
 * (q ~ -5e306), the sweep's products are not -- the gradient is refused, not NaN with GA_OK
 * (found by the API-sequence fuzzer). */
static double g_particle_gravity = 9.81;
static int particle_mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    M[0] = 1.0;
    return 0;
}
static int particle_force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t, (void)q, (void)v, (void)user;
    f[0] = -g_particle_gravity;
    return 0;
}
/* the same with air drag, and a call that fails (counted down; 0: none) */
static int g_particle_fail_at;
static int dragged_force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t, (void)q, (void)user;
    f[0] = -g_particle_gravity - 0.1 * v[0];
    return g_particle_fail_at > 0 && --g_particle_fail_at == 0;
}
static int particle_cost(double t, const double *q, const double *v, const double *qdd,
                         const double *lambda, double *value, double *d_q, double *d_v,
                         double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)v, (void)qdd, (void)lambda, (void)d_lambda, (void)user;
    d_q[0] = 1.0, d_v[0] = d_qdd[0] = d_p[0] = 0.0;
    *value = q[0];
    return 0;
}
static void an_overflowing_sweep_is_refused(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    const double q0 = 0.0, v0 = 1.0;
    double J = -1.0, dJ[1] = {-1.0};
    assert_int_equal(ga_create(1, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, particle_mass, particle_force, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 1, &g_particle_gravity, NULL, GA_DEPENDS_FORCE),
                     GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_OK);
    assert_int_equal(ga_init(s, 0.0, &q0, &v0), GA_OK);
    assert_int_equal(ga_adjoint_gradient(s, particle_cost, particle_cost, &J, dJ), GA_OK);
    assert_true(isfinite(J) && isfinite(dJ[0]));
    assert_int_equal(ga_step(s, 1e153), GA_OK);
    double q;
    assert_int_equal(ga_get_q(s, &q), GA_OK);
    assert_true(isfinite(q) && q < -1e306);
    J = dJ[0] = -1.0;
    const ga_status st = ga_adjoint_gradient(s, particle_cost, particle_cost, &J, dJ);
    if (st != GA_ERR_NONFINITE)
        print_error("%s\n", ga_last_error(s));
    assert_int_equal(st, GA_ERR_NONFINITE);
    assert_non_null(strstr(ga_last_error(s), "adjoint sweep overflowed"));
    assert_true(J == -1.0 && dJ[0] == -1.0); /* not written */
    ga_free(s);
}

/* A restart (ga_init) that fails after the start's derivatives were computed, at each force
 * call in turn, changes nothing of an adjoint-only run: its checkpoints stay those of a twin
 * that never made the call (but dropped its kept matrix, as a failed start does). (Its steps swapped the unused trial derivatives into the state:
 * after a start that failed, NaN there made the next restore -- the adjoint sweep's with
 * checkpoints -- refuse the run's own checkpoint, found by the API-sequence fuzzer.) */
static void a_failed_restart_changes_no_adjoint_run(void **state)
{
    (void)state;
    const double q0 = 0.0, v0 = 1.0, v_new = -2.0;
    int calls = 0;
    for (int k = 1; calls == 0 || k <= calls + 1; ++k) {
        ga_solver *s[2];
        double c[2][64];
        size_t len = 0;
        for (int i = 0; i < 2; ++i) {
            assert_int_equal(ga_create(1, 0, &s[i]), GA_OK);
            assert_int_equal(ga_set_callbacks(s[i], particle_mass, dragged_force, NULL, NULL,
                                              NULL),
                             GA_OK);
            assert_int_equal(ga_set_sensitivity(s[i], 1, &g_particle_gravity, NULL,
                                                GA_DEPENDS_FORCE),
                             GA_OK);
            assert_int_equal(ga_set_sensitivity_method(s[i], GA_SENSITIVITY_ADJOINT, 10), GA_OK);
            assert_int_equal(ga_init(s[i], 0.0, &q0, &v0), GA_OK);
            assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
        }
        long long before = 0, after = 0;
        assert_int_equal(ga_get_counter(s[0], GA_COUNT_FORCE_EVALS, &before), GA_OK);
        g_particle_fail_at = k;
        const ga_status st = ga_init(s[0], 0.01, &q0, &v_new);
        g_particle_fail_at = 0;
        /* (a failed start drops the kept matrix, as a failed step does: so does the twin) */
        assert_int_equal(ga_set_jacobian_reuse(s[1], GA_REUSE_AUTO), GA_OK);
        assert_int_equal(ga_get_counter(s[0], GA_COUNT_FORCE_EVALS, &after), GA_OK);
        if (st == GA_OK) { /* fewer calls than k: every one was failed in turn */
            calls = (int)(after - before);
            ga_free(s[0]);
            ga_free(s[1]);
            break;
        }
        for (int i = 0; i < 2; ++i) {
            for (int j = 0; j < 3; ++j)
                assert_int_equal(ga_step(s[i], 1e-2), GA_OK);
            assert_int_equal(ga_state_size(s[i], &len), GA_OK);
            assert_true(len <= 64);
            assert_int_equal(ga_get_state(s[i], c[i], len), GA_OK);
            ga_free(s[i]);
        }
        for (size_t e = 0; e < len; ++e)
            if (memcmp(&c[0][e], &c[1][e], sizeof(double)) != 0)
                fail_msg("a restart failing at force call %d changed the run (checkpoint entry "
                         "%zu: %.17g, not %.17g)", k, e, c[0][e], c[1][e]);
    }
    printf("  a restart failed at each of its %d force calls: the run as its twin's\n", calls);
    assert_true(calls > 2);
}

static void refusals(void **state)
{
    (void)state;
    catalog_scene sc = catalog_make(0);
    g_n = sc.n, g_m = sc.m, g_np = 1;
    ga_solver *s = catalog_solver(&sc);
    double J, dJ[1];
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "before ga_set_sensitivity"));
    assert_int_equal(ga_set_sensitivity(s, 1, &g_catalog_pendulum.gravity, NULL,
                                        GA_DEPENDS_FORCE),
                     GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, 0, 10), GA_ERR_ARG);
    assert_int_equal(ga_set_sensitivity_method(s, 4, 10), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "GA_SENSITIVITY_FORWARD"));
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "max_steps"));
    /* records beyond memory: refused before (max_steps + 1) * stride is formed, which wrapped
     * (LONG_MAX: ga_init crashed; 2^62: a record of 12 doubles that the steps wrote past) */
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, LONG_MAX),
                     GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(s), "max_steps = 9223372036854775807"));
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 1L << 62),
                     GA_ERR_NOMEM);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 1L << 58),
                     GA_ERR_NOMEM);
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, dJ), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "without a recorded run"));
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_OK);
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, dJ), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "before ga_init"));
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "after ga_init"));
    assert_int_equal(ga_adjoint_gradient(s, NULL, NULL, &J, dJ), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "no cost"));
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, NULL, dJ), GA_ERR_ARG);
    /* adjoint only: no forward sensitivities to read */
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_get_sensitivity(s, 0, dJ, NULL, NULL, NULL), GA_ERR_STATE);
    /* a failing cost */
    assert_int_equal(ga_adjoint_gradient(s, NULL, failing_cost, &J, dJ), GA_ERR_CALLBACK);
    assert_non_null(strstr(ga_last_error(s), "cost"));
    /* restoring into a recorded run */
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *buf = malloc(len * sizeof(double));
    assert_int_equal(ga_get_state(s, buf, len), GA_OK);
    assert_int_equal(ga_set_state(s, buf, len), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "recorded"));
    free(buf);
    ga_free(s);
}

/* A step beyond the record's room fails and changes nothing; the sweep covers what was
 * recorded, and after a Taylor step it refuses. */
static void full_record_and_uncovered_steps(void **state)
{
    (void)state;
    ga_solver *s = pendulum_solver(GA_SENSITIVITY_ADJOINT, 5);
    double J, dJ[1], t, q[2], q_after[2];
    for (int k = 0; k < 5; ++k)
        assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_get_q(s, q), GA_OK);
    assert_int_equal(ga_step(s, 1e-2), GA_ERR_NOMEM);
    assert_non_null(strstr(ga_last_error(s), "record is full"));
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_int_equal(ga_get_q(s, q_after), GA_OK);
    assert_true(fabs(t - 0.05) < 1e-15);
    assert_memory_equal(q, q_after, sizeof q);
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, dJ), GA_OK);
    /* the same five steps with forward sensitivities: the same gradient */
    ga_solver *f = pendulum_solver(GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT, 5);
    for (int k = 0; k < 5; ++k)
        assert_int_equal(ga_step(f, 1e-2), GA_OK);
    double d[4][kCatalogMaxN], fwd = 0.0;
    assert_int_equal(ga_get_sensitivity(f, 0, d[0], d[1], d[2], d[3]), GA_OK);
    for (int k = 0; k < 4; ++k)
        for (int i = 0; i < (k == 3 ? 1 : 2); ++i)
            fwd += g_c[k][i] * d[k][i];
    printf("  adjoint only %.15e, with forward %.15e\n", dJ[0], fwd);
    assert_true(fabs(dJ[0] - fwd) <= 1e-8 * fabs(fwd));
    ga_free(f);
    ga_free(s);

    s = pendulum_solver(GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT, 100);
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_step(s, 1e-5), GA_OK); /* a Taylor step */
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, dJ), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "Taylor step"));
    /* a restart records afresh */
    catalog_scene sc = catalog_make(0);
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    assert_int_equal(ga_step(s, 1e-2), GA_OK);
    assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, dJ), GA_OK);
    ga_free(s);
}


/* Initial values as parameters (ga_set_sensitivity_start): the adjoint's gradient in theta0
 * and omega0 of the pendulum is the forward one. */
static void initial_values_adjoint(void **state)
{
    (void)state;
    for (int f = 0; f < 2; ++f) {
        pendulum pd = {1.0, 1.0, 9.81};
        double q0[2], v0[2], p[2] = {1.0, 0.5}, J, adj[2];
        pendulum_state(&pd, p[0], p[1], q0, v0);
        const double dq_theta[2] = {cos(p[0]), sin(p[0])},
                     dv_theta[2] = {-p[1] * sin(p[0]), p[1] * cos(p[0])},
                     dv_omega[2] = {cos(p[0]), sin(p[0])};
        g_n = 2, g_m = 1, g_np = 2;
        for (int k = 0; k < 4; ++k)
            for (int i = 0; i < 2; ++i)
                g_c[k][i] = k < 2 ? 0.3 + 0.2 * k - 0.5 * i : 0.0;
        ga_solver *s = NULL;
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                          pendulum_jacobian, &pd),
                         GA_OK);
        assert_int_equal(ga_set_formulation(s, f ? GA_INDEX2_STABILIZED : GA_INDEX3), GA_OK);
        assert_int_equal(ga_set_sensitivity(s, 2, p, NULL, GA_DEPENDS_FORCE), GA_OK);
        assert_int_equal(ga_set_sensitivity_start(s, 0, dq_theta, dv_theta), GA_OK);
        assert_int_equal(ga_set_sensitivity_start(s, 1, NULL, dv_omega), GA_OK);
        assert_int_equal(ga_set_sensitivity_method(
                             s, GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT, 200),
                         GA_OK);
        assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
        for (int k = 0; k < 200; ++k)
            assert_int_equal(ga_step(s, 5e-3), GA_OK);
        assert_int_equal(ga_adjoint_gradient(s, NULL, terminal_linear, &J, adj), GA_OK);
        for (int j = 0; j < 2; ++j) {
            double d[4][2], fwd = 0.0;
            assert_int_equal(ga_get_sensitivity(s, j, d[0], d[1], d[2], d[3]), GA_OK);
            for (int k = 0; k < 2; ++k)
                for (int i = 0; i < 2; ++i)
                    fwd += g_c[k][i] * d[k][i];
            printf("  index %d d/d%s: forward %+.15e adjoint %+.15e\n", f ? 2 : 3,
                   j ? "omega0" : "theta0", fwd, adj[j]);
            assert_true(fabs(adj[j] - fwd) <= 1e-12 * fabs(fwd));
        }
        ga_free(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pendulum_adjoint),
        cmocka_unit_test(crank_adjoint),
        cmocka_unit_test(chain_adjoint),
        cmocka_unit_test(initial_values_adjoint),
        cmocka_unit_test(refusals),
        cmocka_unit_test(an_overflowing_sweep_is_refused),
        cmocka_unit_test(a_failed_restart_changes_no_adjoint_run),
        cmocka_unit_test(full_record_and_uncovered_steps),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
