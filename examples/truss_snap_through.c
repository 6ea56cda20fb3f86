/* A shallow two-bar truss snapping through (von Mises truss): two elastic bars from (-a, 0)
 * and (a, 0) to an apex at height h, the apex held on the rail x = 0 by a constraint, a load
 * mu pressing it down. Its equilibria mu(y) = 2 EA (L0 - L) y / (L0 L), L = sqrt(a^2 + y^2),
 * rise to a limit load and fall: load stepping with ga_static_equilibrium stops there (the
 * load has no rest nearby), ga_static_path follows the curve through the limit, down the
 * unstable branch to the inverted rest and beyond, and ga_modes tells the stable rests from
 * the unstable ones. Printed, and checked against the closed curve (exit status 1 if not). */
#include <math.h>
#include <stdio.h>

#include <galpha.h>

typedef struct {
    double a, h, EA, mu;
    double worst; /* |mu - mu(y)| + |x| over the path */
    double limit; /* the largest load on the path above the supports */
    int points;
} truss;

static double closed_load(const truss *p, double y)
{
    const double L0 = sqrt(p->a * p->a + p->h * p->h), L = sqrt(p->a * p->a + y * y);
    return 2.0 * p->EA * (L0 - L) * y / (L0 * L);
}

static int mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = M[3] = 1.0;
    M[1] = M[2] = 0.0;
    return 0;
}

static int force(double t, const double *q, const double *v, double *f, void *u)
{
    const truss *p = u;
    (void)t, (void)v;
    const double L0 = sqrt(p->a * p->a + p->h * p->h);
    f[0] = 0.0;
    f[1] = -p->mu;
    for (int side = -1; side <= 1; side += 2) { /* each bar's tension along it */
        const double dx = q[0] - side * p->a, dy = q[1], L = sqrt(dx * dx + dy * dy);
        const double tension = p->EA * (L - L0) / L0;
        f[0] -= tension * dx / L;
        f[1] -= tension * dy / L;
    }
    return 0;
}

static int rail(double t, const double *q, double *phi, void *u)
{
    (void)t, (void)u;
    phi[0] = q[0];
    return 0;
}

static int rail_jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    J[0] = 1.0;
    J[1] = 0.0;
    return 0;
}

static int on_point(double load, const double *q, const double *lambda, void *u)
{
    truss *p = u;
    (void)lambda;
    p->worst = fmax(p->worst, fabs(load - closed_load(p, q[1])) + fabs(q[0]));
    if (q[1] > 0.0)
        p->limit = fmax(p->limit, load);
    if (p->points++ % 60 == 0)
        printf("  apex at %+.4f: load %8.4f (closed form %8.4f)\n", q[1], load,
               closed_load(p, q[1]));
    return q[1] < -1.5 * p->h; /* past the inverted rest: enough */
}

static int check(int ok, const char *what)
{
    printf("  %-58s %s\n", what, ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}

int main(void)
{
    truss p = {1.0, 0.2, 1000.0, 0.0, 0.0, 0.0, 0};
    ga_solver *s = NULL;
    if (ga_create(2, 1, &s) || ga_set_callbacks(s, mass, force, rail, rail_jacobian, &p))
        return 1;
    int bad = 0;

    /* load stepping: from the unloaded apex, 0.25 more load each time */
    printf("load stepping\n");
    double q[2] = {0.0, p.h}, lambda[1];
    ga_status st = GA_OK;
    for (p.mu = 0.25; p.mu < 10.0 && st == GA_OK; p.mu += 0.25)
        st = ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 50);
    const double failed_at = p.mu - 0.25;
    const ga_status stepping = st;
    printf("  stops at load %.2f: %s\n  (the apex stays at %.4f, the last rest)\n", failed_at,
           ga_last_error(s), q[1]);

    /* arc length from the unloaded truss through the limit point */
    printf("arc length\n");
    p.mu = 0.0;
    q[0] = 0.0;
    q[1] = p.h;
    st = ga_static_path(s, 0.0, &p.mu, q, lambda, 0.05, 5000, 1e-12, on_point, &p);
    printf("  %d points, worst distance from the closed curve %.2g, limit load %.6f\n", p.points,
           p.worst, p.limit);
    bad += check(st == GA_STOPPED && p.points > 100, "follows the path past the inverted rest");
    bad += check(p.worst <= 1e-8, "on the closed load-displacement curve (1e-8)");
    bad += check(stepping == GA_ERR_NEWTON && failed_at > p.limit && failed_at - 0.25 < p.limit,
                 "load stepping stopped at the first step past the limit");

    /* stable before the limit, unstable on the falling branch */
    double w2[1], up[2] = {0.0, 0.18}, down[2] = {0.0, 0.05};
    p.mu = closed_load(&p, 0.18);
    st = ga_modes(s, 0.0, up, NULL, 1, w2, NULL);
    printf("  apex at 0.18: omega^2 = %.4g\n", w2[0]);
    bad += check(st == GA_OK && w2[0] > 0.0, "stable before the limit");
    p.mu = closed_load(&p, 0.05);
    st = ga_modes(s, 0.0, down, NULL, 1, w2, NULL);
    printf("  apex at 0.05: omega^2 = %.4g\n", w2[0]);
    bad += check(st == GA_OK && w2[0] < 0.0, "unstable after it");
    ga_free(s);
    return bad ? 1 : 0;
}
