#include "slider_crank_motor.h"

#include <math.h>
#include <string.h>

sc_motor sc_motor_default(void)
{
    sc_motor p;
    p.crank = slider_crank_paper();
    p.crank.torque = 0.0; /* the motor drives it */
    p.Kt = 0.3, p.Ke = 0.3, p.R = 0.5, p.L = 2e-3;
    p.Kp = 20.0, p.Ki = 50.0;
    p.w_final = 4.0 * M_PI, p.tau = 0.1;
    return p;
}

double scm_reference_speed(const sc_motor *p, double t)
{
    return p->w_final * (1.0 - exp(-t / p->tau));
}

int scm_force(double t, const double *q, const double *v, const double *y, double *f,
              void *user)
{
    const sc_motor *p = user;
    const int rc = sc_force(t, q, v, f, user);
    f[SC_TH1] += p->Kt * y[SCM_I];
    return rc;
}

int scm_rate(double t, const double *q, const double *v, const double *y, double *ydot,
             void *user)
{
    const sc_motor *p = user;
    const double w = v[SC_TH1], error = scm_reference_speed(p, t) - w;
    const double u = p->Kp * error + p->Ki * y[SCM_Z];
    (void)q;
    ydot[SCM_I] = (u - p->R * y[SCM_I] - p->Ke * w) / p->L;
    ydot[SCM_Z] = error;
    return 0;
}

/* column-major: g_q, g_v are SCM_R x SC_N, g_y SCM_R x SCM_R, f_y SC_N x SCM_R */
int scm_coupling(double t, const double *q, const double *v, const double *y, double *g_q,
                 double *g_v, double *g_y, double *f_y, void *user)
{
    const sc_motor *p = user;
    (void)t, (void)q, (void)v, (void)y;
    memset(g_q, 0, sizeof(double) * SCM_R * SC_N);
    memset(g_v, 0, sizeof(double) * SCM_R * SC_N);
    memset(f_y, 0, sizeof(double) * SC_N * SCM_R);
    g_v[SCM_I + SCM_R * SC_TH1] = -(p->Kp + p->Ke) / p->L;
    g_v[SCM_Z + SCM_R * SC_TH1] = -1.0;
    g_y[SCM_I + SCM_R * SCM_I] = -p->R / p->L;
    g_y[SCM_I + SCM_R * SCM_Z] = p->Ki / p->L;
    g_y[SCM_Z + SCM_R * SCM_I] = 0.0;
    g_y[SCM_Z + SCM_R * SCM_Z] = 0.0;
    f_y[SC_TH1 + SC_N * SCM_I] = p->Kt;
    return 0;
}

ga_status scm_declare(ga_solver *s, sc_motor *p)
{
    ga_status st = ga_set_callbacks(s, sc_mass, NULL, sc_constraint, sc_jacobian, p);
    if (!st)
        st = ga_set_constraint_accel(s, sc_constraint_accel);
    if (!st)
        st = ga_set_constraint_dt(s, sc_constraint_dt);
    if (!st)
        st = ga_set_first_order(s, SCM_R, scm_force, scm_rate);
    return st;
}
