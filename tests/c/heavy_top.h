/* The heavy top in Euler parameters (the spatial test of Brüls & Cardona 2010; data as issue 36
 * gives it): a rigid body on a fixed spherical joint at the origin, m = 15, centroidal inertia
 * diag(0.234375, 0.46875, 0.234375), centre of mass at r = (0, 1, 0) in the body, gravity
 * (0, 0, -9.81), body angular velocity (0, 150, -4.61538) at t = 0, body frame = inertial frame.
 *
 * Oracle: top_reference, RK4 on the body-frame Euler equations (an ODE in p and omega',
 * no constraint), independent of the DAE form the solver integrates.
 *
 * q = p = (e0, e1, e2, e3), one constraint Phi = (p^T p - 1) / 2. With L(p) the 3 x 4 matrix
 * of omega' = 2 L(p) p' (body angular velocity; Nikravesh's L) and J the inertia about the
 * joint, T = 2 p'^T L^T J L p' gives (Lagrange; L(p') p' = 0, L(p) p' = -L(p') p)
 *     4 L^T J L p'' = 2 L^T n' - 8 L(p')^T J L(p) p' - p lambda,
 * n' = r x (A^T F) the body-frame moment of gravity about the joint. M = 4 L^T J L is singular
 * along p, which the constraint's gradient p^T completes. */
#ifndef GALPHA_TEST_HEAVY_TOP_H
#define GALPHA_TEST_HEAVY_TOP_H

#include <math.h>
#include <string.h>

enum { TOP_N = 4, TOP_M = 1 };

typedef struct heavy_top {
    double mass, gravity;
    double J[3];  /* principal inertia about the joint: centroidal + m (|r|^2 I - r r^T) */
    double r[3];  /* centre of mass in the body */
} heavy_top;

static inline heavy_top heavy_top_make(void)
{
    heavy_top t = {15.0, 9.81, {0.234375, 0.46875, 0.234375}, {0.0, 1.0, 0.0}};
    const double rr = t.r[0] * t.r[0] + t.r[1] * t.r[1] + t.r[2] * t.r[2];
    for (int i = 0; i < 3; ++i)
        t.J[i] += t.mass * (rr - t.r[i] * t.r[i]); /* r along a principal axis */
    return t;
}

static const double TOP_OMEGA0[3] = {0.0, 150.0, -4.61538};

/* L(p), 3 x 4, row-major: omega' = 2 L(p) p' */
static inline void top_L(const double *p, double L[3][4])
{
    const double e0 = p[0], e1 = p[1], e2 = p[2], e3 = p[3];
    const double rows[3][4] = {{-e1, e0, e3, -e2}, {-e2, -e3, e0, e1}, {-e3, e2, -e1, e0}};
    memcpy(L, rows, sizeof rows);
}

/* A(p): body to inertial, row-major */
static inline void top_A(const double *p, double A[3][3])
{
    const double e0 = p[0], e1 = p[1], e2 = p[2], e3 = p[3];
    A[0][0] = 2 * (e0 * e0 + e1 * e1) - 1, A[0][1] = 2 * (e1 * e2 - e0 * e3),
    A[0][2] = 2 * (e1 * e3 + e0 * e2);
    A[1][0] = 2 * (e1 * e2 + e0 * e3), A[1][1] = 2 * (e0 * e0 + e2 * e2) - 1,
    A[1][2] = 2 * (e2 * e3 - e0 * e1);
    A[2][0] = 2 * (e1 * e3 - e0 * e2), A[2][1] = 2 * (e2 * e3 + e0 * e1),
    A[2][2] = 2 * (e0 * e0 + e3 * e3) - 1;
}

static inline void top_cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* n' = r x (A^T F), F = (0, 0, -m g) */
static inline void top_moment(const heavy_top *t, const double *p, double *n)
{
    double A[3][3], Fb[3];
    top_A(p, A);
    for (int i = 0; i < 3; ++i)
        Fb[i] = -t->mass * t->gravity * A[2][i];
    top_cross(t->r, Fb, n);
}

static inline int top_mass(double time, const double *q, double *M, void *user)
{
    const heavy_top *t = (const heavy_top *)user;
    double L[3][4];
    (void)time;
    top_L(q, L);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k)
                s += L[k][i] * t->J[k] * L[k][j];
            M[i + 4 * j] = 4.0 * s;
        }
    return 0;
}

