/* Sensitivities with parameters in the constraints (GA_DEPENDS_CONSTRAINT): Phi, Phi_q and
 * Phi_t depend on p, and so does the start, whose q0 and v0 (consistent at p) the start
 * projects at p + dp. Against whole-run central differences (whole_run_differences.h) to
 * 1e-7 relative: the pendulum's length, the slider-crank's link lengths (in M and Phi), a
 * pendulum whose length breathes in time (amplitude and mean length in Phi and Phi_t) and the
 * chain's link length on the sparse path; index 3 and stabilized index 2, fixed and adaptive
 * steps. The derivative callback (ga_set_constraint_parameter_derivative) against central
 * differences, its failures, and the adjoint's gradient against the forward one. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "scene_catalog.h"
#include "whole_run_differences.h"

/* ---- a pendulum of length L(t) = L0 (1 + a sin(w t)), Phi = (x^2 + y^2 - L^2) / 2 ---- */
typedef struct breathing {
    double L0, a, gravity; /* the parameters, in this order */
} breathing;
static const double kOmega = 3.0;
static breathing g_breathing;

static double length_at(const breathing *b, double t)
{
    return b->L0 * (1.0 + b->a * sin(kOmega * t));
}
static double length_rate(const breathing *b, double t)
{
    return b->L0 * b->a * kOmega * cos(kOmega * t);
}
static int br_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = M[3] = 1.0;
    M[1] = M[2] = 0.0;
    return 0;
}
static int br_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)q, (void)v;
    f[0] = 0.0;
    f[1] = -((const breathing *)u)->gravity;
    return 0;
}
static int br_constraint(double t, const double *q, double *phi, void *u)
{
    const double L = length_at(u, t);
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - L * L);
    return 0;
}
static int br_jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)u;
    J[0] = q[0];
    J[1] = q[1];
    return 0;
}
static int br_dt(double t, const double *q, double *out, void *u)
{
    (void)q;
    out[0] = -length_at(u, t) * length_rate(u, t);
    return 0;
}
/* Phi_qq(v, v) + 2 Phi_qt v + Phi_tt = |v|^2 - (L'^2 + L L'') */
static int br_accel(double t, const double *q, const double *v, double *out, void *u)
{
    const breathing *b = u;
    (void)q;
    const double L = length_at(b, t), Ld = length_rate(b, t);
    const double Ldd = -b->L0 * b->a * kOmega * kOmega * sin(kOmega * t);
    out[0] = v[0] * v[0] + v[1] * v[1] - (Ld * Ld + L * Ldd);
    return 0;
}
/* The exact derivatives in L0 (j = 0), a (1) and gravity (2, not in the constraints). */
static int br_constraint_p(double t, const double *q, int j, double *phi_p, double *J_p,
                           double *phi_tp, void *u)
{
    const breathing *b = u;
    (void)q;
    const double s = sin(kOmega * t), c = cos(kOmega * t);
    const double L = length_at(b, t);
    J_p[0] = J_p[1] = 0.0;
    phi_p[0] = 0.0;
    double tp = 0.0;
    if (j == 0) { /* L = L0 (1 + a s), Phi_t = -L0^2 (1 + a s) a w c */
        phi_p[0] = -L * (1.0 + b->a * s);
        tp = -2.0 * b->L0 * (1.0 + b->a * s) * b->a * kOmega * c;
    } else if (j == 1) {
        phi_p[0] = -L * b->L0 * s;
        tp = -b->L0 * b->L0 * kOmega * c * (1.0 + 2.0 * b->a * s);
    }
    if (phi_tp)
        phi_tp[0] = tp;
    return 0;
}

static catalog_scene breathing_make(void)
{
    catalog_scene sc;
    memset(&sc, 0, sizeof sc);
    g_breathing = (breathing){1.0, 0.2, 9.81};
    sc.name = "breathing pendulum";
    sc.n = 2, sc.m = 1;
    sc.mass = br_mass, sc.force = br_force;
    sc.constraint = br_constraint, sc.jacobian = br_jacobian;
    sc.accel = br_accel, sc.dt = br_dt;
    sc.user = &g_breathing;
    /* theta = 1 from the downward vertical, angular rate 0.5, radial rate L'(0) */
    const double th = 1.0, L = length_at(&g_breathing, 0.0), Ld = length_rate(&g_breathing, 0.0);
    sc.q0[0] = L * sin(th), sc.q0[1] = -L * cos(th);
    sc.v0[0] = Ld * sin(th) + L * 0.5 * cos(th);
    sc.v0[1] = -Ld * cos(th) + L * 0.5 * sin(th);
    sc.t_end = 1.0;
    return sc;
}
static double *breathing_params(void) { return &g_breathing.L0; }

