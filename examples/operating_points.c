/* The slider-crank with a spring-damper and a constant push (scenes/crank_spring_damper.h):
 * where it rests, how it vibrates there, and whether its own transient run agrees.
 * ga_static_equilibrium finds two rests: from the start of the IDAS example (theta = pi/2)
 * the folded one, theta = pi, which ga_modes shows unstable (omega^2 < 0); from theta = 0.5
 * the stretched one, theta = 0, whose undamped frequency ga_modes gives and whose damped pair
 * s ga_modes_damped: there the damper's line is normal to the mode's motion, so it acts at
 * second order only and the linearized mode is undamped (Re s = 0 to round-off). Then a run
 * released at the rest stays there, and a run released 1e-4 along the mode swings at Im s and
 * keeps its amplitude (the method's own damping at rho_inf = 0.9 and 4 000 steps a period
 * aside), read from the crank angle's extremes. Printed, and checked (exit status 1 if not). */
#include <math.h>
#include <stdio.h>

#include <galpha.h>

#include "scenes/crank_spring_damper.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int check(int ok, const char *what)
{
    printf("  %-58s %s\n", what, ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}

int main(void)
{
    crank_spring_damper c = crank_spring_damper_idas();
    ga_solver *s = NULL;
    if (ga_create(CSD_N, CSD_M, &s) != GA_OK ||
        ga_set_callbacks(s, csd_mass, csd_force, csd_constraint, csd_jacobian, &c) != GA_OK)
        return 1;
    double q[CSD_N], v[CSD_N], lambda[CSD_M], w2, shape[CSD_N], re[2], im[2];
    csd_initial(&c, q, v);
    int failed = 0;
    if (ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50) != GA_OK ||
        ga_modes(s, 0.0, q, lambda, 1, &w2, NULL) != GA_OK) {
        printf("static equilibrium: %s\n", ga_last_error(s));
        return 1;
    }
    printf("from the IDAS start: rest at theta %.12f, x %.12f, omega^2 %.9f\n", q[0], q[1], w2);
    failed += check(fabs(q[0] - M_PI) <= 1e-12 && w2 < 0.0, "the folded rest, unstable");
    /* from a guess near the stretched position */
    const double guess_phi = asin(-c.a * sin(0.5));
    q[0] = 0.5;
    q[1] = cos(guess_phi) + c.a * cos(0.5);
    q[2] = guess_phi;
    if (ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50) != GA_OK) {
        printf("static equilibrium: %s\n", ga_last_error(s));
        return 1;
    }
    printf("rest: theta %.12f, x %.12f, phi %.12f; lambda %.6f %.6f\n", q[0], q[1], q[2], lambda[0],
           lambda[1]);
    if (ga_modes(s, 0.0, q, lambda, 1, &w2, shape) != GA_OK ||
        ga_modes_damped(s, 0.0, q, lambda, 2, re, im, NULL, NULL) != GA_OK) {
        printf("modes: %s\n", ga_last_error(s));
        return 1;
    }
    printf("undamped: omega %.9f rad/s; damped: s = %.9f +- %.9f i\n", sqrt(w2), re[0], im[0]);
    failed += check(w2 > 0.0 && fabs(im[0] - sqrt(w2)) <= 1e-12 * sqrt(w2),
                    "a stable rest; the damped pair at +-i omega");

    /* released at the rest: it stays (round-off) */
    const double zero[CSD_N] = {0.0, 0.0, 0.0};
    double qt[CSD_N], drift = 0.0;
    ga_init(s, 0.0, q, zero);
    for (int k = 0; k < 2000; ++k)
        ga_step(s, 1e-3);
    ga_get_q(s, qt);
    for (int i = 0; i < CSD_N; ++i)
        drift = fmax(drift, fabs(qt[i] - q[i]));
    printf("released at the rest: after 2 s q moved %.3g\n", drift);
    failed += check(drift <= 1e-12, "it stays at rest");

    /* released 1e-4 along the mode: the crank angle's extremes, every half period */
    double q0[CSD_N];
    for (int i = 0; i < CSD_N; ++i)
        q0[i] = q[i] + 1e-4 * shape[i] / fabs(shape[0]);
    ga_init(s, 0.0, q0, zero);
    const double period = 2.0 * M_PI / im[0], h = period / 4000.0;
    double t_ext[8], a_ext[8], prev2 = q0[0] - q[0], prev = prev2, t = 0.0;
    int found = 0;
    while (found < 8 && t < 20.0 * period) {
        if (ga_step(s, h) != GA_OK)
            return 1;
        t += h;
        double qq[CSD_N];
        ga_get_q(s, qq);
        const double d = qq[0] - q[0];
        if ((prev - prev2) * (d - prev) < 0.0) { /* an extreme at the last step: a parabola */
            const double den = prev2 - 2.0 * prev + d;
            const double off = 0.5 * (prev2 - d) / den;
            t_ext[found] = t - h + off * h;
            a_ext[found] = fabs(prev - 0.25 * (prev2 - d) * off);
            ++found;
        }
        prev2 = prev;
        prev = d;
    }
    if (found < 8)
        return 1;
    const double half = (t_ext[7] - t_ext[1]) / 6.0;
    const double decay = log(a_ext[7] / a_ext[1]) / (t_ext[7] - t_ext[1]);
    printf("released along the mode: half period %.9f (pi / Im s %.9f), decay rate %.3g "
           "(Re s %.3g)\n",
           half, M_PI / im[0], decay, re[0]);
    failed += check(fabs(half - M_PI / im[0]) <= 1e-5 * M_PI / im[0], "its swing at Im s (1e-5)");
    failed += check(fabs(re[0]) <= 1e-12 * im[0], "the damper does not act on the mode");
    failed += check(fabs(decay - re[0]) <= 1e-5 * im[0], "its amplitude kept (1e-5 of Im s)");
    ga_free(s);
    return failed ? 1 : 0;
}
