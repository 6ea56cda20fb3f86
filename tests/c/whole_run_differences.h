/* Whole-run central differences in p against galpha's forward sensitivities (issue 20):
 * dq/dp, dv/dp, dqdd/dp and dlambda/dp after the last step against central differences of
 * whole runs (steps p_j +- e and +- e/2, Richardson-extrapolated, on a ladder of e; those runs
 * use full Newton, so that their solutions are converged to round-off). Adaptive runs record
 * their step sizes, which the difference runs replay: the sizes are inputs of the discrete
 * map. Included by the sensitivity suites. */
#ifndef GALPHA_TEST_WHOLE_RUN_DIFFERENCES_H
#define GALPHA_TEST_WHOLE_RUN_DIFFERENCES_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene_catalog.h"

enum { kMaxSteps = 20000, kMaxP = 3, kQuantities = 4 };
enum { kLadder = 5 };
static const double kLadderStep[kLadder] = {1e-2, 3e-3, 1e-3, 3e-4, 1e-4};

typedef struct setup {
    int scene;
    int formulation;
    int adaptive;          /* 0: fixed steps of t_end / steps */
    int steps;
    double t_end, tol;
    int np, depends;
    double *(*params)(void); /* the parameters the scene's callbacks read */
    catalog_scene (*make)(void);       /* a scene outside the catalog (NULL: the catalog's) */
    void (*configure)(ga_solver *s);   /* more options of the sensitivity run, or NULL */
} setup;

/* Andrews' mechanism: the spring's stiffness and the motor torque, through the force's user
 * pointer */
static andrews_params g_andrews;

typedef struct result {
    double x[kQuantities][kCatalogMaxN]; /* q, v, qdd, lambda */
    int count[kQuantities];
} result;

static double h_taken[kMaxSteps];
static int steps_taken;

static void read_state(ga_solver *s, int n, int m, result *r)
{
    assert_int_equal(ga_get_q(s, r->x[0]), GA_OK);
    assert_int_equal(ga_get_v(s, r->x[1]), GA_OK);
    assert_int_equal(ga_get_qdd(s, r->x[2]), GA_OK);
    assert_int_equal(ga_get_lambda(s, r->x[3]), GA_OK);
    r->count[0] = r->count[1] = r->count[2] = n;
    r->count[3] = m;
}

/* A run of the scene with its parameters at p (copied in), with sensitivities (sens != NULL:
 * sens[j] receives the derivatives; adaptive steps are recorded) or replaying the recorded
 * steps with full Newton. */
static void run(const setup *u, const double *p, result *out, result *sens)
{
    catalog_scene sc = u->make ? u->make() : catalog_make(u->scene);
    if (!u->make && (u->scene == 2 || u->scene == 3))
        sc.user = &g_andrews;
    double *pp = u->params();
    memcpy(pp, p, sizeof(double) * (size_t)u->np);
    ga_solver *s = catalog_solver(&sc);
    assert_non_null(s);
    assert_int_equal(ga_set_formulation(s, u->formulation), GA_OK);
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    if (sens) {
        assert_int_equal(ga_set_sensitivity(s, u->np, pp, NULL, u->depends), GA_OK);
        if (u->configure)
            u->configure(s);
    } else {
        assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
        assert_int_equal(ga_set_newton(s, 1e-13, 30), GA_OK);
    }
    const ga_status st = ga_init(s, 0.0, sc.q0, sc.v0);
    if (st)
        printf("ga_init: %s\n", ga_last_error(s));
    assert_int_equal(st, GA_OK);
    const double t_end = u->t_end > 0 ? u->t_end : sc.t_end;
    if (sens && u->adaptive) {
        assert_int_equal(ga_set_tolerances(s, u->tol, u->tol), GA_OK);
        /* the sensitivities are those of the discrete equations solved exactly, evaluated at
         * the step's solution: Newton to round-off here, as in the difference runs (adaptive
         * steps iterate only to a tenth of the local error tolerance by default) */
        assert_int_equal(ga_set_newton(s, 1e-13, 30), GA_OK);
        steps_taken = 0;
        double t = 0.0;
        while (t < t_end) {
            assert_int_equal(ga_step_adaptive(s, t_end), GA_OK);
            assert_true(steps_taken < kMaxSteps);
            assert_int_equal(ga_get_h_last(s, &h_taken[steps_taken++]), GA_OK);
            assert_int_equal(ga_get_t(s, &t), GA_OK);
        }
    } else if (sens) {
        steps_taken = u->steps;
        for (int k = 0; k < u->steps; ++k) {
            h_taken[k] = t_end / u->steps;
            assert_int_equal(ga_step(s, h_taken[k]), GA_OK);
        }
    } else {
        for (int k = 0; k < steps_taken; ++k)
            assert_int_equal(ga_step(s, h_taken[k]), GA_OK);
    }
    read_state(s, sc.n, sc.m, out);
    for (int j = 0; sens && j < u->np; ++j) {
        assert_int_equal(ga_get_sensitivity(s, j, sens[j].x[0], sens[j].x[1], sens[j].x[2],
                                            sens[j].x[3]),
                         GA_OK);
        memcpy(sens[j].count, out->count, sizeof out->count);
    }
    ga_free(s);
}

