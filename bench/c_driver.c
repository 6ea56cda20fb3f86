/* The runs of bench/compiled_callbacks.py with a C driver: the pendulum and Andrews' squeezer
 * (7 angles), stabilized index 2, one ga_advance over the run (rtol = atol = 1e-6) and a loop of
 * ga_step(h); best of 5 of each, in microseconds per step. CSV on stdout: scene,driver,us,steps */
#include <math.h>
#include <stdio.h>

#include <galpha.h>

#include "rounds.h"
#include "scenes/andrews.h"
#include "scenes/pendulum.h"

typedef struct scene {
    const char *name;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    void *user;
    double q0[7], t_end, h;
} scene;

static double per_step(const scene *sc, int advance, long long *steps)
{
    ga_solver *s = NULL;
    double v0[7] = {0};
    if (ga_create(sc->n, sc->m, &s) != GA_OK ||
        ga_set_callbacks(s, sc->mass, sc->force, sc->constraint, sc->jacobian, sc->user) ||
        ga_set_tolerances(s, 1e-6, 1e-6) || ga_set_formulation(s, GA_INDEX2_STABILIZED) ||
        ga_init(s, 0.0, sc->q0, v0) != GA_OK)
        return NAN;
    const double t0 = now();
    int st = GA_OK;
    if (advance)
        st = ga_advance(s, sc->t_end);
    else
        for (long k = 0, n = lround(sc->t_end / sc->h); k < n && st == GA_OK; ++k)
            st = ga_step(s, sc->h);
    const double dt = now() - t0;
    ga_get_counter(s, GA_COUNT_STEPS, steps);
    ga_free(s);
    return st == GA_OK ? dt / (double)*steps : NAN;
}

int main(void)
{
    static pendulum p = {1.0, 1.0, 9.81};
    scene scenes[2] = {
        {"pendulum", 2, 1, pendulum_mass, pendulum_force, pendulum_constraint, pendulum_jacobian,
         &p, {0}, 5.0, 1e-3},
        {"andrews", 7, 6, an7_mass, an7_force, an7_constraint, an7_jacobian, NULL, {0}, 0.03,
         1e-5},
    };
    scenes[0].q0[0] = sin(1.0);
    scenes[0].q0[1] = -cos(1.0);
    for (int i = 0; i < 7; ++i)
        scenes[1].q0[i] = andrews_q0[i];
    double best[2][2] = {{INFINITY, INFINITY}, {INFINITY, INFINITY}};
    long long steps[2][2] = {{0}};
    for (int round = 0; round < 5; ++round)
        for (int k = 0; k < 2; ++k)
            for (int advance = 0; advance < 2; ++advance)
                best[k][advance] = fmin(best[k][advance],
                                        per_step(&scenes[k], advance, &steps[k][advance]));
    printf("scene,driver,us_per_step,steps\n");
    for (int k = 0; k < 2; ++k)
        for (int advance = 0; advance < 2; ++advance)
            printf("%s,%s,%.3f,%lld\n", scenes[k].name, advance ? "advance" : "step",
                   1e6 * best[k][advance], steps[k][advance]);
    return 0;
}
