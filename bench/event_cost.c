/* What watching events costs when none fires: the same run with and without three event
 * functions that stay positive (g_k = 1000 + k + q_0, no multipliers), fixed steps on the paper's
 * scenes and the 1000-link chain, adaptive steps on Andrews' mechanism in index 2. Each round
 * runs both, in alternating order, and gives one ratio of their times; the median ratio over
 * the rounds (and its quartiles) is robust to this machine's drifts of speed, which move both
 * runs of a round alike. Best times for scale.
 *
 *   event_cost [rounds]          -> CSV on stdout: scene,steps,us_without,us_with,
 *                                   median_ratio,lower_quartile,upper_quartile
 *   event_cost one SCENE 0|1     -> one run without (0) or with (1) the events, for callgrind
 *                                   (scripts/bench.sh counts the instructions inside the
 *                                   stepping calls)
 *   event_cost side_by_side [rounds] -> the pendulum, whose step is the cheapest: two solvers
 *                                   stepping in turns, 500 steps each per round, with 3, 1 and
 *                                   0 event functions against none (0: the control); CSV
 *                                   functions,median_ratio,lower_quartile,upper_quartile */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <galpha.h>

#include "rounds.h"

#include "scenes/andrews.h"
#include "scenes/chain.h"
#include "scenes/pendulum.h"
#include "scenes/slider_crank.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif


static int never(double t, const double *q, const double *v, const double *lambda, double *g,
                 void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    for (int k = 0; k < 3; ++k)
        g[k] = 1000.0 + k + q[0]; /* q[0]: every scene has one */
    return 0;
}

static pendulum g_pendulum = {1.0, 1.0, 9.81};
static slider_crank g_sc;
static chain g_chain;

enum { PENDULUM, SLIDER_CRANK, ANDREWS, CHAIN, ANDREWS_ADAPTIVE, SCENES };
static const char *const kNames[SCENES] = {"pendulum", "slider_crank", "andrews7", "chain1000",
                                          "andrews7_adaptive_index2"};

/* One run of scene k; returns the accepted steps (-1 on failure). */
static long run(int k, int with_events)
{
    ga_solver *s = NULL;
    double q[3000], v[3000], h = 1e-3, t_end = 2.0;
    int n, m, adaptive = 0;
    switch (k) {
    case PENDULUM:
        n = 2, m = 1;
        ga_create(n, m, &s);
        ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                         pendulum_jacobian, &g_pendulum);
        ga_set_tangents(s, pendulum_stiffness, NULL);
        pendulum_state(&g_pendulum, M_PI / 2, 0.0, q, v);
        break;
    case SLIDER_CRANK:
        n = SC_N, m = SC_M;
        g_sc = slider_crank_paper();
        ga_create(n, m, &s);
        ga_set_callbacks(s, sc_mass, sc_force, sc_constraint, sc_jacobian, &g_sc);
        ga_set_tangents(s, sc_stiffness, NULL);
        ga_set_constraint_accel(s, sc_constraint_accel);
        ga_set_constant_mass(s, 1);
        ga_set_rho_inf(s, 0.7);
        sc_initial(&g_sc, M_PI / 2, q, v);
        h = 5e-3, t_end = 1.0;
        break;
    case ANDREWS:
    case ANDREWS_ADAPTIVE:
        n = AN7_N, m = AN7_M;
        ga_create(n, m, &s);
        ga_set_callbacks(s, an7_mass, an7_force, an7_constraint, an7_jacobian, NULL);
        ga_set_constraint_accel(s, an7_constraint_accel);
        ga_set_rho_inf(s, 0.7);
        memcpy(q, andrews_q0, sizeof(double) * AN7_N);
        memset(v, 0, sizeof(double) * AN7_N);
        h = 3e-4, t_end = andrews_t_end;
        if (k == ANDREWS_ADAPTIVE) {
            adaptive = 1;
            ga_set_formulation(s, GA_INDEX2_STABILIZED);
            ga_set_constraint_dt(s, an7_constraint_dt);
            ga_set_tolerances(s, 1e-6, 1e-6);
        }
        break;
    default:
        g_chain = chain_make(1000);
        n = 3 * g_chain.links, m = 2 * g_chain.links;
        ga_create(n, m, &s);
        chain_declare_patterns(&g_chain, s);
        ga_set_callbacks(s, chain_mass, chain_force, chain_constraint, chain_jacobian, &g_chain);
        ga_set_tangents(s, chain_stiffness, NULL);
        ga_set_constraint_accel(s, chain_constraint_accel);
        ga_set_constant_mass(s, 1);
        ga_set_rho_inf(s, 0.7);
        chain_initial(&g_chain, q, v);
        t_end = 0.05;
        break;
    }
    if (with_events && ga_set_events(s, 3, never, NULL, NULL, 0) != GA_OK)
        return -1;
    if (ga_init(s, 0.0, q, v) != GA_OK)
        return -1;
    ga_status st = GA_OK;
    if (adaptive) {
        st = ga_advance(s, t_end);
    } else {
        const long steps = (long)(t_end / h + 0.5);
        for (long i = 0; i < steps && st == GA_OK; ++i)
            st = ga_step(s, h);
    }
    long long steps = -1;
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    ga_free(s);
    return st == GA_OK ? (long)steps : -1;
}


