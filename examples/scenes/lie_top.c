/* The heavy top on R^3 x SO(3): see lie_top.h. */
#include "lie_top.h"

#include <math.h>
#include <string.h>

#include <galpha.h>

lie_top lie_top_make(int matrix)
{
    lie_top t = {matrix, 15.0, {0.234375, 0.46875, 0.234375}, {0.0, 1.0, 0.0},
                 {0.0, 0.0, -9.81}, {0.0, 150.0, -4.61538}};
    return t;
}

int lie_top_nq(const lie_top *t) { return t->matrix ? 12 : 7; }

void lie_top_blocks(const lie_top *t, int *kinds, int *counts)
{
    kinds[0] = GA_SPACE_VECTOR;
    counts[0] = 3;
    kinds[1] = t->matrix ? GA_SPACE_SO3_MATRIX : GA_SPACE_SO3_QUATERNION;
    counts[1] = 1;
}

/* R(r) of a unit quaternion r = (w, x, y, z), row-major */
static void quaternion_matrix(const double *r, double R[9])
{
    const double w = r[0], x = r[1], y = r[2], z = r[3];
    const double M[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                         2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(R, M, sizeof M);
}

void lie_top_rotation(const lie_top *t, const double *q, double R[9])
{
    const double *r = q + 3;
    if (t->matrix) {
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                R[3 * i + j] = r[i + 3 * j];
        return;
    }
    quaternion_matrix(r, R);
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

static void rotate(const double R[9], const double *x, double *y)
{
    for (int i = 0; i < 3; ++i)
        y[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}

static void rotate_back(const double R[9], const double *x, double *y) /* R^T x */
{
    for (int i = 0; i < 3; ++i)
        y[i] = R[i] * x[0] + R[3 + i] * x[1] + R[6 + i] * x[2];
}

void lie_top_initial(const lie_top *t, double *q0, double *v0)
{
    memcpy(q0, t->X, 3 * sizeof(double)); /* x = R(0) X = X */
    if (t->matrix) {
        const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        memcpy(q0 + 3, I, sizeof I);
    } else {
        const double one[4] = {1, 0, 0, 0};
        memcpy(q0 + 3, one, sizeof one);
    }
    /* x' = R (omega x X) */
    cross(t->omega0, t->X, v0);
    memcpy(v0 + 3, t->omega0, 3 * sizeof(double));
}

int lie_top_mass(double time, const double *q, double *M, void *user)
{
    (void)time, (void)q;
    const lie_top *t = user;
    memset(M, 0, 36 * sizeof(double));
    for (int i = 0; i < 3; ++i) {
        M[i * 7] = t->mass;
        M[(i + 3) * 7] = t->Jc[i];
    }
    return 0;
}

int lie_top_force(double time, const double *q, const double *v, double *f, void *user)
{
    (void)time, (void)q;
    const lie_top *t = user;
    const double *w = v + 3;
    const double Jw[3] = {t->Jc[0] * w[0], t->Jc[1] * w[1], t->Jc[2] * w[2]};
    double wJw[3];
    cross(w, Jw, wJw);
    for (int i = 0; i < 3; ++i) {
        f[i] = t->mass * t->g[i];
        f[3 + i] = -wJw[i];
    }
    return 0;
}

int lie_top_constraint(double time, const double *q, double *phi, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9], RX[3];
    lie_top_rotation(t, q, R);
    rotate(R, t->X, RX);
    for (int i = 0; i < 3; ++i)
        phi[i] = q[i] - RX[i];
    return 0;
}

/* Phi_q = [I, R X~]: d/de of -R exp(e w) X = -R (w x X) = R (X x w) */
int lie_top_jacobian(double time, const double *q, double *Phi_q, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9];
    lie_top_rotation(t, q, R);
    const double *X = t->X;
    const double Xh[9] = {0, -X[2], X[1], X[2], 0, -X[0], -X[1], X[0], 0};
    memset(Phi_q, 0, 18 * sizeof(double));
    for (int i = 0; i < 3; ++i) {
        Phi_q[i + 3 * i] = 1.0;
        for (int j = 0; j < 3; ++j) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k)
                s += R[3 * i + k] * Xh[3 * k + j];
            Phi_q[i + 3 * (3 + j)] = s;
        }
    }
    return 0;
}

int lie_top_stiffness(double time, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *K, void *user)
{
    (void)time, (void)v, (void)qdd;
    const lie_top *t = user;
    double R[9], l[3];
    lie_top_rotation(t, q, R);
    rotate_back(R, lambda, l);
    const double *X = t->X;
    const double Xh[9] = {0, -X[2], X[1], X[2], 0, -X[0], -X[1], X[0], 0};
    const double lh[9] = {0, -l[2], l[1], l[2], 0, -l[0], -l[1], l[0], 0};
    memset(K, 0, 36 * sizeof(double));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k)
                s += Xh[3 * i + k] * lh[3 * k + j];
            K[(3 + i) + 6 * (3 + j)] = -s;
        }
    return 0;
}

