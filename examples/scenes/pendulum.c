#include "pendulum.h"

#include <math.h>

int pendulum_mass(double t, const double *q, double *M, void *user)
{
    const pendulum *p = (const pendulum *)user;
    (void)t;
    (void)q;
    M[0] = p->mass;
    M[1] = 0.0;
    M[2] = 0.0;
    M[3] = p->mass;
    return 0;
}

int pendulum_force(double t, const double *q, const double *v, double *f, void *user)
{
    const pendulum *p = (const pendulum *)user;
    (void)t;
    (void)q;
    (void)v;
    f[0] = 0.0;
    f[1] = -p->mass * p->gravity;
    return 0;
}

int pendulum_constraint(double t, const double *q, double *phi, void *user)
{
    const pendulum *p = (const pendulum *)user;
    (void)t;
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p->length * p->length);
    return 0;
}

int pendulum_jacobian(double t, const double *q, double *Phi_q, void *user)
{
    (void)t;
    (void)user;
    Phi_q[0] = q[0]; /* 1 x 2, column-major */
    Phi_q[1] = q[1];
    return 0;
}

/* K_t = d(M qdd - f + Phi_q^T lambda)/dq = lambda I (M and f do not depend on q). */
int pendulum_stiffness(double t, const double *q, const double *v, const double *qdd,
                       const double *lambda, double *K, void *user)
{
    (void)t;
    (void)q;
    (void)v;
    (void)qdd;
    (void)user;
    K[0] = lambda[0];
    K[1] = 0.0;
    K[2] = 0.0;
    K[3] = lambda[0];
    return 0;
}

/* Phi_qq(v, v) = |v|^2; no explicit time dependence. */
int pendulum_constraint_accel(double t, const double *q, const double *v, double *out,
                              void *user)
{
    (void)t;
    (void)q;
    (void)user;
    out[0] = v[0] * v[0] + v[1] * v[1];
    return 0;
}

void pendulum_state(const pendulum *p, double theta, double omega, double *q, double *v)
{
    q[0] = p->length * sin(theta);
    q[1] = -p->length * cos(theta);
    v[0] = p->length * omega * cos(theta);
    v[1] = p->length * omega * sin(theta);
}
