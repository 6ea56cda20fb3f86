/* The sparse path: a chain of 10 000 rigid links (30 000 coordinates, 20 000 constraints)
 * falling under gravity, with the sparsity of M, Phi_q, K_t and C_t declared once
 * (examples/scenes/chain.c). galpha picks SuiteSparse KLU; a dense iteration matrix would have
 * 2.5e9 entries. First 0.1 s at a fixed step, index 3; then 0.5 s in adaptive
 * steps of the stabilized index-2 formulation, with output every 0.1 s by interpolation.
 * Usage: chain_demo [links] [--print] (--print: the fixed steps only, then the final q and
 * lambda with 17 digits, for the comparison with examples/python/chain.py). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "scenes/chain.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double max_abs_constraint(const chain *c, const double *q)
{
    double *phi = malloc(sizeof(double) * 2 * c->links), worst = 0.0;
    chain_constraint(0.0, q, phi, (void *)c);
    for (int i = 0; i < 2 * c->links; ++i)
        worst = fmax(worst, fabs(phi[i]));
    free(phi);
    return worst;
}

static int fail(ga_solver *s, ga_status st)
{
    fprintf(stderr, "chain: %s: %s\n", ga_strerror(st), ga_last_error(s));
    ga_free(s);
    return 1;
}

int main(int argc, char **argv)
{
    int print = 0, links = 10000;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--print"))
            print = 1;
        else
            links = atoi(argv[i]);
    }
    if (links < 1) {
        fprintf(stderr, "usage: chain_demo [links] [--print]\n");
        return 2;
    }
    chain c = chain_make(links);
    const int n = 3 * c.links, m = 2 * c.links;
    double *q = malloc(sizeof(double) * n), *v = malloc(sizeof(double) * n);
    const int last = print ? GA_INDEX3 : GA_INDEX2_STABILIZED;
    for (int formulation = GA_INDEX3; formulation <= last; ++formulation) {
        ga_solver *s = NULL;
        chain_initial(&c, q, v);
        ga_status st = ga_create(n, m, &s);
        if (!st)
            st = chain_declare_patterns(&c, s);
        if (!st)
            st = ga_set_callbacks(s, chain_mass, chain_force, chain_constraint, chain_jacobian,
                                  &c);
        if (!st)
            st = ga_set_tangents(s, chain_stiffness, NULL);
        if (!st)
            st = ga_set_constraint_accel(s, chain_constraint_accel);
        if (!st)
            st = ga_set_constraint_dt(s, chain_constraint_dt);
        if (!st)
            st = ga_set_constant_mass(s, 1);
        if (!st)
            st = ga_set_formulation(s, formulation);
        if (!st)
            st = ga_set_tolerances(s, 1e-4, 1e-4);
        const double t0 = now();
        if (!st)
            st = ga_init(s, 0.0, q, v);
        if (st)
            return fail(s, st);
        printf("%s, %d links: n = %d, m = %d, linear algebra: %s\n",
               formulation == GA_INDEX3 ? "Fixed steps h = 1e-3, index 3"
                                        : "Adaptive steps, rtol = atol = 1e-4, index 2",
               c.links, n, m, ga_linear_solver_name(s));
        if (formulation == GA_INDEX3) {
            for (int k = 0; k < 100 && !st; ++k)
                st = ga_step(s, 1e-3);
            if (st)
                return fail(s, st);
        } else {
            double t = 0.0;
            for (double t_out = 0.1; t_out < 0.5 + 1e-12; t_out += 0.1) {
                while (t < t_out && !st) { /* steps of their own size; output interpolated */
                    st = ga_step_adaptive(s, 0.5);
                    ga_get_t(s, &t);
                }
                if (st)
                    return fail(s, st);
                ga_interpolate(s, t_out, q, NULL, NULL);
                printf("  t = %.2f: tip of the chain at (%.6f, %.6f)\n", t_out,
                       q[n - 3] + 0.5 * c.length * cos(q[n - 1]),
                       q[n - 2] + 0.5 * c.length * sin(q[n - 1]));
            }
        }
        const double elapsed = now() - t0;
        double t;
        long long steps, iters, facts;
        ga_get_t(s, &t);
        ga_get_q(s, q);
        ga_get_counter(s, GA_COUNT_STEPS, &steps);
        ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters);
        ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &facts);
        printf("  t = %.3g: |Phi(q)|_inf = %.2e; %lld steps, %.2f Newton iterations and %.2f "
               "factorizations per step; %.0f ms (%.2f ms per step, setup included)\n\n",
               t, max_abs_constraint(&c, q), steps, (double)iters / (double)steps,
               (double)facts / (double)steps, 1e3 * elapsed, 1e3 * elapsed / (double)steps);
        if (print) {
            double *lambda = malloc(sizeof(double) * m);
            ga_get_lambda(s, lambda);
            printf("final q =");
            for (int i = 0; i < n; ++i)
                printf(" %.17e", q[i]);
            printf("\nfinal lambda =");
            for (int i = 0; i < m; ++i)
                printf(" %.17e", lambda[i]);
            printf("\n");
            free(lambda);
        }
        ga_free(s);
    }
    free(q);
    free(v);
    return 0;
}
