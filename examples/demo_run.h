/* What the demo programs share: run a scene at a fixed step and print what a user checks
 * first -- final state, constraint residual, steps, Newton iterations, time. */
#ifndef GALPHA_DEMO_RUN_H
#define GALPHA_DEMO_RUN_H

#include <galpha.h>

typedef struct demo_scene {
    const char *title;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_stiffness_fn stiffness;      /* may be NULL */
    ga_constraint_accel_fn accel;   /* may be NULL */
    void *user;
    const double *q0, *v0;
    double rho_inf, h, t_end;
    const char *const *names;       /* names of the coordinates to print (NULL: first ones) */
    const int *show;                /* indices of the coordinates to print, -1 terminated */
    int full_precision;             /* also print all of q and lambda with 17 digits */
} demo_scene;

/* Runs the scene; on success copies the final q (n) and lambda (m) out (either may be NULL)
 * and returns 0; prints the failure and returns 1 otherwise. */
int demo_run(const demo_scene *d, double *q_end, double *lambda_end);

#endif
