/* A structural model without constraints: a planar lattice of unit point masses on a grid of
 * nx x ny nodes (spacing 1 m), each joined to its right, upper and two diagonal neighbours by
 * springs with the exact (geometrically nonlinear) length law f = k (l - l0), clamped at its
 * left column and sagging under gravity from its unstressed start. The springs of the outer
 * half (midpoint x > nx / 2) are `contrast` times stiffer than the inner ones: a cantilever of
 * two materials, whose stiff part's highest frequencies a time step need not resolve.
 *
 * Unknowns: the displacements (ux, uy) of the free nodes, column by column (n = 2 (nx - 1) ny).
 * The stiffness K_t = -df/du is symmetric, so its compressed rows are its compressed columns:
 * lattice_make builds that pattern once (rowptr, colind) and lattice_stiffness_values fills
 * values in its order, for galpha (ga_set_pattern_csc) and for any code taking CSR. Everything
 * is O(n). */
#ifndef GALPHA_SCENE_LATTICE_H
#define GALPHA_SCENE_LATTICE_H

#include <galpha.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct lattice_spring {
    int a, b;          /* node indices over all nx * ny nodes (column-major) */
    double rest, k;
} lattice_spring;

typedef struct lattice {
    int nx, ny, n, springs;
    double k_soft, contrast, mass, gravity;
    lattice_spring *spring;
    int *rowptr, *colind, nnz; /* K_t's pattern, n + 1 and nnz entries */
    int *slot;                 /* per spring: its four 2x2 blocks' first entries (aa, bb, ab, ba) */
} lattice;

/* Returns 0, or -1 when out of memory. */
int lattice_make(lattice *l, int nx, int ny, double k_soft, double contrast);
void lattice_free(lattice *l);

/* galpha callbacks (user = the lattice) */
int lattice_mass(double t, const double *q, double *M, void *user); /* M = mass I, diagonal */
int lattice_force(double t, const double *q, const double *v, double *f, void *user);
int lattice_stiffness(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *K, void *user);
/* K_t's values in the order of (rowptr, colind) */
void lattice_stiffness_values(const lattice *l, const double *q, double *K);
/* Declares M (diagonal), K_t (the pattern above) and C_t (none) on a solver. */
ga_status lattice_declare_patterns(const lattice *l, ga_solver *s);

#ifdef __cplusplus
}
#endif

#endif
