#include "demo_run.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int demo_run(const demo_scene *d, double *q_end, double *lambda_end)
{
    ga_solver *s = NULL;
    ga_status st = ga_create(d->n, d->m, &s);
    double *q = calloc((size_t)(2 * d->n + d->m), sizeof(double));
    double *lam = q + d->n, *phi = lam + d->m;
    if (!st)
        st = ga_set_callbacks(s, d->mass, d->force, d->constraint, d->jacobian, d->user);
    if (!st && d->stiffness)
        st = ga_set_tangents(s, d->stiffness, NULL);
    if (!st && d->accel)
        st = ga_set_constraint_accel(s, d->accel);
    if (!st)
        st = ga_set_rho_inf(s, d->rho_inf);
    const double t0 = now();
    if (!st)
        st = ga_init(s, 0.0, d->q0, d->v0);
    const long steps = lround(d->t_end / d->h);
    for (long i = 0; i < steps && !st; ++i)
        st = ga_step(s, d->h);
    const double elapsed = now() - t0;
    if (st) {
        fprintf(stderr, "%s: %s: %s\n", d->title, ga_strerror(st), ga_last_error(s));
        ga_free(s);
        free(q);
        return 1;
    }
    double t, phi_max = 0.0;
    long long n_steps, iters, facts, res;
    ga_get_t(s, &t);
    ga_get_q(s, q);
    ga_get_lambda(s, lam);
    ga_get_counter(s, GA_COUNT_STEPS, &n_steps);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &facts);
    ga_get_counter(s, GA_COUNT_RESIDUALS, &res);
    d->constraint(t, q, phi, d->user);
    for (int i = 0; i < d->m; ++i)
        phi_max = fmax(phi_max, fabs(phi[i]));
    printf("%s\n  n = %d coordinates, m = %d constraints; rho_inf = %g, h = %g, t in [0, %g]\n",
           d->title, d->n, d->m, d->rho_inf, d->h, d->t_end);
    printf("  final state at t = %.6g:", t);
    for (int k = 0; d->show[k] >= 0; ++k)
        printf("%s %s = %.10g", k ? "," : "", d->names[k], q[d->show[k]]);
    printf("\n  lambda_1 = %.10g   |Phi(q)|_inf = %.2e\n", d->m ? lam[0] : 0.0, phi_max);
    printf("  steps %lld, Newton iterations %lld (%.2f per step), factorizations %lld, "
           "residuals %lld, time %.2f ms (%.2f us per step)\n",
           n_steps, iters, (double)iters / (double)n_steps, facts, res, 1e3 * elapsed,
           1e6 * elapsed / (double)n_steps);
    if (d->full_precision) {
        printf("final q =");
        for (int i = 0; i < d->n; ++i)
            printf(" %.17e", q[i]);
        printf("\nfinal lambda =");
        for (int i = 0; i < d->m; ++i)
            printf(" %.17e", lam[i]);
        printf("\n");
    }
    if (q_end)
        for (int i = 0; i < d->n; ++i)
            q_end[i] = q[i];
    if (lambda_end)
        for (int i = 0; i < d->m; ++i)
            lambda_end[i] = lam[i];
    ga_free(s);
    free(q);
    return 0;
}
