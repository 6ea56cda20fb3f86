/* The smallest complete galpha program: a planar pendulum in Cartesian coordinates,
 * integrated over one second; prints what a user checks first. */
#include <galpha.h>
#include <math.h>
#include <stdio.h>
#include <time.h>

#include "scenes/pendulum.h"

static int check(ga_solver *s, ga_status st, const char *what)
{
    if (st != GA_OK) {
        fprintf(stderr, "%s: %s: %s\n", what, ga_strerror(st), ga_last_error(s));
        return 1;
    }
    return 0;
}

int main(void)
{
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2], qdd[2], lambda[1], phi[1];
    const double h = 1e-3, t_end = 1.0;
    ga_solver *s = NULL;
    long long steps = 0, iters = 0;
    double t = 0.0;
    clock_t c0;

    if (ga_create(2, 1, &s) != GA_OK)
        return 1;
    pendulum_state(&p, 1.0, 0.5, q, v); /* theta0 = 1 rad, omega0 = 0.5 rad/s */
    if (check(s, ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                  pendulum_jacobian, &p), "ga_set_callbacks") ||
        check(s, ga_set_rho_inf(s, 0.9), "ga_set_rho_inf") ||
        check(s, ga_init(s, 0.0, q, v), "ga_init"))
        return 1;
    c0 = clock();
    for (int i = 0; i < (int)lround(t_end / h); ++i)
        if (check(s, ga_step(s, h), "ga_step"))
            return 1;
    const double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
    ga_get_t(s, &t);
    ga_get_q(s, q);
    ga_get_v(s, v);
    ga_get_qdd(s, qdd);
    ga_get_lambda(s, lambda);
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &iters);
    pendulum_constraint(t, q, phi, &p);
    printf("galpha %s -- planar pendulum (n = 2, m = 1), rho_inf = 0.9, h = %g\n",
           ga_version(), h);
    printf("  t = %.6f  q = (%.12f, %.12f)  v = (%.10f, %.10f)\n", t, q[0], q[1], v[0], v[1]);
    printf("  qdd = (%.8f, %.8f)  lambda = %.10f\n", qdd[0], qdd[1], lambda[0]);
    printf("  |Phi(q)| = %.2e  steps = %lld  Newton iterations = %lld (%.2f per step)  "
           "CPU = %.3f ms\n",
           fabs(phi[0]), steps, iters, (double)iters / (double)steps, 1e3 * cpu);
    printf("final q = %.17e %.17e\nfinal lambda = %.17e\n", q[0], q[1], lambda[0]);
    ga_free(s);
    return 0;
}
