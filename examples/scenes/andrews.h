/* Andrews' squeezing mechanism (Schiehlen 1990; Hairer & Wanner; the Bari IVP Test Set
 * problem "andrews"): 7 rigid bodies in a plane, one degree of freedom, driven by a constant
 * torque, with one spring. Data: the Test Set (docs/references.md).
 *
 * Two models of the same motion:
 *  - andrews7:  the Test Set's 7 relative angles q = (beta, Theta, gamma, Phi, delta, Omega,
 *               epsilon), 6 loop-closure constraints, configuration-dependent M(q);
 *  - andrews31: the paper's absolute coordinates (sec. 5.2): per body (x, y) of the centre of
 *               mass and one rotation (7 x 3 = 21), plus (x, y) of the five moving points
 *               F, E, G, H and D (the spring's attachment) = 31 coordinates; 30 constraints,
 *               each "point = base point + R(theta) local vector"; constant, singular M.
 * Bodies: 1 OF (crank, at O), 2 FE, 3 triangle BDE (at B), 4 EG, 5 GA (at A), 6 HE, 7 AH (at
 * A). Absolute body angles from the relative ones: th1 = beta, th2 = beta + Theta,
 * th3 = gamma, th4 = Phi + delta, th5 = delta, th6 = Omega + epsilon, th7 = epsilon. */
#ifndef GALPHA_SCENE_ANDREWS_H
#define GALPHA_SCENE_ANDREWS_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

enum { AN7_N = 7, AN7_M = 6, AN31_N = 31, AN31_M = 30 };

/* Test Set initial values (t = 0, at rest) of the 7 angles, 30 digits as published. */
extern const double andrews_q0[7];
/* Test Set reference solution at t = 0.03 (PSIDE, rtol = atol = 1e-14): angles, good to about
 * 1e-10 relative (docs/references.md). */
extern const double andrews_q_ref[7];
/* Independent recomputation at t = 0.03 (docs/references.md: GBS extrapolation in long double):
 * velocities (~1e-11), accelerations and multipliers (~1e-11 between the two integrators;
 * the published vector is good to ~1e-7 there). */
extern const double andrews_v_ref[7];
extern const double andrews_qdd_ref[7];
extern const double andrews_lambda_ref[6];
extern const double andrews_t_end;
/* Relative 2-norm error of the 7 angles against the published reference at t = 0.03. */
double andrews_angle_error(const double *q7);

/* The parameters of the applied forces: the spring's stiffness c0 and the motor torque. The
 * force and stiffness callbacks read them through their user pointer (NULL: these published
 * values, 4530 N/m and 0.033 N m); the other callbacks ignore it. */
typedef struct andrews_params {
    double c0, mom;
} andrews_params;
extern const andrews_params andrews_published;

/* ---- 7 relative angles ---------------------------------------------------------------- */
int an7_mass(double t, const double *q, double *M, void *user);
int an7_force(double t, const double *q, const double *v, double *f, void *user);
int an7_constraint(double t, const double *q, double *phi, void *user);
int an7_jacobian(double t, const double *q, double *Phi_q, void *user);
int an7_constraint_accel(double t, const double *q, const double *v, double *out, void *user);
/* Phi_t = 0: the mechanism's constraints do not depend on t */
int an7_constraint_dt(double t, const double *q, double *out, void *user);
/* Energy balance T + V - mom (beta - beta0). */
double an7_energy(const double *q, const double *v);
/* Position of point F (end of the crank) and its acceleration. */
void an7_point_f(const double *q, const double *v, const double *qdd, double *pos, double *acc);

/* ---- 31 absolute coordinates ------------------------------------------------------------ */
int an31_mass(double t, const double *q, double *M, void *user);
int an31_force(double t, const double *q, const double *v, double *f, void *user);
int an31_constraint(double t, const double *q, double *phi, void *user);
int an31_jacobian(double t, const double *q, double *Phi_q, void *user);
int an31_constraint_accel(double t, const double *q, const double *v, double *out, void *user);
int an31_constraint_dt(double t, const double *q, double *out, void *user); /* 0 */
/* K_t = d(Phi_q^T lambda)/dq - df/dq (M is constant): rotation terms and the spring at D. */
int an31_stiffness(double t, const double *q, const double *v, const double *qdd,
                   const double *lambda, double *K, void *user);
/* The same model for a sparse solver: declares the patterns of M (the 21 body entries), Phi_q
 * (4 or 6 entries per constraint pair), K_t (the 7 rotations and the spring point D) and C_t
 * (empty: no velocity-dependent force), and callbacks that write the values in that order. */
ga_status an31_declare_patterns(ga_solver *s);
int an31_mass_sparse(double t, const double *q, double *M, void *user);
int an31_jacobian_sparse(double t, const double *q, double *J, void *user);
int an31_stiffness_sparse(double t, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *K, void *user);

/* Consistent absolute coordinates and velocities from the 7 angles and their rates. */
void an31_from_angles(const double *q7, const double *v7, double *q31, double *v31);
/* The 7 Test Set angles from absolute coordinates. */
void an31_to_angles(const double *q31, double *q7);
double an31_energy(const double *q, const double *v);
/* Index of body b's rotation (b = 1..7) and of point F's x in q. */
int an31_theta(int body);
int an31_point(char name);

#ifdef __cplusplus
}
#endif

#endif
