/* Sensitivities converge at order 2 to the derivatives of the exact solution (issue 20): the
 * slider-crank of SUNDIALS' IDAS forward-sensitivity example (examples/scenes/
 * crank_spring_damper.h), parameters k and c, G = the integral of the kinetic energy over
 * [0, 10]. The reference is computed here by an independent integrator: RK4 on the index-1
 * form (examples/scenes/index1_rk4.c, no galpha code) with G as a quadrature state, and its
 * derivatives by central differences of those runs in k and c (Richardson-extrapolated).
 * galpha: G_h by the trapezoidal rule over its steps, dG_h/dp from dv/dp the same way; also
 * dq/dp at t = 10; dG_h/dp from the adjoint sweep as well (equal to the forward one to
 * 1e-10). Index 3 and stabilized index 2, h = 10/500 ... 10/8000. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include <galpha.h>

#include "scenes/crank_spring_damper.h"
#include "scenes/index1_rk4.h"

enum { kLevels = 5 };
static const double kTEnd = 10.0;
static crank_spring_damper g_model;

static int energy_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                       void *user)
{
    (void)t, (void)q, (void)y;
    ydot[0] = csd_kinetic_energy(user, v, NULL);
    return 0;
}
static int force_ignoring_y(double t, const double *q, const double *v, const double *y,
                            double *f, void *user)
{
    (void)y;
    return csd_force(t, q, v, f, user);
}

/* RK4 on the index-1 form with the energy integral as a state: G and q(10) */
static void reference_run(const double *p, double *G, double *q)
{
    g_model = crank_spring_damper_idas();
    memcpy(g_model.p, p, sizeof g_model.p);
    const rk4_model model = {CSD_N, CSD_M, csd_mass, csd_force, csd_jacobian,
                             csd_constraint_accel, &g_model};
    const rk4_first_order energy = {1, force_ignoring_y, energy_rate};
    double v[CSD_N], y[1] = {0.0};
    csd_initial(&g_model, q, v);
    assert_int_equal(index1_rk4_y(&model, &energy, 0.0, kTEnd, 10000, q, v, y, NULL, NULL, NULL),
                     0);
    *G = y[0];
}

/* d/dp_j of G and q(10): central differences of reference runs, steps e and e/2, extrapolated */
static void reference_derivatives(double dG[2], double dq[2][CSD_N], double *G, double q[CSD_N])
{
    const double p0[2] = {1.0, 1.0};
    reference_run(p0, G, q);
    for (int j = 0; j < 2; ++j) {
        double Gs[4], qs[4][CSD_N];
        const double e = 1e-3, shift[4] = {e, -e, 0.5 * e, -0.5 * e};
        for (int k = 0; k < 4; ++k) {
            double p[2] = {p0[0], p0[1]};
            p[j] += shift[k];
            reference_run(p, &Gs[k], qs[k]);
        }
        dG[j] = (4 * (Gs[2] - Gs[3]) / e - (Gs[0] - Gs[1]) / (2 * e)) / 3;
        for (int i = 0; i < CSD_N; ++i)
            dq[j][i] = (4 * (qs[2][i] - qs[3][i]) / e - (qs[0][i] - qs[1][i]) / (2 * e)) / 3;
    }
}

static int energy_cost(double t, const double *q, const double *v, const double *qdd,
                       const double *lambda, double *value, double *d_q, double *d_v,
                       double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)q, (void)qdd, (void)lambda;
    *value = csd_kinetic_energy(user, v, d_v);
    memset(d_q, 0, sizeof(double) * CSD_N);
    memset(d_qdd, 0, sizeof(double) * CSD_N);
    d_lambda[0] = d_lambda[1] = 0.0;
    d_p[0] = d_p[1] = 0.0;
    return 0;
}

/* galpha with sensitivities in k and c, `steps` steps over [0, 10]; the same G and dG/dp from
 * the adjoint sweep agree with those summed from the forward sensitivities */