static double *pendulum_length(void) { return &g_catalog_pendulum.length; }
/* the catalog's pendulum at its published parameters (catalog_make(0) keeps the last ones) */
static catalog_scene pendulum_make(void)
{
    g_catalog_pendulum = (pendulum){1.0, 1.0, 9.81};
    return catalog_make(0);
}
static double *crank_lengths(void) { return &g_catalog_crank.l1; }
static double *chain_length(void) { return &g_catalog_chain.length; }

static const int kFC = GA_DEPENDS_FORCE | GA_DEPENDS_CONSTRAINT;

static void pendulum_length_sensitivity(void **state)
{
    (void)state;
    const setup list[] = {
        {0, GA_INDEX3, 0, 50, 1.0, 0, 2, kFC, pendulum_length, pendulum_make, NULL},
        {0, GA_INDEX2_STABILIZED, 0, 200, 1.0, 0, 2, kFC, pendulum_length, pendulum_make, NULL},
        {0, GA_INDEX3, 1, 0, 1.0, 1e-2, 2, kFC, pendulum_length, pendulum_make, NULL},
        {0, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-5, 2, kFC, pendulum_length, pendulum_make, NULL},
    };
    run_all(list, 4, "pendulum length, gravity");
}

static void crank_length_sensitivity(void **state)
{
    (void)state;
    const int all = GA_DEPENDS_FORCE | GA_DEPENDS_MASS | GA_DEPENDS_CONSTRAINT;
    const setup list[] = {
        {1, GA_INDEX3, 0, 100, 1.0, 0, 2, all, crank_lengths, NULL, NULL},
        {1, GA_INDEX2_STABILIZED, 0, 100, 1.0, 0, 2, all, crank_lengths, NULL, NULL},
        {1, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-4, 2, all, crank_lengths, NULL, NULL},
    };
    run_all(list, 3, "slider-crank lengths");
}

/* In index 3 dPhi/dp enters dqdd/dp and dlambda/dp divided by beta h^2: there the
 * differences' error (eps^(4/5) of Phi's terms) shows at h = 0.01, and this scene's index-3
 * runs take the exact derivatives (design-notes, "Sensitivities"). */
static void exact(ga_solver *s)
{
    assert_int_equal(ga_set_constraint_parameter_derivative(s, br_constraint_p), GA_OK);
}

static void breathing_sensitivity(void **state)
{
    (void)state;
    const setup list[] = {
        {5, GA_INDEX3, 0, 50, 1.0, 0, 3, kFC, breathing_params, breathing_make, exact},
        {5, GA_INDEX2_STABILIZED, 0, 200, 1.0, 0, 3, kFC, breathing_params, breathing_make,
         NULL},
        {5, GA_INDEX2_STABILIZED, 0, 200, 1.0, 0, 3, kFC, breathing_params, breathing_make,
         exact},
        {5, GA_INDEX2_STABILIZED, 1, 0, 1.0, 1e-5, 3, kFC, breathing_params, breathing_make,
         NULL},
    };
    run_all(list, 4, "breathing pendulum");
}

static void chain_length_sensitivity(void **state)
{
    (void)state;
    const setup list[] = {
        {4, GA_INDEX3, 0, 25, 1.0, 0, 1, GA_DEPENDS_CONSTRAINT, chain_length, NULL, NULL},
        {4, GA_INDEX2_STABILIZED, 0, 50, 1.0, 0, 1, GA_DEPENDS_CONSTRAINT, chain_length, NULL,
         NULL},
    };
    run_all(list, 2, "chain length (sparse)");
}

/* ---- the derivative callback ---- */

/* The slider-crank's l1 (j = 0) and l2 (1): Phi and Phi_q as sc_constraint and sc_jacobian
 * write them, the rods' inertias m l^2 / 12 in M. */
