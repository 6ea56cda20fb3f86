/* A linear electromechanical model with first-order states and an exact solution, shared by
 * the suites (test_first_order.c, test_alloc.c, test_alloc_failures.c). */
#ifndef GALPHA_TEST_ELECTROMECH_H
#define GALPHA_TEST_ELECTROMECH_H

#include <math.h>
#include <string.h>

#include <galpha.h>

/* ---- a linear electromechanical model with an exact solution ----
 * Two masses joined rigidly (Phi = x1 - x2 = 0, lambda the force in the joint); a spring and a
 * damper on mass 1, a DC motor's force Kt i on mass 2; the motor's current i and a PI
 * controller's integral z as first-order states:
 *     m1 x1'' = -k x1 - c v1 - lambda,   m2 x2'' = Kt i + lambda,
 *     L i' = u - R i - Ke v2,   u = -Kp (x2 - xr) - Ki z,   z' = x2 - xr.
 * Reduced to (x, v, i, z) it is Z' = A Z + b, solved exactly by the exponential of the
 * augmented matrix [A b; 0 0] (scaling and squaring of its Taylor series, below). */
enum { EM_N = 2, EM_M = 1, EM_R = 2 };
static const double m1 = 1.0, m2 = 0.5, k_s = 20.0, c_d = 0.5, Kt = 2.0, L_i = 0.05, R_i = 1.0,
                    Ke = 2.0, Kp = 30.0, Ki = 40.0, xr = 1.0;

static inline int em_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = m1, M[1] = 0.0, M[2] = 0.0, M[3] = m2;
    return 0;
}
static inline int em_force(double t, const double *q, const double *v, const double *y, double *f,
                    void *u)
{
    (void)t, (void)u;
    f[0] = -k_s * q[0] - c_d * v[0];
    f[1] = Kt * y[0];
    return 0;
}
static inline int em_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                   void *u)
{
    (void)t, (void)u;
    const double volt = -Kp * (q[1] - xr) - Ki * y[1];
    ydot[0] = (volt - R_i * y[0] - Ke * v[1]) / L_i;
    ydot[1] = q[1] - xr;
    return 0;
}
static inline int em_constraint(double t, const double *q, double *phi, void *u)
{
    (void)t, (void)u;
    phi[0] = q[0] - q[1];
    return 0;
}
static inline int em_jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    J[0] = 1.0, J[1] = -1.0;
    return 0;
}
static inline int em_coupling(double t, const double *q, const double *v, const double *y,
                       double *g_q, double *g_v, double *g_y, double *f_y, void *u)
{
    (void)t, (void)q, (void)v, (void)y, (void)u;
    /* g_q, g_v: 2 x 2 column-major (rows i, z); g_y 2 x 2; f_y 2 x 2 */
    g_q[0] = 0.0, g_q[1] = 0.0, g_q[2] = -Kp / L_i, g_q[3] = 1.0;
    g_v[0] = 0.0, g_v[1] = 0.0, g_v[2] = -Ke / L_i, g_v[3] = 0.0;
    g_y[0] = -R_i / L_i, g_y[1] = 0.0, g_y[2] = -Ki / L_i, g_y[3] = 0.0;
    f_y[0] = 0.0, f_y[1] = Kt, f_y[2] = 0.0, f_y[3] = 0.0;
    return 0;
}

/* The same model on the sparse path: M's diagonal and Phi_q's two entries as pattern values,
 * K_t and C_t each the one entry (0, 0) (the spring and the damper on mass 1). */
static inline int em_mass_diag(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = m1, M[1] = m2;
    return 0;
}
static inline int em_jacobian_values(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    J[0] = 1.0, J[1] = -1.0;
    return 0;
}
static inline ga_status em_declare_sparse(ga_solver *s)
{
    static const int diag[2] = {0, 1}, j_rows[2] = {0, 0}, j_cols[2] = {0, 1}, k0[1] = {0};
    ga_status st = ga_set_pattern(s, GA_MATRIX_MASS, 2, diag, diag);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_JACOBIAN, 2, j_rows, j_cols);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_STIFFNESS, 1, k0, k0);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_DAMPING, 1, k0, k0);
    if (!st)
        st = ga_set_linear_solver(s, GA_LINEAR_SPARSE);
    return st;
}

/* exp(T A5) for the 5 x 5 augmented matrix, by scaling and squaring of the Taylor series. */
static inline void expm5(const double A[5][5], double T, double E[5][5])
{
    double norm = 0.0;
    for (int i = 0; i < 5; ++i) {
        double row = 0.0;
        for (int j = 0; j < 5; ++j)
            row += fabs(A[i][j] * T);
        norm = fmax(norm, row);
    }
    int squarings = 0;
    while (norm > 0.05) {
        norm *= 0.5;
        ++squarings;
    }
    const double scale = T / ldexp(1.0, squarings);
    double term[5][5], next[5][5];
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j)
            E[i][j] = term[i][j] = i == j ? 1.0 : 0.0;
    for (int k = 1; k <= 18; ++k) {
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j) {
                double acc = 0.0;
                for (int l = 0; l < 5; ++l)
                    acc += term[i][l] * A[l][j] * scale;
                next[i][j] = acc / k;
            }
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j) {
                term[i][j] = next[i][j];
                E[i][j] += term[i][j];
            }
    }
    for (int s = 0; s < squarings; ++s) {
        for (int i = 0; i < 5; ++i)
            for (int j = 0; j < 5; ++j) {
                double acc = 0.0;
                for (int l = 0; l < 5; ++l)
                    acc += E[i][l] * E[l][j];
                next[i][j] = acc;
            }
        memcpy(E, next, sizeof next);
    }
}

/* The exact (x, v, i, z) at T from rest, and the derived exact qdd, lambda, i', z'. */
typedef struct em_exact {
    double x, v, i, z, a, lambda, idot, zdot;
} em_exact;

static inline em_exact em_reference(double T)
{
    const double mt = m1 + m2;
    const double A[5][5] = {
        {0, 1, 0, 0, 0},
        {-k_s / mt, -c_d / mt, Kt / mt, 0, 0},
        {-Kp / L_i, -Ke / L_i, -R_i / L_i, -Ki / L_i, Kp * xr / L_i},
        {1, 0, 0, 0, -xr},
        {0, 0, 0, 0, 0}};
    double E[5][5];
    expm5(A, T, E);
    em_exact e;
    /* Z(0) = (0, 0, 0, 0) and the constant 1 in the fifth slot */
    e.x = E[0][4], e.v = E[1][4], e.i = E[2][4], e.z = E[3][4];
    e.a = (-k_s * e.x - c_d * e.v + Kt * e.i) / mt;
    e.lambda = -k_s * e.x - c_d * e.v - m1 * e.a;
    e.idot = (-Kp * (e.x - xr) - Ki * e.z - R_i * e.i - Ke * e.v) / L_i;
    e.zdot = e.x - xr;
    return e;
}

#endif
