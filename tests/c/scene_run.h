/* Runs a scene with galpha at a fixed step and reports what the scene tests check: the final
 * state, the largest constraint residual over all accepted steps, work counters, and
 * (optionally) the largest drift of a conserved quantity. */
#ifndef GALPHA_TEST_SCENE_RUN_H
#define GALPHA_TEST_SCENE_RUN_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

typedef struct scene {
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_stiffness_fn stiffness;
    ga_constraint_accel_fn accel;
    void *user;
    const double *q0, *v0;
    double (*energy)(const double *q, const double *v); /* optional conserved quantity */
} scene;

typedef struct scene_result {
    ga_status status;
    double q[64], v[64], qdd[64], lambda[64];
    double max_phi;      /* max over accepted steps of |Phi(q_n)|_inf */
    double max_q;        /* max over accepted steps of |q_n|_inf */
    double energy_drift; /* max over accepted steps of |E(t_n) - E(t_0)| */
    long long steps, iters, residuals, tangent_evals;
} scene_result;

static inline scene_result run_scene(const scene *sc, double h, double t_end, double rho_inf,
                                     double tol, ga_tangent_mode mode)
{
    scene_result r;
    ga_solver *s = NULL;
    double *phi = (double *)malloc(sizeof(double) * (size_t)(sc->m > 0 ? sc->m : 1));
    memset(&r, 0, sizeof r);
    r.status = ga_create(sc->n, sc->m, &s);
    if (!r.status) /* the scene tests check the method's own qdd and lambda (paper, Figs. 3, 9) */
        r.status = ga_set_output(s, GA_OUTPUT_STEP);
    if (!r.status)
        r.status = ga_set_callbacks(s, sc->mass, sc->force, sc->constraint, sc->jacobian,
                                    sc->user);
    if (!r.status)
        r.status = ga_set_tangents(s, sc->stiffness, NULL);
    if (!r.status)
        r.status = ga_set_tangent_mode(s, mode);
    if (!r.status && sc->accel)
        r.status = ga_set_constraint_accel(s, sc->accel);
    if (!r.status)
        r.status = ga_set_rho_inf(s, rho_inf);
    if (!r.status)
        r.status = ga_set_newton(s, tol, 20);
    if (!r.status)
        r.status = ga_init(s, 0.0, sc->q0, sc->v0);
    double e0 = 0.0;
    if (!r.status && sc->energy) {
        ga_get_q(s, r.q);
        ga_get_v(s, r.v);
        e0 = sc->energy(r.q, r.v);
    }
    const long n = lround(t_end / h);
    for (long i = 0; i < n && !r.status; ++i) {
        double t;
        r.status = ga_step(s, h);
        if (r.status)
            break;
        ga_get_t(s, &t);
        ga_get_q(s, r.q);
        ga_get_v(s, r.v);
        sc->constraint(t, r.q, phi, sc->user);
        for (int j = 0; j < sc->m; ++j)
            r.max_phi = fmax(r.max_phi, fabs(phi[j]));
        for (int j = 0; j < sc->n; ++j)
            r.max_q = fmax(r.max_q, fabs(r.q[j]));
        if (sc->energy)
            r.energy_drift = fmax(r.energy_drift, fabs(sc->energy(r.q, r.v) - e0));
    }
    if (!r.status) {
        ga_get_q(s, r.q);
        ga_get_v(s, r.v);
        ga_get_qdd(s, r.qdd);
        ga_get_lambda(s, r.lambda);
        ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
        ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &r.iters);
        ga_get_counter(s, GA_COUNT_RESIDUALS, &r.residuals);
        ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &r.tangent_evals);
    }
    ga_free(s);
    free(phi);
    return r;
}

#endif