static int crank_constraint_p(double t, const double *q, int j, double *phi_p, double *J_p,
                              double *phi_tp, void *u)
{
    (void)t, (void)u;
    const double c1 = cos(q[SC_TH1]), s1 = sin(q[SC_TH1]);
    const double c2 = cos(q[SC_TH2]), s2 = sin(q[SC_TH2]);
    memset(phi_p, 0, sizeof(double) * SC_M);
    memset(J_p, 0, sizeof(double) * SC_M * SC_N);
    if (phi_tp)
        memset(phi_tp, 0, sizeof(double) * SC_M);
#define JP(i, k) J_p[(i) + SC_M * (k)]
    if (j == 0) {
        phi_p[0] = -0.5 * c1, phi_p[1] = -0.5 * s1, phi_p[2] = -c1, phi_p[3] = -s1;
        JP(0, SC_TH1) = 0.5 * s1, JP(1, SC_TH1) = -0.5 * c1;
        JP(2, SC_TH1) = s1, JP(3, SC_TH1) = -c1;
    } else {
        phi_p[4] = -0.5 * c2, phi_p[5] = -0.5 * s2, phi_p[6] = -c2, phi_p[7] = s2;
        JP(4, SC_TH2) = 0.5 * s2, JP(5, SC_TH2) = -0.5 * c2;
        JP(6, SC_TH2) = s2, JP(7, SC_TH2) = c2;
    }
#undef JP
    return 0;
}
static int crank_mass_p(double t, const double *q, int j, const double *a, double *out, void *u)
{
    const slider_crank *p = u;
    (void)t, (void)q;
    memset(out, 0, sizeof(double) * SC_N);
    if (j == 0)
        out[SC_TH1] = p->m1 * p->l1 / 6.0 * a[SC_TH1];
    else
        out[SC_TH2] = p->m2 * p->l2 / 6.0 * a[SC_TH2];
    return 0;
}
static int crank_force_p(double t, const double *q, const double *v, int j, double *f_p, void *u)
{
    (void)t, (void)q, (void)v, (void)j, (void)u;
    memset(f_p, 0, sizeof(double) * SC_N);
    return 0;
}

static int constraint_p_fails; /* the call that fails (counted down), 0: none */
static int constraint_p_nan;   /* that call writes NaN instead of failing */
static int failing_constraint_p(double t, const double *q, int j, double *phi_p, double *J_p,
                                double *phi_tp, void *u)
{
    const int rc = crank_constraint_p(t, q, j, phi_p, J_p, phi_tp, u);
    if (constraint_p_fails > 0 && --constraint_p_fails == 0) {
        if (!constraint_p_nan)
            return -4;
        J_p[SC_M * SC_TH1] = NAN;
    }
    return rc;
}

static ga_solver *crank_solver(int index2, int callbacks, int methods)
{
    catalog_scene sc = catalog_make(1);
    ga_solver *s = catalog_solver(&sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, index2 ? GA_INDEX2_STABILIZED : GA_INDEX3), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 2, &g_catalog_crank.l1, NULL,
                                        GA_DEPENDS_MASS | GA_DEPENDS_CONSTRAINT),
                     GA_OK);
    if (methods)
        assert_int_equal(ga_set_sensitivity_method(s, methods, 1000), GA_OK);
    if (callbacks) {
        assert_int_equal(ga_set_parameter_derivatives(s, crank_force_p, crank_mass_p), GA_OK);
        assert_int_equal(ga_set_constraint_parameter_derivative(s, failing_constraint_p), GA_OK);
    }
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    return s;
}

static ga_solver *breathing_solver(int index2, int callbacks)
{
    catalog_scene sc = breathing_make();
    ga_solver *s = catalog_solver(&sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, index2 ? GA_INDEX2_STABILIZED : GA_INDEX3), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 3, &g_breathing.L0, NULL, kFC), GA_OK);
    if (callbacks)
        assert_int_equal(ga_set_constraint_parameter_derivative(s, br_constraint_p), GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    return s;
}

/* The largest relative difference between two solvers' sensitivities over the first
 * `quantities` of q, v, qdd, lambda. */
