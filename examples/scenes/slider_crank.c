#include "slider_crank.h"

#include <math.h>
#include <string.h>

slider_crank slider_crank_paper(void)
{
    slider_crank p = {1000.0, 0.3, 0.6, 0.36, 0.15, 0.1, 0.7, 1.0, 0.3};
    return p;
}

int sc_mass(double t, const double *q, double *M, void *user)
{
    const slider_crank *p = user;
    const double diag[SC_N] = {p->m1, p->m1, p->m2, p->m2, p->m1 * p->l1 * p->l1 / 12.0,
                               p->m2 * p->l2 * p->l2 / 12.0, p->m3, p->m4, 0.0, 0.0};
    (void)t, (void)q;
    memset(M, 0, sizeof(double) * SC_N * SC_N);
    for (int i = 0; i < SC_N; ++i)
        M[i + SC_N * i] = diag[i];
    return 0;
}

int sc_force(double t, const double *q, const double *v, double *f, void *user)
{
    const slider_crank *p = user;
    const double spring = p->k * (q[SC_X4] - q[SC_X3] - p->rest_length);
    (void)t, (void)v;
    memset(f, 0, sizeof(double) * SC_N);
    f[SC_TH1] = p->torque;
    f[SC_X3] = spring; /* a stretched spring pulls the slider towards mass 4 ... */
    f[SC_X4] = -spring; /* ... and mass 4 back */
    return 0;
}

/* Rows: crank centre of mass (2), crank end = hinge (2), rod centre of mass (2),
 * rod end = slider on the x axis (2). */
int sc_constraint(double t, const double *q, double *phi, void *user)
{
    const slider_crank *p = user;
    const double c1 = cos(q[SC_TH1]), s1 = sin(q[SC_TH1]);
    const double c2 = cos(q[SC_TH2]), s2 = sin(q[SC_TH2]);
    (void)t;
    phi[0] = q[SC_X1] - 0.5 * p->l1 * c1;
    phi[1] = q[SC_Y1] - 0.5 * p->l1 * s1;
    phi[2] = q[SC_X5] - p->l1 * c1;
    phi[3] = q[SC_Y5] - p->l1 * s1;
    phi[4] = q[SC_X2] - q[SC_X5] - 0.5 * p->l2 * c2;
    phi[5] = q[SC_Y2] - q[SC_Y5] - 0.5 * p->l2 * s2;
    phi[6] = q[SC_X3] - q[SC_X5] - p->l2 * c2;
    phi[7] = q[SC_Y5] + p->l2 * s2;
    return 0;
}

#define J(i, j) Phi_q[(i) + SC_M * (j)]
int sc_jacobian(double t, const double *q, double *Phi_q, void *user)
{
    const slider_crank *p = user;
    const double c1 = cos(q[SC_TH1]), s1 = sin(q[SC_TH1]);
    const double c2 = cos(q[SC_TH2]), s2 = sin(q[SC_TH2]);
    (void)t;
    memset(Phi_q, 0, sizeof(double) * SC_M * SC_N);
    J(0, SC_X1) = 1.0;
    J(0, SC_TH1) = 0.5 * p->l1 * s1;
    J(1, SC_Y1) = 1.0;
    J(1, SC_TH1) = -0.5 * p->l1 * c1;
    J(2, SC_X5) = 1.0;
    J(2, SC_TH1) = p->l1 * s1;
    J(3, SC_Y5) = 1.0;
    J(3, SC_TH1) = -p->l1 * c1;
    J(4, SC_X2) = 1.0;
    J(4, SC_X5) = -1.0;
    J(4, SC_TH2) = 0.5 * p->l2 * s2;
    J(5, SC_Y2) = 1.0;
    J(5, SC_Y5) = -1.0;
    J(5, SC_TH2) = -0.5 * p->l2 * c2;
    J(6, SC_X3) = 1.0;
    J(6, SC_X5) = -1.0;
    J(6, SC_TH2) = p->l2 * s2;
    J(7, SC_Y5) = 1.0;
    J(7, SC_TH2) = p->l2 * c2;
    return 0;
}
#undef J

