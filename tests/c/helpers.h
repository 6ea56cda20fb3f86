/* Shared by the cmocka suites: least-squares order fits and an independent reference
 * solution of the pendulum (RK4 on the angle equation, not galpha). */
#ifndef GALPHA_TEST_HELPERS_H
#define GALPHA_TEST_HELPERS_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

#include "scenes/pendulum.h"

/* Checkpoint layout 4 (src/checkpoint.cpp), as far as tests look into it: 21 header entries
 * (entry 9: the span of slivers; 19-20: how many consistent accelerations the index-3 error
 * estimate has, and their distance in t), then q, v, qdd, lambda, a, a_prev, c, c_prev; then
 * what rebuilds the kept matrix (4n + m + n) and four pivot blocks. The pendulum's takes 92
 * doubles. */
enum { CKPT_HEADER = 21, CKPT_PENDULUM = 92 };

/* The layout-2 checkpoint (galpha 0.2) of the same state: header entries 0-8 with version 2,
 * then the state; its length. */
static inline size_t ckpt_as_layout2(const double *c3, double *c2)
{
    const size_t state = 5 * (size_t)c3[2] + (size_t)c3[3];
    for (int k = 0; k < 9; ++k)
        c2[k] = c3[k];
    c2[1] = 2.0;
    for (size_t k = 0; k < state; ++k)
        c2[9 + k] = c3[CKPT_HEADER + k];
    return 9 + state;
}

/* The layout-3 checkpoint of the same state (no entries 19-20, no c and c_prev), from one of
 * `len` doubles; its length. */
static inline size_t ckpt_as_layout3(const double *c4, size_t len, double *c3)
{
    const size_t n = (size_t)c4[2], state = 5 * n + (size_t)c4[3];
    size_t k3 = 0;
    for (size_t k = 0; k < 19; ++k)
        c3[k3++] = c4[k];
    c3[1] = 3.0;
    for (size_t k = 0; k < state; ++k)
        c3[k3++] = c4[CKPT_HEADER + k];
    for (size_t k = CKPT_HEADER + state + 2 * n; k < len; ++k)
        c3[k3++] = c4[k];
    return k3;
}

/* What a failed step must leave as it was: header entries 0-9 (t, the step-size control) and
 * 19-20, and q, v, qdd, lambda, a, a_prev, c, c_prev. (The rest rebuilds the kept matrix,
 * which a failed step drops on purpose: the next attempt starts with a fresh one.) */
static inline int ckpt_same_state(const double *x, const double *y)
{
    const size_t state = 7 * (size_t)x[2] + (size_t)x[3];
    return memcmp(x, y, 10 * sizeof(double)) == 0 && memcmp(x + 19, y + 19, 2 * sizeof(double)) == 0 &&
           memcmp(x + CKPT_HEADER, y + CKPT_HEADER, state * sizeof(double)) == 0;
}

/* Slope of the least-squares line through (log h_i, log e_i). */
static inline double fit_order(const double *h, const double *e, int k)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < k; ++i) {
        const double x = log(h[i]), y = log(e[i]);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
    }
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

/* Reference pendulum: theta'' = -(g/L) sin(theta), classical RK4 with `steps` steps to t_end.
 * Returns the Cartesian q, v, qdd and lambda = m (|v|^2 - g y) / L^2 at t_end. */
typedef struct pendulum_exact {
    double q[2], v[2], qdd[2], lambda;
} pendulum_exact;

static inline pendulum_exact pendulum_reference(const pendulum *p, double theta0, double omega0,
                                                double t_end, long steps)
{
    const double w2 = p->gravity / p->length, h = t_end / (double)steps;
    double th = theta0, om = omega0;
    for (long i = 0; i < steps; ++i) {
        const double k1t = om, k1o = -w2 * sin(th);
        const double k2t = om + 0.5 * h * k1o, k2o = -w2 * sin(th + 0.5 * h * k1t);
        const double k3t = om + 0.5 * h * k2o, k3o = -w2 * sin(th + 0.5 * h * k2t);
        const double k4t = om + h * k3o, k4o = -w2 * sin(th + h * k3t);
        th += h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t);
        om += h / 6.0 * (k1o + 2 * k2o + 2 * k3o + k4o);
    }
    pendulum_exact r;
    const double L = p->length, al = -w2 * sin(th); /* angular acceleration */
    pendulum_state(p, th, om, r.q, r.v);
    /* x = L sin th, y = -L cos th: differentiate twice */
    r.qdd[0] = L * (al * cos(th) - om * om * sin(th));
    r.qdd[1] = L * (al * sin(th) + om * om * cos(th));
    r.lambda = p->mass * ((r.v[0] * r.v[0] + r.v[1] * r.v[1]) - p->gravity * r.q[1]) / (L * L);
    return r;
}

/* The pendulum with its constraint twice (m = 2, Phi_q of rank 1): redundant constraints. */
static inline int pendulum_twice_constraint(double t, const double *q, double *phi, void *u)
{
    pendulum_constraint(t, q, phi, u);
    phi[1] = phi[0];
    return 0;
}
static inline int pendulum_twice_jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)u;
    J[0] = J[1] = q[0]; /* 2 x 2 column-major: both rows (x, y) */
    J[2] = J[3] = q[1];
    return 0;
}

/* A solver for the pendulum p with its callbacks set (and the exact K_t with_stiffness);
 * options and ga_init are the caller's. NULL if ga_create or a setter fails. */
static inline ga_solver *pendulum_new_solver(pendulum *p, int with_stiffness)
{
    ga_solver *s = NULL;
    if (ga_create(2, 1, &s) != GA_OK)
        return NULL;
    if (ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                         pendulum_jacobian, p) != GA_OK ||
        (with_stiffness && ga_set_tangents(s, pendulum_stiffness, NULL) != GA_OK)) {
        ga_free(s);
        return NULL;
    }
    return s;
}

static inline double max_abs_diff(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int i = 0; i < n; ++i)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

#endif
