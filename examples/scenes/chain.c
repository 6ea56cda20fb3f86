#include "chain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

chain chain_make(int links)
{
    chain c;
    c.links = links;
    c.length = 1.0;
    c.mass = 1.0;
    c.inertia = c.mass * c.length * c.length / 12.0;
    c.gravity = 9.81;
    return c;
}

enum { X = 0, Y = 1, TH = 2 };
#define Q(i, k) (3 * (i) + (k))

/* Jacobian rows 2i (x) and 2i+1 (y) of joint i: start of link i minus end of link i-1 (or the
 * pin). Entries in the order: x_i, th_i, [x_{i-1}, th_{i-1}] for the x row, likewise for y. */
int chain_pattern(const chain *c, int which, int *rows, int *cols)
{
    const int N = c->links;
    int k = 0;
#define PUT(r, col)                                                                            \
    do {                                                                                       \
        if (rows) {                                                                            \
            rows[k] = (r);                                                                     \
            cols[k] = (col);                                                                   \
        }                                                                                      \
        ++k;                                                                                   \
    } while (0)
    switch (which) {
    case GA_MATRIX_MASS:
        for (int i = 0; i < 3 * N; ++i)
            PUT(i, i);
        break;
    case GA_MATRIX_JACOBIAN:
        for (int i = 0; i < N; ++i) {
            for (int d = 0; d < 2; ++d) {
                PUT(2 * i + d, Q(i, d));
                PUT(2 * i + d, Q(i, TH));
                if (i > 0) {
                    PUT(2 * i + d, Q(i - 1, d));
                    PUT(2 * i + d, Q(i - 1, TH));
                }
            }
        }
        break;
    case GA_MATRIX_STIFFNESS: /* d(Phi_q^T lambda)/dq touches the angles only */
        for (int i = 0; i < N; ++i)
            PUT(Q(i, TH), Q(i, TH));
        break;
    default: /* GA_MATRIX_DAMPING: gravity does not depend on v */
        break;
    }
#undef PUT
    return k;
}

ga_status chain_declare_patterns(const chain *c, ga_solver *s)
{
    ga_status st = GA_OK;
    for (int which = GA_MATRIX_MASS; which <= GA_MATRIX_DAMPING && !st; ++which) {
        const int nnz = chain_pattern(c, which, NULL, NULL);
        int *rows = malloc(sizeof(int) * (size_t)(nnz + 1));
        int *cols = malloc(sizeof(int) * (size_t)(nnz + 1));
        if (!rows || !cols) {
            st = GA_ERR_NOMEM;
        } else {
            chain_pattern(c, which, rows, cols);
            st = ga_set_pattern(s, which, nnz, rows, cols);
        }
        free(rows);
        free(cols);
    }
    return st;
}

int chain_mass(double t, const double *q, double *M, void *user)
{
    const chain *c = user;
    (void)t, (void)q;
    for (int i = 0; i < c->links; ++i) {
        M[Q(i, X)] = c->mass;
        M[Q(i, Y)] = c->mass;
        M[Q(i, TH)] = c->inertia;
    }
    return 0;
}

int chain_force(double t, const double *q, const double *v, double *f, void *user)
{
    const chain *c = user;
    (void)t, (void)q, (void)v;
    for (int i = 0; i < c->links; ++i) {
        f[Q(i, X)] = 0.0;
        f[Q(i, Y)] = -c->mass * c->gravity;
        f[Q(i, TH)] = 0.0;
    }
    return 0;
}

int chain_constraint(double t, const double *q, double *phi, void *user)
{
    const chain *c = user;
    const double h = 0.5 * c->length;
    (void)t;
    for (int i = 0; i < c->links; ++i) {
        double ex = q[Q(i, X)] - h * cos(q[Q(i, TH)]), ey = q[Q(i, Y)] - h * sin(q[Q(i, TH)]);
        if (i > 0) {
            ex -= q[Q(i - 1, X)] + h * cos(q[Q(i - 1, TH)]);
            ey -= q[Q(i - 1, Y)] + h * sin(q[Q(i - 1, TH)]);
        }
        phi[2 * i] = ex;
        phi[2 * i + 1] = ey;
    }
    return 0;
}

int chain_jacobian(double t, const double *q, double *J, void *user)
{
    const chain *c = user;
    const double h = 0.5 * c->length;
    int k = 0;
    (void)t;
    for (int i = 0; i < c->links; ++i) {
        const double s = sin(q[Q(i, TH)]), co = cos(q[Q(i, TH)]);
        const double sp = i > 0 ? sin(q[Q(i - 1, TH)]) : 0.0;
        const double cp = i > 0 ? cos(q[Q(i - 1, TH)]) : 0.0;
        /* x row: x_i, th_i, x_{i-1}, th_{i-1} */
        J[k++] = 1.0;
        J[k++] = h * s;
        if (i > 0) {
            J[k++] = -1.0;
            J[k++] = h * sp;
        }
        /* y row */
        J[k++] = 1.0;
        J[k++] = -h * co;
        if (i > 0) {
            J[k++] = -1.0;
            J[k++] = -h * cp;
        }
    }
    return 0;
}

/* theta_i enters joint i (as the link's start) and joint i+1 (as the previous link's end);
 * both contribute h (cos th lambda_x + sin th lambda_y) to d(Phi_q^T lambda)/dth_i. */
int chain_stiffness(double t, const double *q, const double *v, const double *qdd,
                    const double *lambda, double *K, void *user)
{
    const chain *c = user;
    const double h = 0.5 * c->length;
    (void)t, (void)v, (void)qdd;
    for (int i = 0; i < c->links; ++i) {
        const double s = sin(q[Q(i, TH)]), co = cos(q[Q(i, TH)]);
        double lx = lambda[2 * i], ly = lambda[2 * i + 1];
        if (i + 1 < c->links) {
            lx += lambda[2 * (i + 1)];
            ly += lambda[2 * (i + 1) + 1];
        }
        K[i] = h * (co * lx + s * ly);
    }
    return 0;
}

int chain_constraint_accel(double t, const double *q, const double *v, double *out, void *user)
{
    const chain *c = user;
    const double h = 0.5 * c->length;
    (void)t;
    for (int i = 0; i < c->links; ++i) {
        const double w = v[Q(i, TH)] * v[Q(i, TH)];
        double ax = h * cos(q[Q(i, TH)]) * w, ay = h * sin(q[Q(i, TH)]) * w;
        if (i > 0) {
            const double wp = v[Q(i - 1, TH)] * v[Q(i - 1, TH)];
            ax += h * cos(q[Q(i - 1, TH)]) * wp;
            ay += h * sin(q[Q(i - 1, TH)]) * wp;
        }
        out[2 * i] = ax;
        out[2 * i + 1] = ay;
    }
    return 0;
}

void chain_initial(const chain *c, double *q, double *v)
{
    memset(v, 0, sizeof(double) * 3 * (size_t)c->links);
    for (int i = 0; i < c->links; ++i) {
        q[Q(i, X)] = (i + 0.5) * c->length;
        q[Q(i, Y)] = 0.0;
        q[Q(i, TH)] = 0.0;
    }
}

int chain_constraint_dt(double t, const double *q, double *out, void *user)
{
    const chain *c = user;
    (void)t, (void)q;
    memset(out, 0, sizeof(double) * 2 * (size_t)c->links);
    return 0;
}
