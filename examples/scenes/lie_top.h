/* The heavy top as a rigid body on R^3 x SO(3) (issue 36): the centre of mass x in space, the
 * rotation R about it (a unit quaternion or a rotation matrix in q), body-frame angular
 * velocity omega, the centroidal inertia, and the fixed spherical joint at the origin as the
 * constraint Phi = x - R X = 0 (X: the centre of mass in the body). Built with
 * ga_create_space({VECTOR 3, SO3 1}, m = 3): nq = 7 or 12, nv = 6.
 *
 * Data (the classic test, Bruls & Cardona 2010): m = 15, centroidal inertia
 * diag(0.234375, 0.46875, 0.234375), X = (0, 1, 0), gravity (0, 0, -9.81), R(0) = I,
 * omega(0) = (0, 150, -4.61538) in the body.
 *
 * Oracle: lie_top_reference, classical RK4 on Euler's equations about the pivot with a rotation
 * matrix (J_P omega' = -omega x J_P omega + X x R^T m g, R' = R omega~): another set of
 * equations, another integrator, no constraint. A Lagrange top (J_P symmetric about the body
 * axis X), so energy, the vertical angular momentum and the spin omega_2 are its invariants
 * (lie_top_invariants). */
#ifndef GALPHA_SCENES_LIE_TOP_H
#define GALPHA_SCENES_LIE_TOP_H

#ifdef __cplusplus
extern "C" {
#endif

enum { LIE_TOP_NV = 6, LIE_TOP_M = 3 };

typedef struct lie_top {
    int matrix;       /* rotation stored as a matrix (9, column-major) instead of a quaternion */
    double mass;      /* 15 */
    double Jc[3];     /* centroidal inertia */
    double X[3];      /* centre of mass in the body */
    double g[3];      /* gravity */
    double omega0[3]; /* initial body angular velocity */
} lie_top;

lie_top lie_top_make(int matrix);
int lie_top_nq(const lie_top *t); /* 7 or 12 */
/* The space's blocks for ga_create_space: kinds[2], counts[2] */
void lie_top_blocks(const lie_top *t, int *kinds, int *counts);
/* q0 (nq) and v0 (6) at t = 0, consistent with the joint */
void lie_top_initial(const lie_top *t, double *q0, double *v0);
/* The rotation matrix (row-major) of q */
void lie_top_rotation(const lie_top *t, const double *q, double R[9]);

int lie_top_mass(double time, const double *q, double *M, void *user);
int lie_top_force(double time, const double *q, const double *v, double *f, void *user);
int lie_top_constraint(double time, const double *q, double *phi, void *user);
int lie_top_jacobian(double time, const double *q, double *Phi_q, void *user);
/* K_t = d(Phi_q^T lambda)/dq along right increments: -X~ (R^T lambda)~ in the rotation's
 * block (M is constant, f does not depend on q) */
int lie_top_stiffness(double time, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *K, void *user);
/* C_t = -df/domega = omega~ J - (J omega)~ (the gyroscopic term's tangent) */
int lie_top_damping(double time, const double *q, const double *v, double *C, void *user);

/* The same top on SO(3) alone, about its pivot (ga_create_space({SO3 1}, m = 0): nq = 4,
 * nv = 3; q a quaternion, v = omega): the inertia about the pivot J_P, no constraint, the
 * moment of gravity X x R^T m g. */
int lie_top_pivot_mass(double time, const double *q, double *M, void *user);
int lie_top_pivot_force(double time, const double *q, const double *v, double *f, void *user);

/* The same top on SE(3) (ga_create_space({SE3 1}, m = 3): nq = 7, nv = 6; use
 * lie_top_make(0)): q = (x, R's quaternion) as on R^3 x SO(3), v = (U, omega) the body twist,
 * U = R^T x'. The joint as Phi = R^T x - X, Phi_q = [I, (R^T x)~]; M = diag(m I, J_c) as
 * lie_top_mass; f = (R^T m g - m omega x U, -omega x J_c omega). The multiplier is the
 * reaction in the body frame (R lambda in space). */
void lie_top_se3_initial(const lie_top *t, double *q0, double *v0);
int lie_top_se3_force(double time, const double *q, const double *v, double *f, void *user);
int lie_top_se3_constraint(double time, const double *q, double *phi, void *user);
int lie_top_se3_jacobian(double time, const double *q, double *Phi_q, void *user);
/* K_t of -f + Phi_q^T lambda along right increments: -(R^T m g)~ (u rows, w columns),
 * lambda~ (w rows, u columns), lambda~ (R^T x)~ (w rows, w columns) */
int lie_top_se3_stiffness(double time, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *K, void *user);
/* C_t = -df/dv: m omega~ (u, u), -m U~ (u, w), omega~ J - (J omega)~ (w, w) */
int lie_top_se3_damping(double time, const double *q, const double *v, double *C, void *user);
/* Energy, vertical angular momentum about the pivot, spin omega_2, from q and v (any of the
 * formulations with a quaternion at q + 3 and omega at v + 3: they use the rotation only) */
void lie_top_invariants(const lie_top *t, const double *q, const double *v, double out[3]);

/* The reference at t_end by RK4 with `steps` steps: R (row-major), omega, omega', and from
 * them the centre of mass R X and the joint reaction lambda = m g - m x'' (the multipliers of
 * M qdd = f - Phi_q^T lambda, translational rows). */
typedef struct lie_top_state {
    double R[9], omega[3], omega_dot[3], com[3], reaction[3];
} lie_top_state;
lie_top_state lie_top_reference(const lie_top *t, double t_end, long steps);

#ifdef __cplusplus
}
#endif

#endif
