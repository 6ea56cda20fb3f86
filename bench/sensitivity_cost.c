/* What sensitivities cost. Per scene, runs of the same steps: plain, with forward sensitivities
 * in 1 ... P parameters, and recorded for the adjoint followed by ga_adjoint_gradient (a running
 * cost: the kinetic energy) in 1 ... P parameters, and the same with checkpoints every
 * sqrt(steps) steps (ga_set_adjoint_checkpoints) in 1 parameter. Each round runs them all in turn and gives
 * their times relative to the plain run of that round; the medians over the rounds are robust
 * to this machine's drifts of speed. Scenes: the paper's slider-crank (parameters m1, m2, m3,
 * m4 and the torque: M and f; exact tangents by its callback), the slider-crank of IDAS's
 * sensitivity example (k, c: f only; tangents by differences) and a 1000-link chain on the
 * sparse path (link mass, inertia, gravity).
 *
 *   sensitivity_cost [rounds] -> CSV: scene,steps,us_plain,method,parameters,median_ratio,
 *                                lower_quartile,upper_quartile */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <galpha.h>

#include "rounds.h"

#include "scenes/chain.h"
#include "scenes/crank_spring_damper.h"
#include "scenes/slider_crank.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

enum { PAPER_CRANK, IDAS_CRANK, CHAIN, SCENES, MAX_P = 5, MAX_ROUNDS = 101 };
static const char *const kNames[SCENES] = {"slider_crank", "idas_slider_crank", "chain1000"};
static const int kParameters[SCENES] = {5, 2, 3};
static const int kSteps[SCENES] = {2000, 2000, 200};

static slider_crank g_sc;
static crank_spring_damper g_csd;
static chain g_chain;
static double g_mass_diag[3000];


/* the kinetic energy v^T M v / 2 with M diagonal (g_mass_diag, set per scene) */
static int g_n, g_m, g_np;
static int energy(double t, const double *q, const double *v, const double *qdd,
                  const double *lambda, double *value, double *d_q, double *d_v, double *d_qdd,
                  double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)q, (void)qdd, (void)lambda, (void)user, (void)d_lambda, (void)d_p;
    double e = 0;
    for (int i = 0; i < g_n; ++i) {
        e += 0.5 * g_mass_diag[i] * v[i] * v[i];
        d_v[i] = g_mass_diag[i] * v[i];
        d_q[i] = d_qdd[i] = 0.0;
    }
    *value = e;
    memset(d_lambda, 0, sizeof(double) * (size_t)g_m);
    memset(d_p, 0, sizeof(double) * (size_t)g_np);
    return 0;
}

/* One run: method 0 plain, 1 forward, 2 adjoint (record, then the gradient); np parameters.
 * Returns the seconds it took (negative on failure). */
static double run(int scene, int method, int np)
{
    static double q[3000], v[3000];
    ga_solver *s = NULL;
    int n = 0, m = 0, depends = GA_DEPENDS_FORCE | GA_DEPENDS_MASS;
    double h = 1e-3, *p = NULL;
    switch (scene) {
    case PAPER_CRANK:
        g_sc = slider_crank_paper();
        n = SC_N, m = SC_M;
        ga_create(n, m, &s);
        ga_set_callbacks(s, sc_mass, sc_force, sc_constraint, sc_jacobian, &g_sc);
        ga_set_constraint_accel(s, sc_constraint_accel);
        ga_set_constraint_dt(s, sc_constraint_dt);
        ga_set_tangents(s, sc_stiffness, NULL);
        sc_initial(&g_sc, M_PI / 2, q, v);
        p = &g_sc.m1;
        h = 5e-5;
        break;
    case IDAS_CRANK:
        g_csd = crank_spring_damper_idas();
        n = CSD_N, m = CSD_M;
        ga_create(n, m, &s);
        ga_set_callbacks(s, csd_mass, csd_force, csd_constraint, csd_jacobian, &g_csd);
        ga_set_constraint_accel(s, csd_constraint_accel);
        csd_initial(&g_csd, q, v);
        p = g_csd.p;
        depends = GA_DEPENDS_FORCE;
        h = 5e-3;
        break;
    default:
        g_chain = chain_make(1000);
        n = 3000, m = 2000;
        ga_create(n, m, &s);
        ga_set_callbacks(s, chain_mass, chain_force, chain_constraint, chain_jacobian, &g_chain);
        chain_declare_patterns(&g_chain, s);
        chain_initial(&g_chain, q, v);
        p = &g_chain.mass;
        h = 1e-3;
    }
    g_n = n, g_m = m, g_np = np;
    for (int i = 0; i < n; ++i)
        g_mass_diag[i] = 1.0; /* (the cost's weights: any will do for timing) */
    if (method > 0 && ga_set_sensitivity(s, np, p, NULL, depends) != GA_OK)
        return -1;
    if (method >= 2 && ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, kSteps[scene]) != GA_OK)
        return -1;
    /* method 3: checkpoints every sqrt(steps) steps, the sweep computing segments again */
    const long interval = (long)sqrt((double)kSteps[scene]);
    if (method == 3 &&
        ga_set_adjoint_checkpoints(s, interval, kSteps[scene] / interval + 1) != GA_OK)
        return -1;
    const double t0 = now();
    ga_status st = ga_init(s, 0.0, q, v);
    for (int k = 0; k < kSteps[scene] && !st; ++k)
        st = ga_step(s, h);
    double J, dJ[MAX_P];
    if (!st && method >= 2)
        st = ga_adjoint_gradient(s, energy, NULL, &J, dJ);
    const double seconds = now() - t0;
    if (st)
        fprintf(stderr, "%s: %s\n", kNames[scene], ga_last_error(s));
    ga_free(s);
    return st ? -1.0 : seconds;
}

int main(int argc, char **argv)
{
    int rounds = argc > 1 ? atoi(argv[1]) : 21;
    if (rounds < 1 || rounds > MAX_ROUNDS)
        rounds = 21;
    printf("scene,steps,us_plain,method,parameters,median_ratio,lower_quartile,upper_quartile\n");
    for (int scene = 0; scene < SCENES; ++scene) {
        const int P = kParameters[scene];
        static double ratio[3][MAX_P + 1][MAX_ROUNDS];
        double best_plain = 1e300;
        for (int r = 0; r < rounds; ++r) {
            const double plain = run(scene, 0, 0);
            if (plain < 0)
                return 1;
            best_plain = plain < best_plain ? plain : best_plain;
            for (int method = 1; method <= 3; ++method)
                for (int np = 1; np <= (method == 3 ? 1 : P); ++np) {
                    const double t = run(scene, method, np);
                    if (t < 0)
                        return 1;
                    ratio[method - 1][np][r] = t / plain;
                }
        }
        for (int method = 1; method <= 3; ++method)
            for (int np = 1; np <= (method == 3 ? 1 : P); ++np) {
                double *x = ratio[method - 1][np];
                qsort(x, rounds, sizeof(double), by_value);
                printf("%s,%d,%.1f,%s,%d,%.3f,%.3f,%.3f\n", kNames[scene], kSteps[scene],
                       1e6 * best_plain,
                       (const char *[]){"forward", "adjoint", "adjoint_checkpoints"}[method - 1],
                       np, x[rounds / 2],
                       x[rounds / 4], x[(3 * rounds) / 4]);
            }
        fflush(stdout);
    }
    return 0;
}
