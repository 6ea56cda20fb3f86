#include "lattice.h"

#include <math.h>
#include <stdlib.h>

/* free node of grid node (i, j), or -1 on the clamped column */
static int free_node(const lattice *l, int node) { return node < l->ny ? -1 : node - l->ny; }

static void add_spring(lattice *l, int a, int b, double rest, double mid_x)
{
    lattice_spring *s = &l->spring[l->springs++];
    s->a = a;
    s->b = b;
    s->rest = rest;
    s->k = mid_x > 0.5 * l->nx ? l->k_soft * l->contrast : l->k_soft;
}

/* position in K_t's values of the 2x2 block (free nodes fa, fb): its (0, 0) entry; row 2 fa + 1
 * holds the same columns one row length further */
static int block_slot(const lattice *l, int fa, int fb)
{
    if (fa < 0 || fb < 0)
        return -1;
    for (int p = l->rowptr[2 * fa]; p < l->rowptr[2 * fa + 1]; p += 2)
        if (l->colind[p] == 2 * fb)
            return p;
    return -1; /* not reached: every spring's nodes are stencil neighbours */
}

int lattice_make(lattice *l, int nx, int ny, double k_soft, double contrast)
{
    l->nx = nx;
    l->ny = ny;
    l->n = 2 * (nx - 1) * ny;
    l->k_soft = k_soft;
    l->contrast = contrast;
    l->mass = 1.0;
    l->gravity = 9.81;
    l->springs = 0;
    l->spring = malloc(sizeof(lattice_spring) * (size_t)(4 * nx * ny));
    l->rowptr = malloc(sizeof(int) * (size_t)(l->n + 1));
    l->colind = malloc(sizeof(int) * (size_t)(18 * l->n));
    l->slot = malloc(sizeof(int) * (size_t)(16 * nx * ny));
    if (!l->spring || !l->rowptr || !l->colind || !l->slot) {
        lattice_free(l);
        return -1;
    }
    /* the 3 x 3 stencil of free nodes, ascending (column-major numbering) */
    int nnz = 0;
    for (int i = 1; i < nx; ++i)
        for (int j = 0; j < ny; ++j)
            for (int d = 0; d < 2; ++d) {
                l->rowptr[2 * ((i - 1) * ny + j) + d] = nnz;
                for (int ci = i - 1; ci <= i + 1; ++ci)
                    for (int cj = j - 1; cj <= j + 1; ++cj)
                        if (ci >= 1 && ci < nx && cj >= 0 && cj < ny) {
                            const int g = (ci - 1) * ny + cj;
                            l->colind[nnz++] = 2 * g;
                            l->colind[nnz++] = 2 * g + 1;
                        }
            }
    l->rowptr[l->n] = nnz;
    l->nnz = nnz;
    /* springs to the right, up and both diagonals to the right; none within the clamped column */
    const double diag = sqrt(2.0);
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j) {
            const int a = i * ny + j;
            if (i + 1 < nx) {
                add_spring(l, a, a + ny, 1.0, i + 0.5);
                if (j + 1 < ny)
                    add_spring(l, a, a + ny + 1, diag, i + 0.5);
                if (j > 0)
                    add_spring(l, a, a + ny - 1, diag, i + 0.5);
            }
            if (j + 1 < ny && i > 0)
                add_spring(l, a, a + 1, 1.0, i);
        }
    for (int e = 0; e < l->springs; ++e) {
        const int fa = free_node(l, l->spring[e].a), fb = free_node(l, l->spring[e].b);
        int *s = l->slot + 4 * e;
        s[0] = block_slot(l, fa, fa);
        s[1] = block_slot(l, fb, fb);
        s[2] = block_slot(l, fa, fb);
        s[3] = block_slot(l, fb, fa);
    }
    return 0;
}

void lattice_free(lattice *l)
{
    free(l->spring);
    free(l->rowptr);
    free(l->colind);
    free(l->slot);
    l->spring = NULL;
    l->rowptr = l->colind = l->slot = NULL;
}

/* current position of a grid node */
static void position(const lattice *l, const double *q, int node, double x[2])
{
    x[0] = node / l->ny;
    x[1] = node % l->ny;
    const int f = free_node(l, node);
    if (f >= 0) {
        x[0] += q[2 * f];
        x[1] += q[2 * f + 1];
    }
}

