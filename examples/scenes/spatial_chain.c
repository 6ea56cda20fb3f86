/* The spatial chain on (R^3 x SO(3))^N: see spatial_chain.h. */
#include "spatial_chain.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

spatial_chain spatial_chain_make(int bodies, double spin)
{
    spatial_chain c;
    c.bodies = bodies;
    c.length = 1.0;
    c.mass = 1.0;
    const double r = 0.05, L = c.length;
    c.inertia[0] = c.inertia[1] = c.mass * (3 * r * r + L * L) / 12.0;
    c.inertia[2] = c.mass * r * r / 2.0;
    c.gravity = 9.81;
    c.spin = spin;
    return c;
}

void spatial_chain_blocks(const spatial_chain *c, int *kinds, int *counts)
{
    for (int k = 0; k < c->bodies; ++k) {
        kinds[2 * k] = GA_SPACE_VECTOR;
        counts[2 * k] = 3;
        kinds[2 * k + 1] = GA_SPACE_SO3_QUATERNION;
        counts[2 * k + 1] = 1;
    }
}

#define QX(k) (7 * (k))     /* x of body k in q */
#define QR(k) (7 * (k) + 3) /* its quaternion */
#define VX(k) (6 * (k))     /* x' in v */
#define VW(k) (6 * (k) + 3) /* omega */

/* R(r) of the unit quaternion r = (w, x, y, z), row-major */
static void rotation(const double *r, double R[9])
{
    const double w = r[0], x = r[1], y = r[2], z = r[3];
    R[0] = 1 - 2 * (y * y + z * z);
    R[1] = 2 * (x * y - w * z);
    R[2] = 2 * (x * z + w * y);
    R[3] = 2 * (x * y + w * z);
    R[4] = 1 - 2 * (x * x + z * z);
    R[5] = 2 * (y * z - w * x);
    R[6] = 2 * (x * z - w * y);
    R[7] = 2 * (y * z + w * x);
    R[8] = 1 - 2 * (x * x + y * y);
}

/* Entries, in the order the callbacks write them:
 * M: the diagonal, body by body (m, m, m, I1, I2, I3).
 * Phi_q, joint k (rows 3k..3k+2): for each row d, x_k[d], the rotation columns 0, 1 of body k,
 *   and for k > 0 x_{k-1}[d] and the rotation columns 0, 1 of body k-1.
 * K_t, body k: (psi0, psi0), (psi0, psi2), (psi1, psi1), (psi1, psi2).
 * C_t, body k: the 3 x 3 omega block, column by column. */
int spatial_chain_pattern(const spatial_chain *c, int which, int *rows, int *cols)
{
    const int N = c->bodies;
    int n = 0;
#define PUT(r, col)                                                                            \
    do {                                                                                       \
        if (rows) {                                                                            \
            rows[n] = (r);                                                                     \
            cols[n] = (col);                                                                   \
        }                                                                                      \
        ++n;                                                                                   \
    } while (0)
    switch (which) {
    case GA_MATRIX_MASS:
        for (int i = 0; i < 6 * N; ++i)
            PUT(i, i);
        break;
    case GA_MATRIX_JACOBIAN:
        for (int k = 0; k < N; ++k)
            for (int d = 0; d < 3; ++d) {
                PUT(3 * k + d, VX(k) + d);
                PUT(3 * k + d, VW(k));
                PUT(3 * k + d, VW(k) + 1);
                if (k > 0) {
                    PUT(3 * k + d, VX(k - 1) + d);
                    PUT(3 * k + d, VW(k - 1));
                    PUT(3 * k + d, VW(k - 1) + 1);
                }
            }
        break;
    case GA_MATRIX_STIFFNESS:
        for (int k = 0; k < N; ++k) {
            PUT(VW(k), VW(k));
            PUT(VW(k), VW(k) + 2);
            PUT(VW(k) + 1, VW(k) + 1);
            PUT(VW(k) + 1, VW(k) + 2);
        }
        break;
    default: /* GA_MATRIX_DAMPING */
        for (int k = 0; k < N; ++k)
            for (int j = 0; j < 3; ++j)
                for (int i = 0; i < 3; ++i)
                    PUT(VW(k) + i, VW(k) + j);
        break;
    }
#undef PUT
    return n;
}