static void galpha_run(int formulation, int steps, double *G, double dG[2], double dq[2][CSD_N])
{
    g_model = crank_spring_damper_idas();
    double q[CSD_N], v[CSD_N], grad[CSD_N], dv[CSD_N];
    csd_initial(&g_model, q, v);
    ga_solver *s = NULL;
    assert_int_equal(ga_create(CSD_N, CSD_M, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, csd_mass, csd_force, csd_constraint, csd_jacobian,
                                      &g_model),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, csd_constraint_accel), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 2, g_model.p, NULL, GA_DEPENDS_FORCE), GA_OK);
    assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT,
                                               steps),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    const double h = kTEnd / steps;
    double energy = csd_kinetic_energy(&g_model, v, grad), denergy[2] = {0, 0};
    *G = 0.0;
    dG[0] = dG[1] = 0.0; /* the start is at rest: dv/dp = 0 there */
    for (int k = 0; k < steps; ++k) {
        assert_int_equal(ga_step(s, h), GA_OK);
        assert_int_equal(ga_get_v(s, v), GA_OK);
        const double e1 = csd_kinetic_energy(&g_model, v, grad);
        *G += 0.5 * h * (energy + e1);
        energy = e1;
        for (int j = 0; j < 2; ++j) {
            assert_int_equal(ga_get_sensitivity(s, j, NULL, dv, NULL, NULL), GA_OK);
            const double de1 = grad[0] * dv[0] + grad[1] * dv[1] + grad[2] * dv[2];
            dG[j] += 0.5 * h * (denergy[j] + de1);
            denergy[j] = de1;
        }
    }
    for (int j = 0; j < 2; ++j)
        assert_int_equal(ga_get_sensitivity(s, j, dq[j], NULL, NULL, NULL), GA_OK);
    double G_adjoint, dG_adjoint[2];
    assert_int_equal(ga_adjoint_gradient(s, energy_cost, NULL, &G_adjoint, dG_adjoint), GA_OK);
    assert_true(fabs(G_adjoint - *G) <= 1e-13 * *G);
    for (int j = 0; j < 2; ++j)
        assert_true(fabs(dG_adjoint[j] - dG[j]) <= 1e-10 * fabs(dG[j]));
    ga_free(s);
}

static void converges_at_order_two(void **state)
{
    (void)state;
    double G_ref, dG_ref[2], dq_ref[2][CSD_N], q_ref[CSD_N];
    reference_derivatives(dG_ref, dq_ref, &G_ref, q_ref);
    printf("  reference (RK4, h = 1e-3): G = %.12f, dG/dk = %.10e, dG/dc = %.10e\n", G_ref,
           dG_ref[0], dG_ref[1]);
    for (int f = 0; f < 2; ++f) {
        const int formulation = f ? GA_INDEX2_STABILIZED : GA_INDEX3;
        double err_prev[5] = {0};
        for (int level = 0; level < kLevels; ++level) {
            const int steps = 500 << level;
            double G, dG[2], dq[2][CSD_N];
            galpha_run(formulation, steps, &G, dG, dq);
            double err[5] = {fabs(G - G_ref), fabs(dG[0] - dG_ref[0]), fabs(dG[1] - dG_ref[1]),
                             0, 0};
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < CSD_N; ++i)
                    err[3 + j] = fmax(err[3 + j], fabs(dq[j][i] - dq_ref[j][i]));
            printf("  index %d h = %.5f: G error %.2e  dG/dk %.2e  dG/dc %.2e  dq/dk %.2e  "
                   "dq/dc %.2e", f ? 2 : 3, kTEnd / steps, err[0], err[1], err[2], err[3],
                   err[4]);
            if (level > 0) {
                printf("  orders");
                for (int k = 0; k < 5; ++k) {
                    const double order = log2(err_prev[k] / err[k]);
                    printf(" %.2f", order);
                    assert_true(order > 1.8 && order < 2.25);
                }
            }
            printf("\n");
            memcpy(err_prev, err, sizeof err);
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(converges_at_order_two),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
