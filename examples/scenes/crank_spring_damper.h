/* The slider-crank of SUNDIALS' IDAS forward-sensitivity example (idasSlCrank_FSA_dns), in its
 * 3 generalized coordinates q = (theta, x, phi): crank angle, slider position, connecting-rod
 * angle. A crank of length 2a turns about the origin; the rod of length 1 joins the crank's
 * end to the slider, so that
 *     Phi = (x - cos phi - a cos theta, -sin phi - a sin theta) = 0.
 * M = diag(J1, m2, J2). A spring-damper of stiffness k and damping c (rest length l0) joins
 * the crank's and the rod's midpoints, at distance l, with
 *     l^2 = x^2 - x (cos phi + a cos theta) + (1 + a^2) / 4 + (a / 2) cos(phi - theta),
 * and a constant horizontal force F acts on the rod: Q = -f dl/dq + F (0, 1, -sin phi),
 * f = k (l - l0) + c dl/dt. Data: a = 1/2, J1 = 1, m2 = 1, J2 = 2, l0 = 1, F = 1, k = c = 1;
 * start at theta = pi/2, phi = asin(-a), x = cos phi, at rest. IDAS computes the sensitivities
 * of G = int_0^10 of the kinetic energy (J1 theta'^2 + m2 x'^2 + J2 phi'^2) / 2 in k and c. */
#ifndef GALPHA_SCENE_CRANK_SPRING_DAMPER_H
#define GALPHA_SCENE_CRANK_SPRING_DAMPER_H

#ifdef __cplusplus
extern "C" {
#endif

enum { CSD_N = 3, CSD_M = 2 };

typedef struct crank_spring_damper {
    double a, J1, m2, J2, l0, F;
    double p[2]; /* k, c: the parameters of the sensitivity example */
} crank_spring_damper;

crank_spring_damper crank_spring_damper_idas(void);
void csd_initial(const crank_spring_damper *c, double *q, double *v);

int csd_mass(double t, const double *q, double *M, void *user);
int csd_force(double t, const double *q, const double *v, double *f, void *user);
int csd_constraint(double t, const double *q, double *phi, void *user);
int csd_jacobian(double t, const double *q, double *J, void *user);
int csd_constraint_accel(double t, const double *q, const double *v, double *out, void *user);
/* the kinetic energy and its gradient in v (M v) */
double csd_kinetic_energy(const crank_spring_damper *c, const double *v, double *grad);

#ifdef __cplusplus
}
#endif

#endif