static double compare_first(ga_solver *a, ga_solver *b, int np, int n, int m, int quantities,
                            const char *label)
{
    double worst = 0.0;
    for (int j = 0; j < np; ++j) {
        double x[2][4][kCatalogMaxN];
        assert_int_equal(ga_get_sensitivity(a, j, x[0][0], x[0][1], x[0][2], x[0][3]), GA_OK);
        assert_int_equal(ga_get_sensitivity(b, j, x[1][0], x[1][1], x[1][2], x[1][3]), GA_OK);
        for (int qn = 0; qn < 4; ++qn) {
            double diff = 0, size = 0;
            for (int i = 0; i < (qn == 3 ? m : n); ++i) {
                diff = fmax(diff, fabs(x[0][qn][i] - x[1][qn][i]));
                size = fmax(size, fabs(x[1][qn][i]));
            }
            printf("  %s p%d quantity %d: %.2e apart (size %.2e)\n",
                   label, j, qn, diff / size, size);
            if (qn < quantities)
                worst = fmax(worst, diff / size);
        }
    }
    return worst;
}
static double compare(ga_solver *a, ga_solver *b, int np, int n, int m, const char *label)
{
    return compare_first(a, b, np, n, m, 4, label);
}

/* Exact derivatives against extrapolated central differences, to 1e-8: everywhere on the
 * slider-crank; on the breathing pendulum in index 2, and in index 3 for q and v -- there the
 * differences' error reaches dqdd/dp and dlambda/dp divided by beta h^2 (design-notes,
 * "Sensitivities"; printed). */
static void callback_agrees_with_differences(void **state)
{
    (void)state;
    for (int index2 = 0; index2 < 2; ++index2) {
        ga_solver *a = crank_solver(index2, 0, 0), *b = crank_solver(index2, 1, 0);
        for (int k = 0; k < 100; ++k) {
            assert_int_equal(ga_step(a, 1e-2), GA_OK);
            assert_int_equal(ga_step(b, 1e-2), GA_OK);
        }
        assert_true(compare(a, b, 2, SC_N, SC_M, "slider-crank") < 1e-8);
        ga_free(a);
        ga_free(b);
        ga_solver *c = breathing_solver(index2, 0), *d = breathing_solver(index2, 1);
        for (int k = 0; k < 100; ++k) {
            assert_int_equal(ga_step(c, 1e-2), GA_OK);
            assert_int_equal(ga_step(d, 1e-2), GA_OK);
        }
        assert_true(compare_first(c, d, 2, 2, 1, index2 ? 4 : 2, "breathing pendulum") < 1e-8);
        ga_free(c);
        ga_free(d);
    }
}

/* The accepted state and its sensitivities, as the getters give them. */
typedef struct snapshot {
    double t, x[4][SC_N], d[2][4][SC_N];
} snapshot;
static void take(ga_solver *s, snapshot *out)
{
    memset(out, 0, sizeof *out);
    assert_int_equal(ga_get_t(s, &out->t), GA_OK);
    assert_int_equal(ga_get_q(s, out->x[0]), GA_OK);
    assert_int_equal(ga_get_v(s, out->x[1]), GA_OK);
    assert_int_equal(ga_get_qdd(s, out->x[2]), GA_OK);
    assert_int_equal(ga_get_lambda(s, out->x[3]), GA_OK);
    for (int j = 0; j < 2; ++j)
        assert_int_equal(ga_get_sensitivity(s, j, out->d[j][0], out->d[j][1], out->d[j][2],
                                            out->d[j][3]),
                         GA_OK);
}

/* A failing or non-finite derivative callback fails the step (or the start) and changes
 * neither the state nor its sensitivities (a failed step drops the kept matrix:
 * design-notes, "Checkpoints"); the retry goes on as an unbroken run. */
