/* The heavy top spun at 150 rad/s, integrated on the rotation group (ga_create_space): its
 * centre of mass in R^3, its rotation as a unit quaternion about it, the spherical joint at the
 * origin as three constraints (examples/scenes/lie_top.h). Stabilized index 2 with adaptive
 * steps to t = 2 at tolerance 1e-6; printed every 0.25 s: the centre of mass, the quaternion's
 * norm (galpha keeps it on the group, no norm constraint) and the three invariants of this
 * Lagrange top (energy, vertical angular momentum, spin). Exit status 1 if an invariant drifts
 * by more than 1e-4 of its size or the quaternion leaves the unit sphere. */
#include <math.h>
#include <stdio.h>

#include <galpha.h>

#include "scenes/lie_top.h"

int main(void)
{
    lie_top top = lie_top_make(0);
    int kinds[2], counts[2];
    lie_top_blocks(&top, kinds, counts);
    ga_solver *s = NULL;
    if (ga_create_space(2, kinds, counts, LIE_TOP_M, &s) != GA_OK)
        return 1;
    double q[7], v[6], inv0[3], inv[3];
    lie_top_initial(&top, q, v);
    lie_top_invariants(&top, q, v, inv0);
    ga_status st = ga_set_callbacks(s, lie_top_mass, lie_top_force, lie_top_constraint,
                                    lie_top_jacobian, &top);
    if (!st)
        st = ga_set_tangents(s, lie_top_stiffness, lie_top_damping);
    if (!st)
        st = ga_set_formulation(s, GA_INDEX2_STABILIZED);
    if (!st)
        st = ga_set_tolerances(s, 1e-6, 1e-6);
    if (!st)
        st = ga_init(s, 0.0, q, v);
    double drift = 0.0, norm_off = 0.0;
    printf("     t    centre of mass                     |q|-1      energy drift\n");
    for (int k = 1; k <= 8 && !st; ++k) {
        const double t = 0.25 * k;
        st = ga_advance(s, t);
        if (!st)
            st = ga_interpolate(s, t, q, v, NULL);
        if (st)
            break;
        lie_top_invariants(&top, q, v, inv);
        for (int i = 0; i < 3; ++i)
            drift = fmax(drift, fabs(inv[i] - inv0[i]) / fabs(inv0[i]));
        const double n = sqrt(q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6]);
        norm_off = fmax(norm_off, fabs(n - 1.0));
        printf("  %4.2f  %10.6f %10.6f %10.6f  %9.1e  %9.1e\n", t, q[0], q[1], q[2], n - 1.0,
               fabs(inv[0] - inv0[0]) / fabs(inv0[0]));
    }
    long long steps = 0;
    ga_get_counter(s, GA_COUNT_STEPS, &steps);
    if (st) {
        printf("failed: %s\n", ga_last_error(s));
        ga_free(s);
        return 1;
    }
    printf("%lld steps; invariants within %.1e, |q| within %.1e of 1\n", steps, drift, norm_off);
    ga_free(s);
    return drift < 1e-4 && norm_off < 1e-12 ? 0 : 1;
}
