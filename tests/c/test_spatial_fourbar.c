/* The spatial RSSR four-bar on (R^3 x SO(3))^3 (examples/scenes/spatial_fourbar.h), a closed
 * loop on the group, against a reference that takes nothing from galpha: a one-degree-of-
 * freedom conservative motion is fixed by its energy, E = m(theta) theta'^2 / 2 + V(theta), so
 * the time to reach crank angle theta is t(theta) = int sqrt(m / (2 (E - V))) dtheta, which
 * Gauss-Legendre quadrature gives to round-off; m(theta) and V(theta) come from the loop's
 * closed-form kinematics, checked here first. Then: order 2 in the crank angle at t = 1 in
 * index 3 and index 2, the joints held, the coupler's free spin left at zero. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

#include "scenes/spatial_fourbar.h"

static const double kPi = 3.14159265358979323846;
static const double kOmega0 = 10.0; /* the crank's rate at theta = 0, rad/s */
static const double kTEnd = 1.0;    /* about 2.2 turns */

/* m(theta) (twice the kinetic energy at theta' = 1) and V(theta), from the kinematics: the
 * crank and rocker turn about fixed axes, the coupler moves with its centre at (B + C) / 2 and
 * turns with e x e', e its axis (no spin) */
static void energy_terms(const spatial_fourbar *f, double th, double *m, double *V)
{
    const double L1 = f->length[0], L2 = f->length[1], L3 = f->length[2];
    const double *D = f->pivot;
    double dphi;
    const double phi = spatial_fourbar_rocker_angle(f, th, &dphi);
    const double B[3] = {L1 * cos(th), L1 * sin(th), 0.0};
    const double C[3] = {D[0], D[1] + L3 * cos(phi), D[2] + L3 * sin(phi)};
    const double dB[3] = {-L1 * sin(th), L1 * cos(th), 0.0};
    const double dC[3] = {0.0, -L3 * sin(phi) * dphi, L3 * cos(phi) * dphi};
    double e[3], de[3], vc2 = 0.0;
    for (int i = 0; i < 3; ++i) {
        e[i] = (C[i] - B[i]) / L2;
        de[i] = (dC[i] - dB[i]) / L2;
        vc2 += 0.25 * (dB[i] + dC[i]) * (dB[i] + dC[i]);
    }
    const double w[3] = {e[1] * de[2] - e[2] * de[1], e[2] * de[0] - e[0] * de[2],
                         e[0] * de[1] - e[1] * de[0]};
    const double w2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    const double crank = f->inertia[0][0] + f->mass[0] * L1 * L1 / 4.0;
    const double rocker = f->inertia[2][0] + f->mass[2] * L3 * L3 / 4.0;
    *m = crank + f->mass[1] * vc2 + f->inertia[1][0] * w2 + rocker * dphi * dphi;
    const double g = f->gravity;
    *V = g * (f->mass[0] * B[2] / 2.0 + f->mass[1] * (B[2] + C[2]) / 2.0 +
              f->mass[2] * (D[2] + C[2]) / 2.0);
}

/* dt/dtheta = sqrt(m / (2 (E - V))) */
static double rate(const spatial_fourbar *f, double E, double th)
{
    double m, V;
    energy_terms(f, th, &m, &V);
    return sqrt(m / (2.0 * (E - V)));
}

/* t(theta) by 8-point Gauss-Legendre on panels of 1/400 turn */
static double time_to(const spatial_fourbar *f, double E, double theta)
{
    static const double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                0.9602898564975363};
    static const double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                0.1012285362903763};
    const int panels = (int)ceil(fabs(theta) / (2.0 * kPi / 400.0));
    const double d = theta / panels;
    double t = 0.0;
    for (int p = 0; p < panels; ++p) {
        const double mid = (p + 0.5) * d;
        for (int k = 0; k < 4; ++k)
            t += 0.5 * d * w[k] *
                 (rate(f, E, mid - 0.5 * d * x[k]) + rate(f, E, mid + 0.5 * d * x[k]));
    }
    return t;
}

/* theta with t(theta) = T, by Newton's method */
static double reference_angle(const spatial_fourbar *f, double T)
{
    double m0, V0;
    energy_terms(f, 0.0, &m0, &V0);
    const double E = 0.5 * m0 * kOmega0 * kOmega0 + V0;
    double th = kOmega0 * T;
    for (int k = 0; k < 50; ++k) {
        const double step = (T - time_to(f, E, th)) / rate(f, E, th);
        th += step;
        if (fabs(step) < 1e-15)
            break;
    }
    return th;
}

