/* The slider-crank of slider_crank.h driven by a DC motor under a PI speed controller: the
 * motor current i and the controller's integral z are first-order states (galpha's
 * ga_set_first_order), y = (i, z):
 *     L i' = u - R i - Ke w,   u = Kp (w_ref(t) - w) + Ki z,   z' = w_ref(t) - w,
 * with w = theta1' the crank speed and the motor torque Kt i on the crank (no other torque).
 * The speed reference rises smoothly, w_ref(t) = w_final (1 - exp(-t / tau)), so the solution
 * is smooth and convergence orders can be measured on it. Data chosen here (no published
 * source): a small motor with gearing folded into Kt = Ke = 0.3 N m / A, R = 0.5 Ohm,
 * L = 2 mH (electrical time constant 4 ms, stiff against the mechanism's motion), Kp = 20 V s,
 * Ki = 50 V, w_final = 4 pi rad/s (2 revolutions per second), tau = 0.1 s. */
#ifndef GALPHA_SCENE_SLIDER_CRANK_MOTOR_H
#define GALPHA_SCENE_SLIDER_CRANK_MOTOR_H

#include <galpha.h>

#include "slider_crank.h"

#ifdef __cplusplus
extern "C" {
#endif

enum { SCM_R = 2, SCM_I = 0, SCM_Z = 1 };

typedef struct sc_motor {
    slider_crank crank; /* first: the slider-crank's callbacks take the same user pointer */
    double Kt, Ke, R, L, Kp, Ki, w_final, tau;
} sc_motor;

sc_motor sc_motor_default(void);
double scm_reference_speed(const sc_motor *p, double t);
/* f(t, q, v, y): the slider-crank's forces and the motor torque Kt i on theta1 */
int scm_force(double t, const double *q, const double *v, const double *y, double *f,
              void *user);
/* y' = (i', z') */
int scm_rate(double t, const double *q, const double *v, const double *y, double *ydot,
             void *user);
/* the exact coupling blocks g_q (0), g_v, g_y, f_y */
int scm_coupling(double t, const double *q, const double *v, const double *y, double *g_q,
                 double *g_v, double *g_y, double *f_y, void *user);
/* The scene on a new solver: the callbacks (user p), the constraint acceleration and Phi_t,
 * the two first-order states; the first failing status, or GA_OK. */
ga_status scm_declare(ga_solver *s, sc_motor *p);

#ifdef __cplusplus
}
#endif

#endif