int lie_top_damping(double time, const double *q, const double *v, double *C, void *user)
{
    (void)time, (void)q;
    const lie_top *t = user;
    const double *w = v + 3;
    const double Jw[3] = {t->Jc[0] * w[0], t->Jc[1] * w[1], t->Jc[2] * w[2]};
    /* d/dw (w x J w) = w~ J - (J w)~ */
    const double wh[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
    const double Jwh[9] = {0, -Jw[2], Jw[1], Jw[2], 0, -Jw[0], -Jw[1], Jw[0], 0};
    memset(C, 0, 36 * sizeof(double));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[(3 + i) + 6 * (3 + j)] = wh[3 * i + j] * t->Jc[j] - Jwh[3 * i + j];
    return 0;
}

/* Inertia about the pivot, J_P = J_c + m (|X|^2 I - X X^T), applied to w */
static void pivot_inertia(const lie_top *t, const double *w, double *out)
{
    const double *X = t->X;
    const double XX = X[0] * X[0] + X[1] * X[1] + X[2] * X[2];
    const double Xw = X[0] * w[0] + X[1] * w[1] + X[2] * w[2];
    for (int i = 0; i < 3; ++i)
        out[i] = t->Jc[i] * w[i] + t->mass * (XX * w[i] - X[i] * Xw);
}

int lie_top_pivot_mass(double time, const double *q, double *M, void *user)
{
    (void)time, (void)q;
    const lie_top *t = user;
    double e[3] = {0, 0, 0};
    for (int j = 0; j < 3; ++j) {
        e[j] = 1.0;
        pivot_inertia(t, e, M + 3 * j);
        e[j] = 0.0;
    }
    return 0;
}

int lie_top_pivot_force(double time, const double *q, const double *v, double *f, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9], mg[3], gb[3], n[3], Jw[3], wJw[3];
    quaternion_matrix(q, R);
    for (int i = 0; i < 3; ++i)
        mg[i] = t->mass * t->g[i];
    rotate_back(R, mg, gb);
    cross(t->X, gb, n);
    pivot_inertia(t, v, Jw);
    cross(v, Jw, wJw);
    for (int i = 0; i < 3; ++i)
        f[i] = n[i] - wJw[i];
    return 0;
}

void lie_top_invariants(const lie_top *t, const double *q, const double *v, double out[3])
{
    double R[9], Jw[3], L[3], com[3];
    lie_top_rotation(t, q, R);
    const double *w = v + 3;
    pivot_inertia(t, w, Jw);
    rotate(R, Jw, L);
    rotate(R, t->X, com);
    out[0] = 0.5 * (w[0] * Jw[0] + w[1] * Jw[1] + w[2] * Jw[2]) -
             t->mass * (t->g[0] * com[0] + t->g[1] * com[1] + t->g[2] * com[2]);
    out[1] = L[2];
    out[2] = w[1];
}

