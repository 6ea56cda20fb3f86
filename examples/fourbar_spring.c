/* A four-bar linkage held by a spring, in natural coordinates: ground pivots (0, 0) and
 * (d, 0), crank a, coupler b, rocker c, point masses at the crank's and the rocker's moving
 * pins q = (B, C), a linear spring from C to an anchor E, gravity. One degree of freedom.
 * ga_static_equilibrium finds where it rests, ga_modes its one frequency, and a transient
 * run released from the rest with a small velocity along the mode swings with that period
 * (zero crossings of the modal coordinate on the steps, h = T / 400: the method's own period
 * error is (omega h)^2 / 12 = 2.1e-5). Printed, and checked (exit status 1 if not). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    double d, a, b, c, mB, mC, k, l0, E[2], g;
} fourbar;

static int mass(double t, const double *q, double *M, void *u)
{
    const fourbar *p = u;
    (void)t, (void)q;
    memset(M, 0, 16 * sizeof(double));
    M[0] = M[5] = p->mB;
    M[10] = M[15] = p->mC;
    return 0;
}

static int force(double t, const double *q, const double *v, double *f, void *u)
{
    const fourbar *p = u;
    (void)t, (void)v;
    const double ex = q[2] - p->E[0], ey = q[3] - p->E[1], l = sqrt(ex * ex + ey * ey);
    const double pull = -p->k * (l - p->l0) / l;
    f[0] = 0.0;
    f[1] = -p->mB * p->g;
    f[2] = pull * ex;
    f[3] = pull * ey - p->mC * p->g;
    return 0;
}

/* crank, coupler and rocker lengths, halved squares */
static int constraint(double t, const double *q, double *phi, void *u)
{
    const fourbar *p = u;
    (void)t;
    const double bx = q[0], by = q[1], cx = q[2], cy = q[3];
    phi[0] = 0.5 * (bx * bx + by * by - p->a * p->a);
    phi[1] = 0.5 * ((cx - bx) * (cx - bx) + (cy - by) * (cy - by) - p->b * p->b);
    phi[2] = 0.5 * ((cx - p->d) * (cx - p->d) + cy * cy - p->c * p->c);
    return 0;
}

static int jacobian(double t, const double *q, double *J, void *u)
{
    const fourbar *p = u;
    (void)t;
    const double bx = q[0], by = q[1], cx = q[2], cy = q[3];
    memset(J, 0, 12 * sizeof(double)); /* 3 x 4, column-major */
    J[0] = bx;
    J[3] = by;
    J[1] = -(cx - bx);
    J[4] = -(cy - by);
    J[7] = cx - bx;
    J[10] = cy - by;
    J[8] = cx - p->d;
    J[11] = cy;
    return 0;
}

static int check(int ok, const char *what)
{
    printf("  %-58s %s\n", what, ok ? "ok" : "FAILED");
    return ok ? 0 : 1;
}

int main(void)
{
    fourbar p = {4.0, 1.0, 3.5, 2.5, 2.0, 1.5, 200.0, 1.0, {1.0, 4.0}, 9.81};
    ga_solver *s = NULL;
    if (ga_create(4, 3, &s) || ga_set_callbacks(s, mass, force, constraint, jacobian, &p))
        return 1;
    int bad = 0;
    /* a start with the crank at 1.35 rad, on the loop: B on its circle, C where the coupler
     * and the rocker meet */
    double q[4], lambda[3], w2[1], shape[4];
    const double th = 1.35, bx = p.a * cos(th), by = p.a * sin(th);
    {
        const double dx = p.d - bx, dy = -by, l = sqrt(dx * dx + dy * dy);
        const double along = (p.b * p.b - p.c * p.c + l * l) / (2.0 * l);
        const double up = sqrt(p.b * p.b - along * along);
        q[0] = bx;
        q[1] = by;
        q[2] = bx + (along * dx - up * dy) / l;
        q[3] = by + (along * dy + up * dx) / l;
    }
    ga_status st = ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50);
    bad += check(st == GA_OK, "rests");
    if (st) {
        printf("  %s\n", ga_last_error(s));
        return 1;
    }
    printf("  crank at %.6f rad, rocker pin at (%.6f, %.6f)\n", atan2(q[1], q[0]), q[2], q[3]);
    st = ga_modes(s, 0.0, q, lambda, 1, w2, shape);
    bad += check(st == GA_OK && w2[0] > 0.0, "a stable rest with one frequency");
    const double omega = sqrt(w2[0]), T = 2.0 * M_PI / omega, h = T / 400.0;
    printf("  omega %.8f rad/s, period %.8f s\n", omega, T);

    /* released from the rest at a velocity 1e-4 omega along the mode (tangent to the loop) */
    double v[4], x[4], z_prev = 0.0, first = -1.0, last = -1.0;
    for (int i = 0; i < 4; ++i)
        v[i] = 1e-4 * omega * shape[i];
    ga_solver *d = NULL;
    if (ga_create(4, 3, &d) || ga_set_callbacks(d, mass, force, constraint, jacobian, &p))
        return 1;
    ga_set_rho_inf(d, 0.9);
    st = ga_init(d, 0.0, q, v);
    int crossings = 0;
    for (int k = 0; k <= 1600 && !st; ++k) { /* four periods */
        if (k > 0)
            st = ga_step(d, h);
        ga_get_q(d, x);
        double z = 0.0; /* modal coordinate shape^T M (x - q) */
        for (int i = 0; i < 4; ++i)
            z += (i < 2 ? p.mB : p.mC) * shape[i] * (x[i] - q[i]);
        if (k > 0 && z_prev > 0.0 && z <= 0.0) { /* downward, by linear interpolation */
            const double tc = (k - 1 + z_prev / (z_prev - z)) * h;
            if (first < 0.0)
                first = tc;
            last = tc;
            ++crossings;
        }
        z_prev = z;
    }
    bad += check(st == GA_OK, "its transient run");
    if (st)
        printf("  %s\n", ga_last_error(d));
    const double period = crossings > 1 ? (last - first) / (crossings - 1) : 0.0;
    printf("  period in the run %.8f s: %.2g relative\n", period, fabs(period - T) / T);
    bad += check(crossings >= 3 && fabs(period - T) <= 1e-4 * T,
                 "swings at the computed period (within 1e-4)");
    ga_free(d);
    ga_free(s);
    return bad ? 1 : 0;
}
