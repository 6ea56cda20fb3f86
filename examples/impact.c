/* A pendulum that hits a wall: released at 60 degrees, it strikes a wall along the vertical
 * through its pivot at every swing down, and rebounds with restitution e. The wall is an event
 * function, g = x, falling and terminal (ga_set_events): ga_step stops with GA_EVENT in the
 * step that crossed it, the impact located on that step's dense output; the velocity at that
 * instant is reflected (v -> -e v: at the wall the velocity is normal to it), and the run
 * restarted there with ga_init, which keeps every option and the event function and starts
 * afresh. Between impacts energy is conserved, so the kinetic energy at
 * successive impacts falls by e^2 each time; the first impact comes after a quarter period,
 * K(sin(theta0 / 2)) sqrt(L / g) (K: the complete elliptic integral of the first kind), with
 * the energy the fall released, m g L (1 - cos theta0). Printed, and checked (exit status 1
 * if not). */
#include <math.h>
#include <stdio.h>

#include <galpha.h>

#include "scenes/pendulum.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* K(k) = pi / (2 AGM(1, sqrt(1 - k^2))) */
static double elliptic_k(double k)
{
    double a = 1.0, b = sqrt(1.0 - k * k);
    for (int i = 0; i < 40; ++i) {
        const double m = 0.5 * (a + b);
        b = sqrt(a * b);
        a = m;
    }
    return M_PI / (2.0 * a);
}

/* the wall: x = 0 */
static int wall(double t, const double *q, const double *v, const double *lambda, double *g,
                void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    g[0] = q[0];
    return 0;
}

static int check(ga_solver *s, ga_status st)
{
    if (st != GA_OK)
        fprintf(stderr, "galpha: %s: %s\n", ga_strerror(st), ga_last_error(s));
    return st != GA_OK;
}

int main(void)
{
    pendulum p = {1.0, 1.0, 9.81};
    const double e = 0.8, h = 1e-3;
    enum { IMPACTS = 6 };
    double q[2], v[2];
    const double theta0 = M_PI / 3.0;
    pendulum_state(&p, theta0, 0.0, q, v); /* on the side x > 0, the wall at x = 0 */
    const double t_first = elliptic_k(sin(0.5 * theta0)) * sqrt(p.length / p.gravity);
    const double kinetic_first = p.mass * p.gravity * p.length * (1.0 - cos(theta0));
    double t_impact[IMPACTS];
    ga_solver *s = NULL;
    if (ga_create(2, 1, &s) != GA_OK)
        return 1;
    const int falling = GA_EVENT_FALLING, terminal = 1;
    if (check(s, ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                  pendulum_jacobian, &p)) ||
        check(s, ga_set_events(s, 1, wall, &falling, &terminal, 0)) ||
        check(s, ga_init(s, 0.0, q, v)))
        return 1;
    double kinetic[IMPACTS], t = 0.0;
    int failed = 0;
    for (int k = 0; k < IMPACTS && !failed; ++k) {
        /* steps until the pendulum reaches the wall */
        ga_status st;
        while ((st = ga_step(s, h)) == GA_OK) {
        }
        failed = st != GA_EVENT && check(s, st);
        failed = failed || check(s, ga_get_event(s, 0, &t, NULL, NULL)) ||
                 check(s, ga_interpolate(s, t, q, v, NULL));
        if (failed)
            break;
        kinetic[k] = 0.5 * p.mass * (v[0] * v[0] + v[1] * v[1]);
        t_impact[k] = t;
        printf("impact %d at t = %.9f s: kinetic energy %.9f J", k + 1, t, kinetic[k]);
        if (k > 0)
            printf(", %.9f of the one before (e^2 = %.2f)", kinetic[k] / kinetic[k - 1], e * e);
        printf("\n");
        v[0] *= -e; /* the impact law */
        v[1] *= -e;
        failed = check(s, ga_init(s, t, q, v));
    }
    if (failed) {
        ga_free(s);
        return 1;
    }
    /* the state of the last restart, for the comparison with examples/python/impact.py */
    double lambda[1];
    ga_get_q(s, q);
    ga_get_lambda(s, lambda);
    printf("final q = %.17e %.17e\nfinal lambda = %.17e\n", q[0], q[1], lambda[0]);
    double worst = 0.0;
    for (int k = 1; k < IMPACTS; ++k)
        worst = fmax(worst, fabs(kinetic[k] / kinetic[k - 1] / (e * e) - 1.0));
    const double dt = fabs(t_impact[0] - t_first) / t_first;
    const double dk = fabs(kinetic[0] - kinetic_first) / kinetic_first;
    printf("largest relative deviation from e^2: %.2e; first impact: time %.2e and energy "
           "%.2e off the exact ones (relative)\n", worst, dt, dk);
    ga_free(s);
    /* the ratios to 1e-6; the first impact to the method's error at h = 1e-3 */
    return worst > 1e-6 || dt > 1e-5 || dk > 1e-5;
}