/* Two pendulum solvers, the second watching `functions` events, stepping in turns from the
 * same start: the median over `rounds` of the ratio of their times for 500 steps. */
static int side_by_side(int functions, int rounds, double *ratio)
{
    ga_solver *s[2] = {NULL, NULL};
    for (int w = 0; w < 2; ++w) {
        if (ga_create(2, 1, &s[w]) != GA_OK ||
            ga_set_callbacks(s[w], pendulum_mass, pendulum_force, pendulum_constraint,
                             pendulum_jacobian, &g_pendulum) != GA_OK ||
            ga_set_tangents(s[w], pendulum_stiffness, NULL) != GA_OK ||
            (w == 1 && functions > 0 &&
             ga_set_events(s[w], functions, never, NULL, NULL, 0) != GA_OK))
            return 1;
    }
    for (int r = 0; r < rounds; ++r) {
        double dt[2];
        for (int i = 0; i < 2; ++i) {
            const int w = (r + i) % 2;
            double q[2], v[2];
            pendulum_state(&g_pendulum, M_PI / 2, 0.0, q, v);
            if (ga_init(s[w], 0.0, q, v) != GA_OK)
                return 1;
            const double t0 = now();
            for (int k = 0; k < 500; ++k)
                if (ga_step(s[w], 1e-3) != GA_OK)
                    return 1;
            dt[w] = now() - t0;
        }
        ratio[r] = dt[1] / dt[0];
    }
    ga_free(s[0]);
    ga_free(s[1]);
    qsort(ratio, (size_t)rounds, sizeof(double), by_value);
    printf("%d,%.3f,%.3f,%.3f\n", functions, ratio[rounds / 2], ratio[rounds / 4],
           ratio[(3 * rounds) / 4]);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "side_by_side") == 0) {
        const int rounds = argc > 2 ? atoi(argv[2]) : 400;
        double *ratio = malloc(sizeof(double) * (size_t)(rounds > 0 ? rounds : 1));
        if (!ratio || rounds < 1)
            return 1;
        printf("functions,median_ratio,lower_quartile,upper_quartile\n");
        const int functions[3] = {3, 1, 0};
        for (int i = 0; i < 3; ++i)
            if (side_by_side(functions[i], rounds, ratio))
                return 1;
        free(ratio);
        return 0;
    }
    if (argc > 3 && strcmp(argv[1], "one") == 0) {
        for (int k = 0; k < SCENES; ++k)
            if (strcmp(argv[2], kNames[k]) == 0)
                return run(k, atoi(argv[3])) < 0;
        fprintf(stderr, "unknown scene %s\n", argv[2]);
        return 2;
    }
    const int rounds = argc > 1 ? atoi(argv[1]) : 41;
    double *ratio = malloc(sizeof(double) * (size_t)(rounds > 0 ? rounds : 1));
    if (!ratio || rounds < 1)
        return 1;
    printf("scene,steps,us_without,us_with,median_ratio,lower_quartile,upper_quartile\n");
    for (int k = 0; k < SCENES; ++k) {
        double best[2] = {1e30, 1e30};
        long steps = 0;
        for (int r = 0; r < rounds; ++r) {
            double dt[2];
            for (int i = 0; i < 2; ++i) {
                const int with = (r + i) % 2; /* which runs first alternates */
                const double t0 = now();
                steps = run(k, with);
                dt[with] = now() - t0;
                if (steps < 0) {
                    fprintf(stderr, "%s failed\n", kNames[k]);
                    return 1;
                }
                if (dt[with] < best[with])
                    best[with] = dt[with];
            }
            ratio[r] = dt[1] / dt[0];
        }
        qsort(ratio, (size_t)rounds, sizeof(double), by_value);
        printf("%s,%ld,%.1f,%.1f,%.3f,%.3f,%.3f\n", kNames[k], steps, 1e6 * best[0],
               1e6 * best[1], ratio[rounds / 2], ratio[rounds / 4], ratio[(3 * rounds) / 4]);
    }
    free(ratio);
    return 0;
}
