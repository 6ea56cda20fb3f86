/* An independent reference integrator for the scenes: classical RK4 on the index-1 form
 *     [M Phi_q^T; Phi_q 0] [qdd; lambda] = [f; -(Phi_qq(v, v) + ...)],   q' = v, v' = qdd,
 * with its own dense Gaussian elimination. It shares nothing with galpha but the model
 * callbacks, so tests and studies can use it as an oracle (with a step far below galpha's). */
#ifndef GALPHA_SCENE_INDEX1_RK4_H
#define GALPHA_SCENE_INDEX1_RK4_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rk4_model {
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_jacobian_fn jacobian;
    ga_constraint_accel_fn accel; /* required: the exact constraint acceleration term */
    void *user;
} rk4_model;

/* First-order states y' = rate(t, q, v, y) (r of them), with force_y replacing the model's
 * force; the user pointer is the model's. */
typedef struct rk4_first_order {
    int r;
    ga_force_y_fn force_y;
    ga_rate_fn rate;
} rk4_first_order;

/* Integrates from (t0, q, v) over `steps` steps to t_end; q and v are updated in place;
 * qdd (n) and lambda (m) receive the values at t_end (either may be NULL). Returns 0, or -1
 * if the saddle-point matrix was singular or a callback failed. */
int index1_rk4(const rk4_model *model, double t0, double t_end, long steps, double *q, double *v,
               double *qdd, double *lambda);
/* The same with first-order states: y (r) integrated with q and v, updated in place; ydot (r)
 * receives y' at t_end (may be NULL). */
int index1_rk4_y(const rk4_model *model, const rk4_first_order *states, double t0, double t_end,
                 long steps, double *q, double *v, double *y, double *qdd, double *lambda,
                 double *ydot);

#ifdef __cplusplus
}
#endif

#endif