/* The largest relative difference, per quantity, between the sensitivities and the
 * extrapolated central differences of whole runs. */
static double check_setup(const setup *u, const char *label)
{
    double p0[kMaxP];
    /* the scene's parameters as the runs start from them */
    (void)(u->make ? u->make() : catalog_make(u->scene));
    g_andrews = andrews_published;
    memcpy(p0, u->params(), sizeof(double) * (size_t)u->np);
    result base, sens[kMaxP];
    run(u, p0, &base, sens);
    double worst = 0.0;
    for (int j = 0; j < u->np; ++j) {
        /* Richardson-extrapolated central differences on a ladder of steps; per quantity the
         * rung where consecutive estimates agree best, and that agreement as their
         * uncertainty */
        static double fd[kLadder][kQuantities][kCatalogMaxN];
        for (int l = 0; l < kLadder; ++l) {
            result r[4];
            const double e = kLadderStep[l] * fabs(p0[j]);
            const double shift[4] = {e, -e, 0.5 * e, -0.5 * e};
            for (int k = 0; k < 4; ++k) {
                double p[kMaxP];
                memcpy(p, p0, sizeof p);
                p[j] += shift[k];
                run(u, p, &r[k], NULL);
            }
            for (int qn = 0; qn < kQuantities; ++qn)
                for (int i = 0; i < base.count[qn]; ++i) {
                    const double d1 = (r[0].x[qn][i] - r[1].x[qn][i]) / (2 * e);
                    const double d2 = (r[2].x[qn][i] - r[3].x[qn][i]) / e;
                    fd[l][qn][i] = (4 * d2 - d1) / 3;
                }
        }
        for (int qn = 0; qn < kQuantities; ++qn) {
            double best_unc = INFINITY, best_diff = 0.0, size = 0.0;
            for (int l = 0; l + 1 < kLadder; ++l) {
                double unc = 0.0, diff = 0.0, sz = 0.0;
                for (int i = 0; i < base.count[qn]; ++i) {
                    unc = fmax(unc, fabs(fd[l][qn][i] - fd[l + 1][qn][i]));
                    diff = fmax(diff, fabs(sens[j].x[qn][i] - fd[l + 1][qn][i]));
                    sz = fmax(sz, fabs(fd[l + 1][qn][i]));
                }
                if (unc < best_unc)
                    best_unc = unc, best_diff = diff, size = sz;
            }
            const double rel = size > 0 ? best_diff / size : best_diff;
            printf("  %-34s p%d %-6s |d/dp| %.3e  difference %.2e  (differences agree to %.1e)\n",
                   label, j, (const char *[]){"q", "v", "qdd", "lambda"}[qn], size, rel,
                   size > 0 ? best_unc / size : best_unc);
            worst = fmax(worst, rel);
        }
    }
    memcpy(u->params(), p0, sizeof(double) * (size_t)u->np);
    return worst;
}

static void run_all(const setup *list, int count, const char *name)
{
    double worst = 0.0;
    for (int k = 0; k < count; ++k) {
        char label[80];
        snprintf(label, sizeof label, "%s %s %s", name,
                 list[k].formulation == GA_INDEX3 ? "index 3" : "index 2",
                 list[k].adaptive ? "adaptive" : "fixed");
        worst = fmax(worst, check_setup(&list[k], label));
    }
    assert_true(worst < 1e-7);
}

#endif
