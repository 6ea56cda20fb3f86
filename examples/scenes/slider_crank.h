/* Slider-crank with a spring-mass system on the slider (Arnold & Bruls 2007, sec. 5.1), in the
 * paper's 10 absolute coordinates
 *     q = (x1, y1, x2, y2, theta1, theta2, x3, x4, x5, y5)
 * and 8 nonlinear constraints. Body 1 is the crank (pinned at the origin), body 2 the
 * connecting rod, body 3 the slider on the x axis, body 4 the additional mass, tied to the
 * slider by a spring along x; (x5, y5) is the massless hinge node between crank and rod, so
 * M is singular while [M Phi_q^T; Phi_q 0] is regular.
 *
 * Data of the paper: k = 1000 N/m, l1 = 0.3 m, l2 = 0.6 m, m1 = 0.36, m2 = 0.15, m3 = 0.1,
 * m4 = 0.7 kg, torque T = 1 N m on the crank, no gravity. Not given there, chosen here:
 * slender-bar inertias m l^2 / 12 about the centres of mass, which sit at mid-length; spring
 * rest length 0.3 m (undeformed at t = 0: x4(0) = x3(0) + 0.3); mass 4 moves along x only.
 * Initial state: theta1 = pi/2, at rest. */
#ifndef GALPHA_SCENE_SLIDER_CRANK_H
#define GALPHA_SCENE_SLIDER_CRANK_H

#ifdef __cplusplus
extern "C" {
#endif

enum { SC_N = 10, SC_M = 8 };
enum { SC_X1, SC_Y1, SC_X2, SC_Y2, SC_TH1, SC_TH2, SC_X3, SC_X4, SC_X5, SC_Y5 };

typedef struct slider_crank {
    double k, l1, l2, m1, m2, m3, m4, torque, rest_length;
} slider_crank;

/* The paper's data. */
slider_crank slider_crank_paper(void);

int sc_mass(double t, const double *q, double *M, void *user);
int sc_force(double t, const double *q, const double *v, double *f, void *user);
int sc_constraint(double t, const double *q, double *phi, void *user);
int sc_jacobian(double t, const double *q, double *Phi_q, void *user);
int sc_constraint_accel(double t, const double *q, const double *v, double *out, void *user);
/* Phi_t = 0: no driving constraint */
int sc_constraint_dt(double t, const double *q, double *out, void *user);
/* K_t = d(Phi_q^T lambda)/dq - df/dq (M is constant); C_t = 0 (f does not depend on v). */
int sc_stiffness(double t, const double *q, const double *v, const double *qdd,
                 const double *lambda, double *K, void *user);

/* Consistent positions for crank angle theta1 (rod below the crank hinge, slider at x > 0),
 * at rest. */
void sc_initial(const slider_crank *p, double theta1, double *q, double *v);

#ifdef __cplusplus
}
#endif

#endif
