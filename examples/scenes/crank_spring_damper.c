#include "crank_spring_damper.h"

#include <math.h>
#include <string.h>

crank_spring_damper crank_spring_damper_idas(void)
{
    crank_spring_damper c = {0.5, 1.0, 1.0, 2.0, 1.0, 1.0, {1.0, 1.0}};
    return c;
}

void csd_initial(const crank_spring_damper *c, double *q, double *v)
{
    const double phi = asin(-c->a);
    q[0] = 2.0 * atan(1.0);
    q[1] = cos(phi);
    q[2] = phi;
    v[0] = v[1] = v[2] = 0.0;
}

int csd_mass(double t, const double *q, double *M, void *user)
{
    const crank_spring_damper *c = user;
    (void)t, (void)q;
    memset(M, 0, sizeof(double) * CSD_N * CSD_N);
    M[0] = c->J1;
    M[4] = c->m2;
    M[8] = c->J2;
    return 0;
}

int csd_force(double t, const double *q, const double *v, double *f, void *user)
{
    const crank_spring_damper *c = user;
    const double a = c->a, th = q[0], x = q[1], ph = q[2];
    (void)t;
    /* l^2 and its gradient in q */
    const double l2 = x * x - x * (cos(ph) + a * cos(th)) + 0.25 * (1.0 + a * a) +
                      0.5 * a * cos(ph - th);
    const double g[3] = {a * x * sin(th) + 0.5 * a * sin(ph - th),
                         2.0 * x - cos(ph) - a * cos(th),
                         x * sin(ph) - 0.5 * a * sin(ph - th)};
    const double l = sqrt(l2);
    const double ldot = (g[0] * v[0] + g[1] * v[1] + g[2] * v[2]) / (2.0 * l);
    const double tension = c->p[0] * (l - c->l0) + c->p[1] * ldot;
    for (int i = 0; i < 3; ++i)
        f[i] = -tension * g[i] / (2.0 * l); /* -f dl/dq */
    f[1] += c->F;
    f[2] -= c->F * sin(ph);
    return 0;
}

int csd_constraint(double t, const double *q, double *phi, void *user)
{
    const crank_spring_damper *c = user;
    (void)t;
    phi[0] = q[1] - cos(q[2]) - c->a * cos(q[0]);
    phi[1] = -sin(q[2]) - c->a * sin(q[0]);
    return 0;
}

int csd_jacobian(double t, const double *q, double *J, void *user)
{
    const crank_spring_damper *c = user;
    (void)t;
    /* column-major 2 x 3 */
    J[0] = c->a * sin(q[0]);
    J[1] = -c->a * cos(q[0]);
    J[2] = 1.0;
    J[3] = 0.0;
    J[4] = sin(q[2]);
    J[5] = -cos(q[2]);
    return 0;
}

int csd_constraint_accel(double t, const double *q, const double *v, double *out, void *user)
{
    const crank_spring_damper *c = user;
    (void)t;
    out[0] = c->a * cos(q[0]) * v[0] * v[0] + cos(q[2]) * v[2] * v[2];
    out[1] = c->a * sin(q[0]) * v[0] * v[0] + sin(q[2]) * v[2] * v[2];
    return 0;
}

double csd_kinetic_energy(const crank_spring_damper *c, const double *v, double *grad)
{
    const double Mv[3] = {c->J1 * v[0], c->m2 * v[1], c->J2 * v[2]};
    if (grad)
        memcpy(grad, Mv, sizeof Mv);
    return 0.5 * (Mv[0] * v[0] + Mv[1] * v[1] + Mv[2] * v[2]);
}
