/* The lattice's lowest vibration modes on the sparse path (scenes/lattice.h: a cantilever of
 * two materials, 48 x 12 nodes, 1 128 unknowns, clamped at its left column): where it rests
 * under gravity (ga_static_equilibrium, Newton on the sparse [K_t]), its six lowest modes
 * (ga_modes_near at sigma = 0: shift-invert Lanczos on one sparse factorization), and whether
 * its own transient run agrees: released at the rest plus 1e-4 m along the lowest mode, its
 * modal coordinate x_1^T M (q - q_rest) swings with the computed period (zero crossings on the
 * steps, h = T_1 / 400: the method's period error, (omega h)^2 / 12, is 2.1e-5 there). Printed,
 * and checked (exit status 1 if not). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <galpha.h>

#include "scenes/lattice.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

enum { count = 6 };

static int check(int ok, const char *what)
{
    printf("  %-58s %s\n", what, ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}

static ga_solver *make(lattice *l)
{
    ga_solver *s = NULL;
    if (ga_create(l->n, 0, &s) || lattice_declare_patterns(l, s) ||
        ga_set_callbacks(s, lattice_mass, lattice_force, NULL, NULL, l) ||
        ga_set_tangents(s, lattice_stiffness, NULL) || ga_set_constant_mass(s, 1) ||
        ga_set_rho_inf(s, 0.9)) {
        fprintf(stderr, "set-up failed\n");
        exit(1);
    }
    return s;
}

int main(void)
{
    lattice l;
    if (lattice_make(&l, 48, 12, 1e6 * 2.25, 10.0))
        return 1;
    const int n = l.n;
    ga_solver *s = make(&l);
    double *q = calloc((size_t)n, sizeof(double)), *v = calloc((size_t)n, sizeof(double));
    double *shapes = malloc(sizeof(double) * (size_t)n * count), *x = malloc(sizeof(double) * n);
    double w2[count];
    if (!q || !v || !shapes || !x)
        return 1;
    int bad = 0;
    ga_status st = ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 50);
    printf("lattice of %d unknowns\n", n);
    bad += check(st == GA_OK, "rests under gravity");
    if (st) {
        printf("  %s\n", ga_last_error(s));
        return 1;
    }
    printf("  tip sag %.6f m\n", q[n - 1]);
    st = ga_modes_near(s, 0.0, q, NULL, 0.0, count, w2, shapes);
    bad += check(st == GA_OK, "six lowest modes by shift-invert Lanczos");
    if (st) {
        printf("  %s\n", ga_last_error(s));
        return 1;
    }
    for (int k = 0; k < count; ++k)
        printf("  mode %d: omega %.6f rad/s, period %.6f s\n", k + 1, sqrt(w2[k]),
               2.0 * M_PI / sqrt(w2[k]));

    /* the transient run: modal coordinate of mode 1 (unit modal mass, M = mass I) */
    const double T1 = 2.0 * M_PI / sqrt(w2[0]), h = T1 / 400.0;
    double big = 0.0;
    for (int i = 0; i < n; ++i)
        big = fmax(big, fabs(shapes[i]));
    for (int i = 0; i < n; ++i)
        x[i] = q[i] + 1e-4 * shapes[i] / big;
    ga_solver *d = make(&l);
    /* the default 1e-10 on the increments is below what a vibration of 1e-4 m can resolve:
     * its accelerations (1e-2) carry the round-off of spring forces computed from positions
     * up to 48 m (1e-7), and Newton stops with GA_ERR_NEWTON; 1e-6 is above that floor */
    ga_set_newton(d, 1e-6, 20);
    st = ga_init(d, 0.0, x, v);
    double prev = 0.0, first = -1.0, last = -1.0;
    int crossings = 0;
    for (int k = 0; k <= 1600 && !st; ++k) { /* four periods */
        if (k > 0)
            st = ga_step(d, h);
        ga_get_q(d, x);
        double z = 0.0;
        for (int i = 0; i < n; ++i)
            z += l.mass * shapes[i] * (x[i] - q[i]);
        if (k > 0 && prev < 0.0 && z >= 0.0) { /* upward, by linear interpolation */
            const double tc = (k - 1 + prev / (prev - z)) * h;
            if (first < 0.0)
                first = tc;
            last = tc;
            ++crossings;
        }
        prev = z;
    }
    bad += check(st == GA_OK, "its transient run along the lowest mode");
    if (st)
        printf("  %s\n", ga_last_error(d));
    const double period = crossings > 1 ? (last - first) / (crossings - 1) : 0.0;
    printf("  period in the run %.8f s, computed %.8f s: %.2g relative\n", period, T1,
           fabs(period - T1) / T1);
    bad += check(crossings >= 3 && fabs(period - T1) <= 1e-4 * T1,
                 "swings at the computed period (within 1e-4)");
    ga_free(d);
    ga_free(s);
    free(x);
    free(shapes);
    free(v);
    free(q);
    lattice_free(&l);
    return bad ? 1 : 0;
}