static ga_solver *make(spatial_fourbar *f, int formulation)
{
    int kinds[FOURBAR_BLOCKS], counts[FOURBAR_BLOCKS];
    spatial_fourbar_blocks(kinds, counts);
    ga_solver *s = NULL;
    assert_int_equal(ga_create_space(FOURBAR_BLOCKS, kinds, counts, FOURBAR_M, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, spatial_fourbar_mass, spatial_fourbar_force,
                                      spatial_fourbar_constraint, spatial_fourbar_jacobian, f),
                     GA_OK);
    assert_int_equal(ga_set_constraint_dt(s, spatial_fourbar_constraint_dt), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    return s;
}

static void the_loop_closes_and_starts_on_it(void **state)
{
    (void)state;
    spatial_fourbar f = spatial_fourbar_make();
    for (int k = 0; k < 72; ++k) {
        const double th = k * 2.0 * kPi / 72, e = 1e-6;
        double dphi;
        const double phi = spatial_fourbar_rocker_angle(&f, th, &dphi);
        const double B[3] = {0.2 * cos(th), 0.2 * sin(th), 0.0};
        const double C[3] = {0.25, 0.1 + 0.4 * cos(phi), 0.3 + 0.4 * sin(phi)};
        const double d = sqrt((B[0] - C[0]) * (B[0] - C[0]) + (B[1] - C[1]) * (B[1] - C[1]) +
                              (B[2] - C[2]) * (B[2] - C[2]));
        assert_true(fabs(d - 0.6) < 1e-15);
        const double diff = (spatial_fourbar_rocker_angle(&f, th + e, NULL) -
                             spatial_fourbar_rocker_angle(&f, th - e, NULL)) /
                            (2 * e);
        assert_true(fabs(diff - dphi) < 1e-8);
        assert_true(phi > -1.1 && phi < 0.6); /* the branch below the pivot */
    }
    double q[FOURBAR_NQ], v[FOURBAR_NV], phi[FOURBAR_M], J[FOURBAR_M * FOURBAR_NV];
    spatial_fourbar_initial(&f, 0.7, kOmega0, q, v);
    assert_int_equal(spatial_fourbar_constraint(0.0, q, phi, &f), 0);
    assert_int_equal(spatial_fourbar_jacobian(0.0, q, J, &f), 0);
    for (int i = 0; i < FOURBAR_M; ++i) {
        double Jv = 0.0;
        for (int j = 0; j < FOURBAR_NV; ++j)
            Jv += J[i + FOURBAR_M * j] * v[j];
        assert_true(fabs(phi[i]) < 1e-15);
        assert_true(fabs(Jv) < 1e-13);
    }
    assert_true(fabs(spatial_fourbar_crank_angle(q) - 0.7) < 1e-15);
    assert_true(fabs(v[6 + 5]) < 1e-14); /* the coupler's spin (of rates about 10) */
    /* the energy from the state is the reference's */
    double m, V;
    energy_terms(&f, 0.7, &m, &V);
    assert_true(fabs(spatial_fourbar_energy(&f, q, v) - (0.5 * m * kOmega0 * kOmega0 + V)) < 1e-13);
}

static void its_jacobian_is_the_derivative_along_right_increments(void **state)
{
    (void)state;
    spatial_fourbar f = spatial_fourbar_make();
    ga_solver *s = make(&f, GA_INDEX3);
    double q[FOURBAR_NQ], v[FOURBAR_NV], worst = 1.0;
    spatial_fourbar_initial(&f, 2.1, kOmega0, q, v);
    assert_int_equal(ga_check_derivatives(s, 0.0, q, v, NULL, NULL, NULL, 1e-6, &worst), GA_OK);
    assert_true(worst < 1e-6);
    ga_free(s);
}

typedef struct run_result {
    double angle_error, joints, spin, energy_drift;
} run_result;

static run_result run(int formulation, double h, double reference)
{
    spatial_fourbar f = spatial_fourbar_make();
    ga_solver *s = make(&f, formulation);
    double q[FOURBAR_NQ], v[FOURBAR_NV], phi[FOURBAR_M];
    spatial_fourbar_initial(&f, 0.0, kOmega0, q, v);
    const double E0 = spatial_fourbar_energy(&f, q, v);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    const long n = lround(kTEnd / h);
    double turns = 0.0, last = 0.0;
    run_result r = {0.0, 0.0, 0.0, 0.0};
    for (long k = 0; k < n; ++k) {
        assert_int_equal(ga_step(s, kTEnd / n), GA_OK);
        assert_int_equal(ga_get_q(s, q), GA_OK);
        assert_int_equal(ga_get_v(s, v), GA_OK);
        const double a = spatial_fourbar_crank_angle(q);
        if (a < last - kPi)
            turns += 1.0; /* passed from +pi to -pi */
        last = a;
        spatial_fourbar_constraint(0.0, q, phi, &f);
        for (int i = 0; i < FOURBAR_M; ++i)
            r.joints = fmax(r.joints, fabs(phi[i]));
        r.spin = fmax(r.spin, fabs(v[6 + 5]));
        r.energy_drift = fmax(r.energy_drift, fabs(spatial_fourbar_energy(&f, q, v) - E0) / E0);
    }
    r.angle_error = fabs(last + 2.0 * kPi * turns - reference);
    ga_free(s);
    return r;
}

static void crank_angle_converges_at_order_two(void **state)
{
    (void)state;
    spatial_fourbar f = spatial_fourbar_make();
    const double reference = reference_angle(&f, kTEnd);
    assert_true(reference > 4.0 * kPi && reference < 5.0 * kPi); /* past two turns */
    const int forms[2] = {GA_INDEX3, GA_INDEX2_STABILIZED};
    const double hs[3] = {4e-3, 2e-3, 1e-3};
    for (int k = 0; k < 2; ++k) {
        run_result r[3];
        for (int i = 0; i < 3; ++i) {
            r[i] = run(forms[k], hs[i], reference);
            assert_true(r[i].joints < 1e-12); /* index 2 too: its positions are projected */
            assert_true(r[i].spin < 1e-9);
        }
        const double p1 = log2(r[0].angle_error / r[1].angle_error);
        const double p2 = log2(r[1].angle_error / r[2].angle_error);
        printf("  %s: crank angle errors %.3e %.3e %.3e (h = 4e-3, 2e-3, 1e-3), orders %.3f "
               "%.3f; joints %.1e, spin %.1e, energy %.2e\n",
               k ? "index 2" : "index 3", r[0].angle_error, r[1].angle_error, r[2].angle_error, p1,
               p2, r[2].joints, r[2].spin, r[2].energy_drift);
        assert_true(fabs(p2 - 2.0) < 0.1);
        assert_true(fabs(p1 - 2.0) < 0.15);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_loop_closes_and_starts_on_it),
        cmocka_unit_test(its_jacobian_is_the_derivative_along_right_increments),
        cmocka_unit_test(crank_angle_converges_at_order_two),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
