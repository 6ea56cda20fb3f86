/* A spatial chain of N rigid rods hanging from a fixed point, each body on R^3 x SO(3)
 * (ga_create_space): per body its centre of mass x in space (3 numbers) and its attitude as a
 * unit quaternion (4); in v, x' in space and the body angular velocity omega (6 per body).
 * Spherical joints: the first rod's top end at the origin, every other rod's top end at the
 * previous rod's bottom end (3 constraints each, 3N in all). Every rod is 1 m, 1 kg, of radius
 * 0.05 m, its axis the body z axis, ends at (0, 0, +-L/2). The chain starts straight and
 * horizontal along +x, every rod spinning about its own axis at `spin` rad/s (which the joints
 * allow), and falls under gravity (0, 0, -9.81).
 *
 * The callbacks are written for declared sparsity patterns: they fill values in the order of
 * spatial_chain_pattern(). Phi_q's rotation columns are -R a~ and R b~, whose third column
 * (the spin axis) is zero and left out of the pattern; K_t = a~ (R^T (lambda_k +
 * lambda_{k+1}))~ has two rows per body. Everything is O(N). */
#ifndef GALPHA_SCENE_SPATIAL_CHAIN_H
#define GALPHA_SCENE_SPATIAL_CHAIN_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct spatial_chain {
    int bodies;
    double length, mass, inertia[3], gravity, spin; /* per rod */
} spatial_chain;

spatial_chain spatial_chain_make(int bodies, double spin);

/* The space: 2N blocks (a vector block of 3, one rotation) into kinds and counts */
void spatial_chain_blocks(const spatial_chain *c, int *kinds, int *counts);
/* A solver on that space with the callbacks, the tangents and the four patterns */
ga_status spatial_chain_solver(spatial_chain *c, ga_solver **out);
/* Pattern of a matrix (GA_MATRIX_MASS, _JACOBIAN, _STIFFNESS, _DAMPING): the number of entries
 * when rows/cols are NULL, otherwise fills them and returns the count. */
int spatial_chain_pattern(const spatial_chain *c, int which, int *rows, int *cols);

int spatial_chain_mass(double t, const double *q, double *M, void *user);
int spatial_chain_force(double t, const double *q, const double *v, double *f, void *user);
int spatial_chain_constraint(double t, const double *q, double *phi, void *user);
int spatial_chain_jacobian(double t, const double *q, double *J, void *user);
int spatial_chain_stiffness(double t, const double *q, const double *v, const double *qdd,
                            const double *lambda, double *K, void *user);
int spatial_chain_damping(double t, const double *q, const double *v, double *C, void *user);

/* q (7N) and v (6N) at t = 0 */
void spatial_chain_initial(const spatial_chain *c, double *q, double *v);

#ifdef __cplusplus
}
#endif

#endif