ga_status spatial_chain_solver(spatial_chain *c, ga_solver **out)
{
    *out = NULL;
    const int N = c->bodies;
    int *kinds = malloc(sizeof(int) * 2 * (size_t)N), *counts = malloc(sizeof(int) * 2 * (size_t)N);
    ga_solver *s = NULL;
    ga_status st = kinds && counts ? GA_OK : GA_ERR_NOMEM;
    if (!st) {
        spatial_chain_blocks(c, kinds, counts);
        st = ga_create_space(2 * N, kinds, counts, 3 * N, &s);
    }
    free(kinds);
    free(counts);
    if (!st)
        st = ga_set_callbacks(s, spatial_chain_mass, spatial_chain_force, spatial_chain_constraint,
                              spatial_chain_jacobian, c);
    if (!st)
        st = ga_set_tangents(s, spatial_chain_stiffness, spatial_chain_damping);
    for (int which = GA_MATRIX_MASS; which <= GA_MATRIX_DAMPING && !st; ++which) {
        const int nnz = spatial_chain_pattern(c, which, NULL, NULL);
        int *rows = malloc(sizeof(int) * (size_t)(nnz + 1));
        int *cols = malloc(sizeof(int) * (size_t)(nnz + 1));
        if (!rows || !cols) {
            st = GA_ERR_NOMEM;
        } else {
            spatial_chain_pattern(c, which, rows, cols);
            st = ga_set_pattern(s, which, nnz, rows, cols);
        }
        free(rows);
        free(cols);
    }
    if (!st)
        st = ga_set_constant_mass(s, 1);
    if (st) {
        ga_free(s);
        return st;
    }
    *out = s;
    return GA_OK;
}

int spatial_chain_mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q;
    const spatial_chain *c = user;
    for (int k = 0; k < c->bodies; ++k)
        for (int i = 0; i < 3; ++i) {
            M[6 * k + i] = c->mass;
            M[6 * k + 3 + i] = c->inertia[i];
        }
    return 0;
}

int spatial_chain_force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t, (void)q;
    const spatial_chain *c = user;
    const double *J = c->inertia;
    for (int k = 0; k < c->bodies; ++k) {
        const double *w = v + VW(k);
        f[VX(k)] = 0.0;
        f[VX(k) + 1] = 0.0;
        f[VX(k) + 2] = -c->mass * c->gravity;
        /* -omega x J omega */
        f[VW(k)] = -(w[1] * J[2] * w[2] - w[2] * J[1] * w[1]);
        f[VW(k) + 1] = -(w[2] * J[0] * w[0] - w[0] * J[2] * w[2]);
        f[VW(k) + 2] = -(w[0] * J[1] * w[1] - w[1] * J[0] * w[0]);
    }
    return 0;
}

/* Phi_k = x_k + R_k a - x_{k-1} - R_{k-1} b, a = (0, 0, L/2) = -b (x_{-1} = R_{-1} b = 0) */
int spatial_chain_constraint(double t, const double *q, double *phi, void *user)
{
    (void)t;
    const spatial_chain *c = user;
    const double h = 0.5 * c->length;
    double R[9], Rp[9];
    for (int k = 0; k < c->bodies; ++k) {
        rotation(q + QR(k), R);
        for (int d = 0; d < 3; ++d)
            phi[3 * k + d] = q[QX(k) + d] + h * R[3 * d + 2];
        if (k > 0) {
            rotation(q + QR(k - 1), Rp);
            for (int d = 0; d < 3; ++d)
                phi[3 * k + d] -= q[QX(k - 1) + d] - h * Rp[3 * d + 2];
        }
    }
    return 0;
}

