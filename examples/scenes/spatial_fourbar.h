/* A spatial closed loop: the RSSR four-bar (crank, coupler, rocker), each rod a body on
 * R^3 x SO(3) (ga_create_space; per body its centre of mass in space and its attitude as a
 * unit quaternion in q, x' and the body angular velocity in v). The crank turns about the
 * space z axis through the origin (a revolute joint: 3 + 2 constraints), the rocker about the
 * space x axis through D (3 + 2), the coupler joins their ends by two spherical joints (3 + 3):
 * 18 velocities, 16 constraints, and two degrees of freedom -- the crank angle and the
 * coupler's spin about its own axis, which the joints leave free and which stays zero when it
 * starts so (the coupler is axisymmetric and every force on it acts on its axis). So the motion
 * under gravity is that of one coordinate, the crank angle theta, with energy
 * E = m(theta) theta'^2 / 2 + V(theta): the reference of tests/c/test_spatial_fourbar.c.
 *
 * Rods: their axis the body z axis, ends at (0, 0, -+L/2), radius 0.02; a revolute joint's axis
 * is the rod's body y axis. Crank L 0.2, mass 1; coupler 0.6, 2; rocker 0.4, 1.5;
 * D = (0.25, 0.1, 0.3); gravity (0, 0, -9.81). The crank's tip is B = L1 (cos theta,
 * sin theta, 0), the rocker's C = D + L3 (0, cos phi, sin phi), |B - C| = L2 (the rocker's
 * branch below its pivot, phi in (-59, 34) degrees: the loop is far from a dead point). */
#ifndef GALPHA_SCENE_SPATIAL_FOURBAR_H
#define GALPHA_SCENE_SPATIAL_FOURBAR_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { FOURBAR_BODIES = 3, FOURBAR_NQ = 21, FOURBAR_NV = 18, FOURBAR_M = 16, FOURBAR_BLOCKS = 6 };

typedef struct spatial_fourbar {
    double length[3], mass[3], inertia[3][3]; /* crank, coupler, rocker; inertia about the com */
    double pivot[3];                          /* D, the rocker's joint */
    double gravity;                           /* along -z */
} spatial_fourbar;

spatial_fourbar spatial_fourbar_make(void);
/* The space: per body a vector block of 3 and one quaternion */
void spatial_fourbar_blocks(int *kinds, int *counts);
/* The rocker's angle phi closing the loop at crank angle theta (closed form), and
 * dphi/dtheta */
double spatial_fourbar_rocker_angle(const spatial_fourbar *f, double theta, double *dphi);
/* q (21) and v (18) on the loop at crank angle theta, crank rate theta_dot, no coupler spin */
void spatial_fourbar_initial(const spatial_fourbar *f, double theta, double theta_dot, double *q,
                             double *v);
/* The crank's angle in (-pi, pi] from q */
double spatial_fourbar_crank_angle(const double *q);
/* Kinetic plus potential energy */
double spatial_fourbar_energy(const spatial_fourbar *f, const double *q, const double *v);

int spatial_fourbar_mass(double t, const double *q, double *M, void *user);
int spatial_fourbar_force(double t, const double *q, const double *v, double *out, void *user);
int spatial_fourbar_constraint(double t, const double *q, double *phi, void *user);
int spatial_fourbar_jacobian(double t, const double *q, double *J, void *user);
int spatial_fourbar_constraint_dt(double t, const double *q, double *phi_t, void *user);

#ifdef __cplusplus
}
#endif

#endif