/* Phi_qq(v, v): each -c cos(th) term gives +c cos(th) th'^2, each -c sin(th) term +c sin(th)
 * th'^2, and +c sin(th) gives -c sin(th) th'^2. */
int sc_constraint_accel(double t, const double *q, const double *v, double *out, void *user)
{
    const slider_crank *p = user;
    const double c1 = cos(q[SC_TH1]), s1 = sin(q[SC_TH1]);
    const double c2 = cos(q[SC_TH2]), s2 = sin(q[SC_TH2]);
    const double w1 = v[SC_TH1] * v[SC_TH1], w2 = v[SC_TH2] * v[SC_TH2];
    (void)t;
    out[0] = 0.5 * p->l1 * c1 * w1;
    out[1] = 0.5 * p->l1 * s1 * w1;
    out[2] = p->l1 * c1 * w1;
    out[3] = p->l1 * s1 * w1;
    out[4] = 0.5 * p->l2 * c2 * w2;
    out[5] = 0.5 * p->l2 * s2 * w2;
    out[6] = p->l2 * c2 * w2;
    out[7] = -p->l2 * s2 * w2;
    return 0;
}

/* K_t = d(Phi_q^T lambda)/dq - df/dq: the constraint rows depend on theta1 and theta2 only,
 * and the spring couples x3 and x4. */
int sc_stiffness(double t, const double *q, const double *v, const double *qdd,
                 const double *lambda, double *K, void *user)
{
    const slider_crank *p = user;
    const double c1 = cos(q[SC_TH1]), s1 = sin(q[SC_TH1]);
    const double c2 = cos(q[SC_TH2]), s2 = sin(q[SC_TH2]);
    const double *l = lambda;
    (void)t, (void)v, (void)qdd;
    memset(K, 0, sizeof(double) * SC_N * SC_N);
    /* d/dtheta1 of sum_i lambda_i dPhi_i/dtheta1 */
    K[SC_TH1 + SC_N * SC_TH1] = 0.5 * p->l1 * c1 * l[0] + 0.5 * p->l1 * s1 * l[1] +
                                p->l1 * c1 * l[2] + p->l1 * s1 * l[3];
    K[SC_TH2 + SC_N * SC_TH2] = 0.5 * p->l2 * c2 * l[4] + 0.5 * p->l2 * s2 * l[5] +
                                p->l2 * c2 * l[6] - p->l2 * s2 * l[7];
    /* -df/dq of the spring */
    K[SC_X3 + SC_N * SC_X3] = p->k;
    K[SC_X3 + SC_N * SC_X4] = -p->k;
    K[SC_X4 + SC_N * SC_X3] = -p->k;
    K[SC_X4 + SC_N * SC_X4] = p->k;
    return 0;
}

void sc_initial(const slider_crank *p, double theta1, double *q, double *v)
{
    const double x5 = p->l1 * cos(theta1), y5 = p->l1 * sin(theta1);
    const double theta2 = asin(-y5 / p->l2); /* rod end on y = 0, slider to the right */
    memset(q, 0, sizeof(double) * SC_N);
    memset(v, 0, sizeof(double) * SC_N);
    q[SC_X1] = 0.5 * x5;
    q[SC_Y1] = 0.5 * y5;
    q[SC_TH1] = theta1;
    q[SC_TH2] = theta2;
    q[SC_X5] = x5;
    q[SC_Y5] = y5;
    q[SC_X2] = x5 + 0.5 * p->l2 * cos(theta2);
    q[SC_Y2] = y5 + 0.5 * p->l2 * sin(theta2);
    q[SC_X3] = x5 + p->l2 * cos(theta2);
    q[SC_X4] = q[SC_X3] + p->rest_length;
}

int sc_constraint_dt(double t, const double *q, double *out, void *user)
{
    (void)t, (void)q, (void)user;
    memset(out, 0, sizeof(double) * SC_M);
    return 0;
}