/* a spring's vector from its node a to its node b, and its length */
static double spring_vector(const lattice *l, const double *q, const lattice_spring *s,
                            double d[2])
{
    double xa[2], xb[2];
    position(l, q, s->a, xa);
    position(l, q, s->b, xb);
    d[0] = xb[0] - xa[0];
    d[1] = xb[1] - xa[1];
    return sqrt(d[0] * d[0] + d[1] * d[1]);
}

int lattice_mass(double t, const double *q, double *M, void *user)
{
    (void)t;
    (void)q;
    const lattice *l = user;
    for (int i = 0; i < l->n; ++i)
        M[i] = l->mass;
    return 0;
}

int lattice_force(double t, const double *q, const double *v, double *f, void *user)
{
    (void)t;
    (void)v;
    const lattice *l = user;
    for (int i = 0; i < l->n; i += 2) {
        f[i] = 0.0;
        f[i + 1] = -l->mass * l->gravity;
    }
    for (int e = 0; e < l->springs; ++e) {
        const lattice_spring *s = &l->spring[e];
        double d[2];
        const double len = spring_vector(l, q, s, d), d0 = d[0], d1 = d[1];
        const double pull = s->k * (len - s->rest) / len;
        const int fa = free_node(l, s->a), fb = free_node(l, s->b);
        if (fa >= 0) {
            f[2 * fa] += pull * d0;
            f[2 * fa + 1] += pull * d1;
        }
        if (fb >= 0) {
            f[2 * fb] -= pull * d0;
            f[2 * fb + 1] -= pull * d1;
        }
    }
    return 0;
}

/* adds sign * B to the 2x2 block at slot p of rows whose length is len */
static void add_block(double *K, int p, int len, double sign, const double B[3])
{
    if (p < 0)
        return;
    K[p] += sign * B[0];
    K[p + 1] += sign * B[1];
    K[p + len] += sign * B[1];
    K[p + len + 1] += sign * B[2];
}

void lattice_stiffness_values(const lattice *l, const double *q, double *K)
{
    for (int p = 0; p < l->nnz; ++p)
        K[p] = 0.0;
    for (int e = 0; e < l->springs; ++e) {
        const lattice_spring *s = &l->spring[e];
        double d[2];
        const double len = spring_vector(l, q, s, d);
        const double n0 = d[0] / len, n1 = d[1] / len, slack = 1.0 - s->rest / len;
        /* k (n n^T + (1 - l0 / l)(I - n n^T)): symmetric, (xx, xy, yy) */
        const double B[3] = {s->k * (n0 * n0 + slack * (1.0 - n0 * n0)),
                             s->k * (n0 * n1 - slack * n0 * n1),
                             s->k * (n1 * n1 + slack * (1.0 - n1 * n1))};
        const int *slot = l->slot + 4 * e;
        const int fa = free_node(l, s->a), fb = free_node(l, s->b);
        const int len_a = fa >= 0 ? l->rowptr[2 * fa + 1] - l->rowptr[2 * fa] : 0;
        const int len_b = fb >= 0 ? l->rowptr[2 * fb + 1] - l->rowptr[2 * fb] : 0;
        add_block(K, slot[0], len_a, 1.0, B);
        add_block(K, slot[1], len_b, 1.0, B);
        add_block(K, slot[2], len_a, -1.0, B);
        add_block(K, slot[3], len_b, -1.0, B);
    }
}

int lattice_stiffness(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *K, void *user)
{
    (void)t;
    (void)v;
    (void)qdd;
    (void)lambda;
    lattice_stiffness_values(user, q, K);
    return 0;
}

ga_status lattice_declare_patterns(const lattice *l, ga_solver *s)
{
    int *diag = malloc(sizeof(int) * (size_t)l->n);
    if (!diag)
        return GA_ERR_NOMEM;
    for (int i = 0; i < l->n; ++i)
        diag[i] = i;
    ga_status st = ga_set_pattern(s, GA_MATRIX_MASS, l->n, diag, diag);
    free(diag);
    if (!st)
        st = ga_set_pattern_csc(s, GA_MATRIX_STIFFNESS, l->rowptr, l->colind);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL);
    return st;
}