/* d(R a)/dpsi = -R a~: columns (-h R e1, h R e0, 0); d(-R b)/dpsi = R b~ = -R a~ likewise */
int spatial_chain_jacobian(double t, const double *q, double *J, void *user)
{
    (void)t;
    const spatial_chain *c = user;
    const double h = 0.5 * c->length;
    double R[9], Rp[9];
    int n = 0;
    for (int k = 0; k < c->bodies; ++k) {
        rotation(q + QR(k), R);
        if (k > 0)
            rotation(q + QR(k - 1), Rp);
        for (int d = 0; d < 3; ++d) {
            J[n++] = 1.0;
            J[n++] = -h * R[3 * d + 1];
            J[n++] = h * R[3 * d];
            if (k > 0) {
                J[n++] = -1.0;
                J[n++] = -h * Rp[3 * d + 1];
                J[n++] = h * Rp[3 * d];
            }
        }
    }
    return 0;
}

/* K_t of Phi_q^T lambda: body k's rotation rows are a~ R_k^T (lambda_k + lambda_{k+1}) = a~ l,
 * whose derivative along psi is a~ l~ (l turns by -psi x l): rows (0, -h, 0) l~ and (h, 0, 0) l~ */
int spatial_chain_stiffness(double t, const double *q, const double *v, const double *qdd,
                            const double *lambda, double *K, void *user)
{
    (void)t, (void)v, (void)qdd;
    const spatial_chain *c = user;
    const int N = c->bodies;
    const double h = 0.5 * c->length;
    double R[9];
    for (int k = 0; k < N; ++k) {
        double s[3];
        for (int d = 0; d < 3; ++d)
            s[d] = lambda[3 * k + d] + (k + 1 < N ? lambda[3 * (k + 1) + d] : 0.0);
        rotation(q + QR(k), R);
        double l[3];
        for (int i = 0; i < 3; ++i)
            l[i] = R[i] * s[0] + R[3 + i] * s[1] + R[6 + i] * s[2];
        /* -h (row 1 of l~) = -h (l2, 0, -l0); h (row 0 of l~) = h (0, -l2, l1) */
        K[4 * k] = -h * l[2];
        K[4 * k + 1] = h * l[0];
        K[4 * k + 2] = -h * l[2];
        K[4 * k + 3] = h * l[1];
    }
    return 0;
}

/* C_t = d(omega x J omega)/d omega = omega~ J - (J omega)~ */
int spatial_chain_damping(double t, const double *q, const double *v, double *C, void *user)
{
    (void)t, (void)q;
    const spatial_chain *c = user;
    const double *I = c->inertia;
    for (int k = 0; k < c->bodies; ++k) {
        const double *w = v + VW(k);
        const double Jw[3] = {I[0] * w[0], I[1] * w[1], I[2] * w[2]};
        const double wh[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
        const double Jwh[9] = {0, -Jw[2], Jw[1], Jw[2], 0, -Jw[0], -Jw[1], Jw[0], 0};
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i)
                C[9 * k + 3 * j + i] = wh[3 * i + j] * I[j] - Jwh[3 * i + j];
    }
    return 0;
}

void spatial_chain_initial(const spatial_chain *c, double *q, double *v)
{
    /* every rod turned by -90 degrees about y: its axis z along -x, top end towards the pin */
    const double s = sqrt(0.5);
    for (int k = 0; k < c->bodies; ++k) {
        q[QX(k)] = (k + 0.5) * c->length;
        q[QX(k) + 1] = 0.0;
        q[QX(k) + 2] = 0.0;
        q[QR(k)] = s;
        q[QR(k) + 1] = 0.0;
        q[QR(k) + 2] = -s;
        q[QR(k) + 3] = 0.0;
        memset(v + 6 * k, 0, 6 * sizeof(double));
        v[VW(k) + 2] = c->spin;
    }
}
