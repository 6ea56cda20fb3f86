/* Planar pendulum in Cartesian coordinates: the smallest constrained scene.
 * q = (x, y), one constraint Phi = (x^2 + y^2 - L^2)/2, M = m I, f = (0, -m g).
 * With this Phi, lambda = m (|v|^2 - g y) / L^2: the rod tension divided by L. */
#ifndef GALPHA_SCENE_PENDULUM_H
#define GALPHA_SCENE_PENDULUM_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pendulum {
    double mass;    /* kg */
    double length;  /* m */
    double gravity; /* m/s^2 */
} pendulum;

int pendulum_mass(double t, const double *q, double *M, void *user);
int pendulum_force(double t, const double *q, const double *v, double *f, void *user);
int pendulum_constraint(double t, const double *q, double *phi, void *user);
int pendulum_jacobian(double t, const double *q, double *Phi_q, void *user);
int pendulum_stiffness(double t, const double *q, const double *v, const double *qdd,
                       const double *lambda, double *K, void *user);
int pendulum_constraint_accel(double t, const double *q, const double *v, double *out,
                              void *user);

/* Cartesian state from the angle theta (from the downward vertical) and its rate. */
void pendulum_state(const pendulum *p, double theta, double omega, double *q, double *v);

#ifdef __cplusplus
}
#endif

#endif
