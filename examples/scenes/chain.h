/* A planar chain of N rigid links hanging from a fixed pin, in absolute coordinates: per link
 * the centre of mass (x, y) and the angle theta (3N coordinates); the first link's start is
 * pinned at the origin and every other link's start is pinned to the previous link's end (2N
 * constraints). Gravity only. Every link is a slender bar of 1 m and 1 kg (I = m L^2 / 12), so
 * the iteration matrix is equally well scaled for every N; the chain starts straight and
 * horizontal, at rest, and falls.
 *
 * The callbacks are written for declared sparsity patterns (ga_set_pattern): they fill values
 * in the order given by chain_pattern(). Everything is O(N). */
#ifndef GALPHA_SCENE_CHAIN_H
#define GALPHA_SCENE_CHAIN_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct chain {
    int links;
    double length, mass, inertia, gravity; /* per link */
} chain;

chain chain_make(int links);

/* Pattern of a matrix (GA_MATRIX_MASS, _JACOBIAN, _STIFFNESS, _DAMPING): the number of entries
 * when rows/cols are NULL, otherwise fills them and returns the count. */
int chain_pattern(const chain *c, int which, int *rows, int *cols);
/* Declares all four patterns on a solver. */
ga_status chain_declare_patterns(const chain *c, ga_solver *s);

int chain_mass(double t, const double *q, double *M, void *user);
int chain_force(double t, const double *q, const double *v, double *f, void *user);
int chain_constraint(double t, const double *q, double *phi, void *user);
int chain_jacobian(double t, const double *q, double *J, void *user);
int chain_stiffness(double t, const double *q, const double *v, const double *qdd,
                    const double *lambda, double *K, void *user);
int chain_constraint_accel(double t, const double *q, const double *v, double *out, void *user);
/* Phi_t = 0 (the pin is fixed) */
int chain_constraint_dt(double t, const double *q, double *out, void *user);

void chain_initial(const chain *c, double *q, double *v);

#ifdef __cplusplus
}
#endif

#endif
