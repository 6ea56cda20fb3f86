/* Modified Newton never accepts an unsolved step: for every fixed h from 1e-2 down to 1e-7 in
 * half decades, both formulations and every shipped scene, a run with the default settings
 * (Jacobian reuse, the default stopping test) ends within 1.5 times the error of full Newton
 * (GA_REUSE_NEVER: a matrix at every iteration) at the same h. Errors of q and v at the end
 * against an independent reference (index1_rk4.c: RK4 on the index-1 form, far smaller
 * steps). A run takes at most kMaxSteps steps, so the smallest steps end early: errors
 * there are round-off, which both runs must keep equally small. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <galpha.h>

#include "scene_catalog.h"

enum { kMaxSteps = 20000 };
static const double kBeyondReach = 0.1;

typedef struct errors {
    double q, v;
    long long factorizations, iterations;
    ga_status status;
} errors;

/* Relative max-norm errors of q and v at the end of N steps of size h. */
static errors run(const catalog_scene *sc, int formulation, int reuse, double h, long N,
                  const double *q_ref, const double *v_ref)
{
    double q[kCatalogMaxN], v[kCatalogMaxN];
    errors e = {0, 0, 0, 0, GA_OK};
    ga_solver *s = catalog_solver(sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_jacobian_reuse(s, reuse), GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc->q0, sc->v0), GA_OK);
    for (long i = 0; i < N; ++i) {
        e.status = ga_step(s, h);
        if (e.status != GA_OK) {
            printf("  %s, h = %g, step %ld: %s\n", sc->name, h, i, ga_last_error(s));
            ga_free(s);
            return e;
        }
    }
    ga_get_q(s, q);
    ga_get_v(s, v);
    for (int i = 0; i < sc->n; ++i) {
        e.q = fmax(e.q, fabs(q[i] - q_ref[i]));
        e.v = fmax(e.v, fabs(v[i] - v_ref[i]));
    }
    e.q /= catalog_max_abs(q_ref, sc->n);
    e.v /= catalog_max_abs(v_ref, sc->n);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &e.factorizations);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &e.iterations);
    ga_free(s);
    return e;
}

static void sweep(int which)
{
    catalog_scene sc = catalog_make(which);
    printf("  %s\n  %-9s %-6s %10s %10s %10s %10s %7s %7s\n", sc.name, "h", "form", "q default",
           "q full", "v default", "v full", "fac/st", "it/st");
    /* The end times of the 11 runs, and the reference at each: one RK4 pass over them in
     * increasing order (the span is the same for most h: one pass instead of eleven). */
    enum { kFirst = 4, kLast = 14, kRuns = kLast - kFirst + 1 };
    long steps[kRuns];
    double ends[kRuns], q_refs[kRuns][kCatalogMaxN], v_refs[kRuns][kCatalogMaxN];
    for (int k = kFirst; k <= kLast; ++k) {
        const long N = lround(sc.t_end / pow(10.0, -0.5 * k));
        steps[k - kFirst] = N > kMaxSteps ? kMaxSteps : N;
        ends[k - kFirst] = steps[k - kFirst] * pow(10.0, -0.5 * k);
    }
    {
        double q[kCatalogMaxN], v[kCatalogMaxN], t = 0.0;
        int done[kRuns] = {0};
        memcpy(q, sc.q0, sizeof q);
        memcpy(v, sc.v0, sizeof v);
        for (int r = 0; r < kRuns; ++r) {
            int next = -1;
            for (int j = 0; j < kRuns; ++j)
                if (!done[j] && (next < 0 || ends[j] < ends[next]))
                    next = j;
            done[next] = 1;
            if (ends[next] > t) {
                const long ref_steps = lround(fmax(400.0, (ends[next] - t) / sc.h_reference));
                assert_int_equal(index1_rk4(&sc.reference, t, ends[next], ref_steps, q, v, NULL,
                                            NULL), 0);
                t = ends[next];
            }
            memcpy(q_refs[next], q, sizeof q);
            memcpy(v_refs[next], v, sizeof v);
        }
    }
    for (int k = kFirst; k <= kLast; ++k) {
        const double h = pow(10.0, -0.5 * k);
        const long N = steps[k - kFirst];
        const double *q_ref = q_refs[k - kFirst], *v_ref = v_refs[k - kFirst];
        for (int f = GA_INDEX3; f <= GA_INDEX2_STABILIZED; ++f) {
            const errors d = run(&sc, f, GA_REUSE_AUTO, h, N, q_ref, v_ref);
            const errors full = run(&sc, f, GA_REUSE_NEVER, h, N, q_ref, v_ref);
            /* Andrews' mechanism at h >= 1e-3: the crank turns too far per step. */
            if (full.status != GA_OK || full.q > kBeyondReach) {
                printf("  %-9.3g %-6s full Newton %s: h beyond the method's reach here\n", h,
                       f == GA_INDEX3 ? "idx3" : "idx2",
                       full.status != GA_OK ? "fails" : "is more than 10 % off");
                continue;
            }
            assert_int_equal(d.status, GA_OK);
            printf("  %-9.3g %-6s %10.2e %10.2e %10.2e %10.2e %7.2f %7.2f\n", h,
                   f == GA_INDEX3 ? "idx3" : "idx2", d.q, full.q, d.v, full.v,
                   (double)d.factorizations / N, (double)d.iterations / N);
            /* Below the round-off floor of a quantity errors are noise: for positions a random
             * walk of about an ulp per step; an index-3 velocity is known to gamma' times an
             * ulp of |q| (v moves by gamma' dq). */
            const double eps = DBL_EPSILON, q_floor = 2 * eps * sqrt((double)N);
            double v_floor = q_floor;
            if (f == GA_INDEX3) {
                double beta, gamma;
                ga_solver *probe = NULL;
                assert_int_equal(ga_create(1, 0, &probe), GA_OK);
                ga_get_params(probe, NULL, NULL, &beta, &gamma);
                ga_free(probe);
                v_floor = fmax(v_floor, 4 * eps * gamma / (h * beta) * catalog_max_abs(q_ref, sc.n) /
                                            catalog_max_abs(v_ref, sc.n));
            }
            if (!(d.q <= 1.5 * fmax(full.q, q_floor) && d.v <= 1.5 * fmax(full.v, v_floor)))
                fail_msg("%s, %s, h = %g: errors of q, v %.3g, %.3g against %.3g, %.3g for "
                         "full Newton (floors %.3g, %.3g)", sc.name,
                         f == GA_INDEX3 ? "index 3" : "index 2", h, d.q, d.v, full.q, full.v,
                         q_floor, v_floor);
        }
    }
}

static void pendulum_sweep(void **state) { (void)state; sweep(0); }
static void slider_crank_sweep(void **state) { (void)state; sweep(1); }
static void andrews7_sweep(void **state) { (void)state; sweep(2); }
static void andrews31_sweep(void **state) { (void)state; sweep(3); }
static void chain_sweep(void **state) { (void)state; sweep(4); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pendulum_sweep),     cmocka_unit_test(slider_crank_sweep),
        cmocka_unit_test(andrews7_sweep),     cmocka_unit_test(andrews31_sweep),
        cmocka_unit_test(chain_sweep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
