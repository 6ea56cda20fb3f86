/* The shipped scenes as the accuracy suites sweep them (test_newton_sweep.c,
 * test_tolerance.c): each with its callbacks for galpha (sparse patterns where the scene has
 * them), dense callbacks for the independent reference (index1_rk4.c: RK4 on the index-1 form,
 * no galpha code) and a step for that reference whose error is far below galpha's. */
#ifndef GALPHA_TEST_SCENE_CATALOG_H
#define GALPHA_TEST_SCENE_CATALOG_H

#include <math.h>
#include <string.h>

#include <galpha.h>

#include "scenes/andrews.h"
#include "scenes/chain.h"
#include "scenes/index1_rk4.h"
#include "scenes/pendulum.h"
#include "scenes/slider_crank.h"

enum { kCatalogMaxN = 40, kCatalogScenes = 5, kCatalogLinks = 4 };

typedef struct catalog_scene {
    const char *name;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_constraint_accel_fn accel;
    ga_constraint_fn dt;
    ga_status (*declare)(ga_solver *s, void *user); /* sparse patterns, or NULL */
    void *user;
    rk4_model reference; /* dense callbacks */
    double q0[kCatalogMaxN], v0[kCatalogMaxN];
    double t_end;       /* a run over the scene's motion */
    double h_reference; /* RK4's step: its error ~(h omega)^4 far below galpha's */
} catalog_scene;

/* ---- the chain, whose callbacks fill pattern values: dense versions for the reference ---- */
static chain g_catalog_chain;

static inline void catalog_scatter(int which, int rows_n, const double *values, double *dense)
{
    int rows[64], cols[64];
    const int nnz = chain_pattern(&g_catalog_chain, which, rows, cols);
    memset(dense, 0, sizeof(double) * (size_t)(rows_n * 3 * kCatalogLinks));
    for (int k = 0; k < nnz; ++k)
        dense[rows[k] + rows_n * cols[k]] += values[k];
}
static inline int catalog_chain_mass(double t, const double *q, double *M, void *u)
{
    double values[64];
    const int rc = chain_mass(t, q, values, u);
    catalog_scatter(GA_MATRIX_MASS, 3 * kCatalogLinks, values, M);
    return rc;
}
static inline int catalog_chain_jacobian(double t, const double *q, double *J, void *u)
{
    double values[64];
    const int rc = chain_jacobian(t, q, values, u);
    catalog_scatter(GA_MATRIX_JACOBIAN, 2 * kCatalogLinks, values, J);
    return rc;
}
static inline ga_status catalog_declare_chain(ga_solver *s, void *user)
{
    return chain_declare_patterns((const chain *)user, s);
}
static inline ga_status catalog_declare_andrews31(ga_solver *s, void *user)
{
    (void)user;
    return an31_declare_patterns(s);
}

static pendulum g_catalog_pendulum = {1.0, 1.0, 9.81};
static slider_crank g_catalog_crank;

/* Scene 0 the pendulum (theta0 = 1, omega0 = 0.5), 1 the slider-crank of the paper, 2 Andrews
 * in 7 angles, 3 Andrews in 31 absolute coordinates on the sparse path, 4 a chain of 4 links
 * on the sparse path. */
static inline catalog_scene catalog_make(int which)
{
    catalog_scene sc;
    memset(&sc, 0, sizeof sc);
    switch (which) {
    case 0:
        sc.name = "pendulum";
        sc.n = 2, sc.m = 1;
        sc.mass = pendulum_mass, sc.force = pendulum_force;
        sc.constraint = pendulum_constraint, sc.jacobian = pendulum_jacobian;
        sc.accel = pendulum_constraint_accel;
        sc.user = &g_catalog_pendulum;
        pendulum_state(&g_catalog_pendulum, 1.0, 0.5, sc.q0, sc.v0);
        sc.t_end = 1.0, sc.h_reference = 1e-4;
        break;
    case 1:
        g_catalog_crank = slider_crank_paper();
        sc.name = "slider-crank";
        sc.n = SC_N, sc.m = SC_M;
        sc.mass = sc_mass, sc.force = sc_force;
        sc.constraint = sc_constraint, sc.jacobian = sc_jacobian;
        sc.accel = sc_constraint_accel, sc.dt = sc_constraint_dt;
        sc.user = &g_catalog_crank;
        sc_initial(&g_catalog_crank, M_PI / 2, sc.q0, sc.v0);
        sc.t_end = 0.1, sc.h_reference = 1e-5;
        break;
    case 2:
        sc.name = "andrews7";
        sc.n = AN7_N, sc.m = AN7_M;
        sc.mass = an7_mass, sc.force = an7_force;
        sc.constraint = an7_constraint, sc.jacobian = an7_jacobian;
        sc.accel = an7_constraint_accel, sc.dt = an7_constraint_dt;
        memcpy(sc.q0, andrews_q0, sizeof andrews_q0);
        sc.t_end = andrews_t_end, sc.h_reference = 2e-6;
        break;
    case 3:
        sc.name = "andrews31 sparse";
        sc.n = AN31_N, sc.m = AN31_M;
        sc.mass = an31_mass_sparse, sc.force = an31_force;
        sc.constraint = an31_constraint, sc.jacobian = an31_jacobian_sparse;
        sc.accel = an31_constraint_accel, sc.dt = an31_constraint_dt;
        sc.declare = catalog_declare_andrews31;
        an31_from_angles(andrews_q0, sc.v0, sc.q0, sc.v0);
        sc.reference = (rk4_model){sc.n, sc.m, an31_mass, an31_force, an31_jacobian,
                                   an31_constraint_accel, NULL};
        sc.t_end = andrews_t_end, sc.h_reference = 2e-6;
        return sc;
    default:
        g_catalog_chain = chain_make(kCatalogLinks);
        sc.name = "chain sparse";
        sc.n = 3 * kCatalogLinks, sc.m = 2 * kCatalogLinks;
        sc.mass = chain_mass, sc.force = chain_force;
        sc.constraint = chain_constraint, sc.jacobian = chain_jacobian;
        sc.accel = chain_constraint_accel, sc.dt = chain_constraint_dt;
        sc.declare = catalog_declare_chain;
        sc.user = &g_catalog_chain;
        chain_initial(&g_catalog_chain, sc.q0, sc.v0);
        sc.reference = (rk4_model){sc.n, sc.m, catalog_chain_mass, chain_force,
                                   catalog_chain_jacobian, chain_constraint_accel,
                                   &g_catalog_chain};
        sc.t_end = 1.0, sc.h_reference = 1e-4;
        return sc;
    }
    sc.reference = (rk4_model){sc.n, sc.m, sc.mass, sc.force, sc.jacobian, sc.accel, sc.user};
    return sc;
}

/* A solver for the scene with its callbacks and patterns, not yet initialized. */
static inline ga_solver *catalog_solver(const catalog_scene *sc)
{
    ga_solver *s = NULL;
    if (ga_create(sc->n, sc->m, &s) != GA_OK)
        return NULL;
    if (ga_set_callbacks(s, sc->mass, sc->force, sc->constraint, sc->jacobian, sc->user) ||
        ga_set_constraint_accel(s, sc->accel) ||
        (sc->dt && ga_set_constraint_dt(s, sc->dt)) || (sc->declare && sc->declare(s, sc->user))) {
        ga_free(s);
        return NULL;
    }
    return s;
}

static inline double catalog_max_abs(const double *x, int n)
{
    double m = 0;
    for (int i = 0; i < n; ++i)
        m = fmax(m, fabs(x[i]));
    return m;
}

#endif