static inline int top_force(double time, const double *q, const double *v, double *f, void *user)
{
    const heavy_top *t = (const heavy_top *)user;
    double L[3][4], Ld[3][4], n[3], Jw[3];
    (void)time;
    top_L(q, L);
    top_L(v, Ld);
    top_moment(t, q, n);
    for (int k = 0; k < 3; ++k) {
        double w = 0.0;
        for (int j = 0; j < 4; ++j)
            w += L[k][j] * v[j];
        Jw[k] = t->J[k] * w; /* J L p' = J omega' / 2 */
    }
    for (int i = 0; i < 4; ++i) {
        double s = 0.0;
        for (int k = 0; k < 3; ++k)
            s += 2.0 * L[k][i] * n[k] - 8.0 * Ld[k][i] * Jw[k];
        f[i] = s;
    }
    return 0;
}

static inline int top_constraint(double time, const double *q, double *phi, void *user)
{
    (void)time, (void)user;
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1.0);
    return 0;
}

static inline int top_jacobian(double time, const double *q, double *Phi_q, void *user)
{
    (void)time, (void)user;
    memcpy(Phi_q, q, 4 * sizeof *q);
    return 0;
}

static inline int top_constraint_accel(double time, const double *q, const double *v,
                                       double *out, void *user)
{
    (void)time, (void)q, (void)user;
    out[0] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3];
    return 0;
}

/* omega' = 2 L(p) p' */
static inline void top_omega(const double *p, const double *pd, double *w)
{
    double L[3][4];
    top_L(p, L);
    for (int k = 0; k < 3; ++k) {
        w[k] = 0.0;
        for (int j = 0; j < 4; ++j)
            w[k] += 2.0 * L[k][j] * pd[j];
    }
}

static inline double top_energy(const heavy_top *t, const double *p, const double *pd)
{
    double w[3], A[3][3];
    top_omega(p, pd, w);
    top_A(p, A);
    double e = 0.0;
    for (int k = 0; k < 3; ++k)
        e += 0.5 * t->J[k] * w[k] * w[k] + t->mass * t->gravity * A[2][k] * t->r[k];
    return e;
}

/* p = (1, 0, 0, 0), p' = L^T omega' / 2 */
static inline void top_initial(double *p, double *pd)
{
    const double p0[4] = {1.0, 0.0, 0.0, 0.0};
    double L[3][4];
    memcpy(p, p0, sizeof p0);
    top_L(p, L);
    for (int j = 0; j < 4; ++j) {
        pd[j] = 0.0;
        for (int k = 0; k < 3; ++k)
            pd[j] += 0.5 * L[k][j] * TOP_OMEGA0[k];
    }
}

/* The centre of mass in the inertial frame, A(p) r */
static inline void top_centre(const heavy_top *t, const double *p, double *x)
{
    double A[3][3];
    top_A(p, A);
    for (int i = 0; i < 3; ++i)
        x[i] = A[i][0] * t->r[0] + A[i][1] * t->r[1] + A[i][2] * t->r[2];
}

/* Independent reference: classical RK4 on Euler's equations in the body frame,
 * J omega'' = -omega' x J omega' + n', with p' = L(p)^T omega' / 2 (an ODE in (p, omega'),
 * no constraint, no mass matrix), p renormalized after each step. */
static inline void top_rk4_rates(const heavy_top *t, const double *x, double *dx)
{
    const double *p = x, *w = x + 4;
    double L[3][4], n[3], Jw[3], wJw[3];
    top_L(p, L);
    for (int j = 0; j < 4; ++j) {
        dx[j] = 0.0;
        for (int k = 0; k < 3; ++k)
            dx[j] += 0.5 * L[k][j] * w[k];
    }
    top_moment(t, p, n);
    for (int k = 0; k < 3; ++k)
        Jw[k] = t->J[k] * w[k];
    top_cross(w, Jw, wJw);
    for (int k = 0; k < 3; ++k)
        dx[4 + k] = (n[k] - wJw[k]) / t->J[k];
}

static inline void top_reference(const heavy_top *t, double t_end, long steps, double *p_end)
{
    double x[7], k1[7], k2[7], k3[7], k4[7], y[7];
    const double h = t_end / (double)steps;
    double pd[4];
    top_initial(x, pd);
    memcpy(x + 4, TOP_OMEGA0, 3 * sizeof(double));
    for (long s = 0; s < steps; ++s) {
        top_rk4_rates(t, x, k1);
        for (int i = 0; i < 7; ++i) y[i] = x[i] + 0.5 * h * k1[i];
        top_rk4_rates(t, y, k2);
        for (int i = 0; i < 7; ++i) y[i] = x[i] + 0.5 * h * k2[i];
        top_rk4_rates(t, y, k3);
        for (int i = 0; i < 7; ++i) y[i] = x[i] + h * k3[i];
        top_rk4_rates(t, y, k4);
        for (int i = 0; i < 7; ++i) x[i] += h / 6.0 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
        const double norm = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3]);
        for (int i = 0; i < 4; ++i) x[i] /= norm;
    }
    memcpy(p_end, x, 4 * sizeof(double));
}

#endif