static void callback_failures(void **state)
{
    (void)state;
    for (int nan = 0; nan < 2; ++nan) {
        constraint_p_nan = nan;
        ga_solver *a = crank_solver(1, 1, 0), *b = crank_solver(1, 1, 0);
        for (int k = 0; k < 10; ++k) {
            assert_int_equal(ga_step(a, 1e-2), GA_OK);
            assert_int_equal(ga_step(b, 1e-2), GA_OK);
        }
        snapshot before, after;
        take(a, &before);
        constraint_p_fails = 3; /* parameter 1's first call (index 2: two per parameter) */
        const ga_status st = ga_step(a, 1e-2);
        assert_int_equal(st, nan ? GA_ERR_NONFINITE : GA_ERR_CALLBACK);
        printf("  %s\n", ga_last_error(a));
        assert_non_null(strstr(ga_last_error(a), nan ? "dPhi_q/dp" : "constraint_p"));
        assert_non_null(strstr(ga_last_error(a), "parameter 1"));
        take(a, &after);
        assert_memory_equal(&before, &after, sizeof before);
        for (int k = 0; k < 5; ++k) {
            assert_int_equal(ga_step(a, 1e-2), GA_OK);
            assert_int_equal(ga_step(b, 1e-2), GA_OK);
        }
        assert_true(compare(a, b, 2, SC_N, SC_M, "after the failure") < 1e-8);
        ga_free(a);
        ga_free(b);

        /* at the start: ga_init fails and may be called again */
        catalog_scene sc = catalog_make(1);
        ga_solver *c = catalog_solver(&sc);
        assert_int_equal(ga_set_sensitivity(c, 2, &g_catalog_crank.l1, NULL,
                                            GA_DEPENDS_MASS | GA_DEPENDS_CONSTRAINT),
                         GA_OK);
        assert_int_equal(ga_set_constraint_parameter_derivative(c, failing_constraint_p), GA_OK);
        constraint_p_fails = 1;
        assert_int_equal(ga_init(c, 0.0, sc.q0, sc.v0), nan ? GA_ERR_NONFINITE : GA_ERR_CALLBACK);
        assert_int_equal(ga_init(c, 0.0, sc.q0, sc.v0), GA_OK);
        ga_free(c);
    }
    constraint_p_nan = 0;
}

/* A cost of the run's end and of its multipliers. */
static int crank_cost(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *value, double *d_q, double *d_v,
                      double *d_qdd, double *d_lambda, double *d_p, void *u)
{
    (void)t, (void)qdd, (void)u;
    memset(d_q, 0, sizeof(double) * SC_N);
    memset(d_v, 0, sizeof(double) * SC_N);
    memset(d_qdd, 0, sizeof(double) * SC_N);
    memset(d_lambda, 0, sizeof(double) * SC_M);
    d_p[0] = d_p[1] = 0.0;
    *value = q[SC_X3] * q[SC_X3] + v[SC_TH1] + lambda[6] * lambda[6];
    d_q[SC_X3] = 2.0 * q[SC_X3];
    d_v[SC_TH1] = 1.0;
    d_lambda[6] = 2.0 * lambda[6];
    return 0;
}

/* The adjoint's gradient of a terminal cost against the forward sensitivities of the same run,
 * to 1e-9. */
static void adjoint_agrees_with_forward(void **state)
{
    (void)state;
    for (int index2 = 0; index2 < 2; ++index2)
        for (int callbacks = 0; callbacks < 2; ++callbacks) {
            ga_solver *s = crank_solver(index2, callbacks,
                                        GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT);
            /* the cost sees the steps' own lambda, as their sensitivities are */
            assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
            for (int k = 0; k < 50; ++k)
                assert_int_equal(ga_step(s, 1e-2), GA_OK);
            double J = 0.0, dJ[2], q[SC_N], v[SC_N], lam[SC_M];
            assert_int_equal(ga_adjoint_gradient(s, NULL, crank_cost, &J, dJ), GA_OK);
            assert_int_equal(ga_get_q(s, q), GA_OK);
            assert_int_equal(ga_get_v(s, v), GA_OK);
            assert_int_equal(ga_get_lambda(s, lam), GA_OK);
            for (int j = 0; j < 2; ++j) {
                double dq[SC_N], dv[SC_N], dl[SC_M];
                assert_int_equal(ga_get_sensitivity(s, j, dq, dv, NULL, dl), GA_OK);
                const double forward = 2.0 * q[SC_X3] * dq[SC_X3] + dv[SC_TH1] +
                                       2.0 * lam[6] * dl[6];
                printf("  index %d callbacks %d p%d: adjoint %.15e forward %.15e (%.1e)\n",
                       index2 ? 2 : 3, callbacks, j, dJ[j], forward,
                       fabs(dJ[j] - forward) / fabs(forward));
                assert_true(fabs(dJ[j] - forward) <= 1e-9 * fabs(forward));
            }
            ga_free(s);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pendulum_length_sensitivity),
        cmocka_unit_test(crank_length_sensitivity),
        cmocka_unit_test(breathing_sensitivity),
        cmocka_unit_test(chain_length_sensitivity),
        cmocka_unit_test(callback_agrees_with_differences),
        cmocka_unit_test(callback_failures),
        cmocka_unit_test(adjoint_agrees_with_forward),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