/* Euler's equations about the pivot: y = (R row-major, omega) */
static void euler_rates(const lie_top *t, const double *y, double *dy)
{
    const double *R = y, *w = y + 9;
    /* R' = R w~ */
    const double wh[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            dy[3 * i + j] = R[3 * i] * wh[j] + R[3 * i + 1] * wh[3 + j] + R[3 * i + 2] * wh[6 + j];
    double Jw[3], wJw[3], mg[3], gb[3], n[3];
    pivot_inertia(t, w, Jw);
    cross(w, Jw, wJw);
    for (int i = 0; i < 3; ++i)
        mg[i] = t->mass * t->g[i];
    rotate_back(R, mg, gb);
    cross(t->X, gb, n);
    double rhs[3];
    for (int i = 0; i < 3; ++i)
        rhs[i] = n[i] - wJw[i];
    /* J_P is diagonal for X on a body axis (diag(Jc) + m (|X|^2 I - X X^T)) */
    double d[3], e[3] = {0, 0, 0};
    for (int i = 0; i < 3; ++i) {
        e[i] = 1.0;
        pivot_inertia(t, e, d);
        dy[9 + i] = rhs[i] / d[i];
        e[i] = 0.0;
    }
}

lie_top_state lie_top_reference(const lie_top *t, double t_end, long steps)
{
    double y[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0}, k1[12], k2[12], k3[12], k4[12], z[12];
    memcpy(y + 9, t->omega0, 3 * sizeof(double));
    const double h = t_end / (double)steps;
    for (long s = 0; s < steps; ++s) {
        euler_rates(t, y, k1);
        for (int i = 0; i < 12; ++i) z[i] = y[i] + 0.5 * h * k1[i];
        euler_rates(t, z, k2);
        for (int i = 0; i < 12; ++i) z[i] = y[i] + 0.5 * h * k2[i];
        euler_rates(t, z, k3);
        for (int i = 0; i < 12; ++i) z[i] = y[i] + h * k3[i];
        euler_rates(t, z, k4);
        for (int i = 0; i < 12; ++i) y[i] += h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    }
    lie_top_state r;
    memcpy(r.R, y, sizeof r.R);
    memcpy(r.omega, y + 9, sizeof r.omega);
    euler_rates(t, y, k1);
    memcpy(r.omega_dot, k1 + 9, sizeof r.omega_dot);
    rotate(r.R, t->X, r.com);
    /* x'' = R (w' x X + w x (w x X)); lambda = m g - m x'' */
    double a[3], b[3], c[3], acc[3];
    cross(r.omega_dot, t->X, a);
    cross(r.omega, t->X, b);
    cross(r.omega, b, c);
    for (int i = 0; i < 3; ++i)
        b[i] = a[i] + c[i];
    rotate(r.R, b, acc);
    for (int i = 0; i < 3; ++i)
        r.reaction[i] = t->mass * (t->g[i] - acc[i]);
    return r;
}

/* ---- the top on SE(3) ---- */

static void hat(const double *a, double A[9]) /* row-major a~ */
{
    const double M[9] = {0, -a[2], a[1], a[2], 0, -a[0], -a[1], a[0], 0};
    memcpy(A, M, sizeof M);
}

void lie_top_se3_initial(const lie_top *t, double *q0, double *v0)
{
    lie_top_initial(t, q0, v0); /* x = X, R = I; x' = omega x X = U at R = I */
}

int lie_top_se3_force(double time, const double *q, const double *v, double *f, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9], mg[3], gb[3], wU[3], Jw[3], wJw[3];
    lie_top_rotation(t, q, R);
    const double *U = v, *w = v + 3;
    for (int i = 0; i < 3; ++i)
        mg[i] = t->mass * t->g[i];
    rotate_back(R, mg, gb);
    cross(w, U, wU);
    for (int i = 0; i < 3; ++i)
        Jw[i] = t->Jc[i] * w[i];
    cross(w, Jw, wJw);
    for (int i = 0; i < 3; ++i) {
        f[i] = gb[i] - t->mass * wU[i];
        f[3 + i] = -wJw[i];
    }
    return 0;
}

int lie_top_se3_constraint(double time, const double *q, double *phi, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9], y[3];
    lie_top_rotation(t, q, R);
    rotate_back(R, q, y);
    for (int i = 0; i < 3; ++i)
        phi[i] = y[i] - t->X[i];
    return 0;
}

/* d/de of exp(-e w~) R^T (x + e R u) = u - w x y = u + y~ w, y = R^T x */
int lie_top_se3_jacobian(double time, const double *q, double *Phi_q, void *user)
{
    (void)time;
    const lie_top *t = user;
    double R[9], y[3], Y[9];
    lie_top_rotation(t, q, R);
    rotate_back(R, q, y);
    hat(y, Y);
    memset(Phi_q, 0, 18 * sizeof(double));
    for (int i = 0; i < 3; ++i) {
        Phi_q[i + 3 * i] = 1.0;
        for (int j = 0; j < 3; ++j)
            Phi_q[i + 3 * (3 + j)] = Y[3 * i + j];
    }
    return 0;
}

int lie_top_se3_stiffness(double time, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *K, void *user)
{
    (void)time, (void)v, (void)qdd;
    const lie_top *t = user;
    double R[9], y[3], mg[3], gb[3], G[9], L[9], Y[9];
    lie_top_rotation(t, q, R);
    rotate_back(R, q, y);
    for (int i = 0; i < 3; ++i)
        mg[i] = t->mass * t->g[i];
    rotate_back(R, mg, gb);
    hat(gb, G);
    hat(lambda, L);
    hat(y, Y);
    memset(K, 0, 36 * sizeof(double));
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double LY = 0.0;
            for (int k = 0; k < 3; ++k)
                LY += L[3 * i + k] * Y[3 * k + j];
            K[i + 6 * (3 + j)] = -G[3 * i + j];
            K[(3 + i) + 6 * j] = L[3 * i + j];
            K[(3 + i) + 6 * (3 + j)] = LY;
        }
    return 0;
}

int lie_top_se3_damping(double time, const double *q, const double *v, double *C, void *user)
{
    lie_top_damping(time, q, v, C, user); /* the (w, w) block, zeros elsewhere */
    const lie_top *t = user;
    double W[9], Uh[9];
    hat(v + 3, W);
    hat(v, Uh);
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            C[i + 6 * j] = t->mass * W[3 * i + j];
            C[i + 6 * (3 + j)] = -t->mass * Uh[3 * i + j];
        }
    return 0;
}
