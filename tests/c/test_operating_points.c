/* Operating points (ga_static_equilibrium, ga_linearize, ga_modes) against what is known
 * without galpha: the pendulum's and the double pendulum's small-oscillation frequencies in
 * closed form, and a four-bar with a spring derived by hand in its one minimal coordinate
 * (the crank angle: the coupler point by circle intersection, its derivatives by implicit
 * differentiation of the loop, equilibrium by a scalar Newton on V'(theta)). Then the
 * consistency with dynamics (a run started in the equilibrium stays there; the period of a
 * small free vibration in galpha's own transient run) and every refusal, with nothing
 * written and the solver as it was. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <complex.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

static const double g_acc = 9.81;

/* ---- pendulums in Cartesian coordinates: point masses on massless rods ---------------- */
/* q = (x1, y1, x2, y2, ...), Phi_i = ((p_i - p_{i-1})^2 - L_i^2) / 2 with p_0 = 0 */
typedef struct {
    int bodies;
    double m[2], L[2];
    int no_stiffness; /* leave K_t to differences */
    int fail_force;   /* the force callback fails */
} Pendulums;

static int pend_mass(double t, const double *q, double *M, void *u)
{
    const Pendulums *p = u;
    const int n = 2 * p->bodies;
    (void)t, (void)q;
    memset(M, 0, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n; ++i)
        M[i + n * i] = p->m[i / 2];
    return 0;
}

static int pend_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Pendulums *p = u;
    (void)t, (void)q, (void)v;
    if (p->fail_force)
        return -1;
    for (int b = 0; b < p->bodies; ++b) {
        f[2 * b] = 0.0;
        f[2 * b + 1] = -p->m[b] * g_acc;
    }
    return 0;
}

static void rel(const Pendulums *p, const double *q, int b, double *d)
{
    d[0] = q[2 * b] - (b > 0 ? q[2 * b - 2] : 0.0);
    d[1] = q[2 * b + 1] - (b > 0 ? q[2 * b - 1] : 0.0);
    (void)p;
}

static int pend_phi(double t, const double *q, double *phi, void *u)
{
    const Pendulums *p = u;
    (void)t;
    for (int b = 0; b < p->bodies; ++b) {
        double d[2];
        rel(p, q, b, d);
        phi[b] = 0.5 * (d[0] * d[0] + d[1] * d[1] - p->L[b] * p->L[b]);
    }
    return 0;
}

static int pend_jac(double t, const double *q, double *J, void *u)
{
    const Pendulums *p = u;
    const int m = p->bodies, n = 2 * m;
    (void)t;
    memset(J, 0, sizeof(double) * (size_t)(m * n));
    for (int b = 0; b < m; ++b) {
        double d[2];
        rel(p, q, b, d);
        J[b + m * (2 * b)] = d[0];
        J[b + m * (2 * b + 1)] = d[1];
        if (b > 0) {
            J[b + m * (2 * b - 2)] = -d[0];
            J[b + m * (2 * b - 1)] = -d[1];
        }
    }
    return 0;
}

/* K_t = sum_i lambda_i Hess(Phi_i) (the forces are constant) */
static int pend_stiff(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *K, void *u)
{
    const Pendulums *p = u;
    const int n = 2 * p->bodies;
    (void)t, (void)q, (void)v, (void)qdd;
    memset(K, 0, sizeof(double) * (size_t)(n * n));
    for (int b = 0; b < p->bodies; ++b)
        for (int c = 0; c < 2; ++c) {
            const int i = 2 * b + c;
            K[i + n * i] += lambda[b];
            if (b > 0) {
                const int j = i - 2;
                K[j + n * j] += lambda[b];
                K[i + n * j] -= lambda[b];
                K[j + n * i] -= lambda[b];
            }
        }
    return 0;
}

static ga_solver *pendulums(Pendulums *p)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2 * p->bodies, p->bodies, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pend_mass, pend_force, pend_phi, pend_jac, p), GA_OK);
    if (!p->no_stiffness)
        assert_int_equal(ga_set_tangents(s, pend_stiff, NULL), GA_OK);
    return s;
}

static void assert_rel(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol * fabs(want)))
        fail_msg("%.17g against %.17g: relative %.3g > %.3g", got, want,
                 fabs(got - want) / fabs(want), tol);
}

static void assert_near(double got, double want, double tol)
{
    if (!(fabs(got - want) <= tol))
        fail_msg("%.17g against %.17g: off by %.3g > %.3g", got, want, fabs(got - want), tol);
}

static void test_pendulum_rests_below_and_swings_at_sqrt_g_over_l(void **state)
{
    (void)state;
    for (int fd = 0; fd < 2; ++fd) {
        Pendulums p = {1, {1.7, 0}, {0.8, 0}, fd, 0};
        ga_solver *s = pendulums(&p);
        double q[2] = {0.3, -0.6}, lambda[1] = {0}; /* off the circle, to one side */
        assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 50), GA_OK);
        assert_true(fabs(q[0]) <= 1e-14);
        assert_rel(q[1], -0.8, 1e-14);
        assert_rel(lambda[0], 1.7 * g_acc / 0.8, 1e-13); /* f = Phi_q^T lambda: m g = L lambda */
        double w2[1], shape[2];
        assert_int_equal(ga_modes(s, 0.0, q, lambda, 1, w2, shape), GA_OK);
        /* exact tangents, or central differences of an r linear in q here: round-off */
        assert_rel(w2[0], g_acc / 0.8, 1e-13);
        /* horizontal, unit modal mass */
        assert_true(fabs(shape[1]) <= 1e-12);
        assert_rel(fabs(shape[0]), 1.0 / sqrt(1.7), 1e-12);
        /* hung upside down: an equilibrium too, unstable: omega^2 = -g/L */
        double top[2] = {0.0, 0.8};
        assert_int_equal(ga_modes(s, 0.0, top, NULL, 1, w2, NULL), GA_OK);
        assert_rel(w2[0], -g_acc / 0.8, 1e-13);
        ga_free(s);
    }
}

/* det(K - w^2 M) = 0 in the two angles: m1 m2 L1^2 L2^2 w^4
 * - (m1 + m2) m2 g L1 L2 (L1 + L2) w^2 + (m1 + m2) m2 g^2 L1 L2 = 0 */
static void double_pendulum_frequencies(const Pendulums *p, double w2[2])
{
    const double m1 = p->m[0], m2 = p->m[1], L1 = p->L[0], L2 = p->L[1];
    const double a = m1 * m2 * L1 * L1 * L2 * L2;
    const double b = -(m1 + m2) * m2 * g_acc * L1 * L2 * (L1 + L2);
    const double c = (m1 + m2) * m2 * g_acc * g_acc * L1 * L2;
    const double disc = sqrt(b * b - 4.0 * a * c);
    w2[0] = 2.0 * c / (-b + disc); /* (the small root without cancellation) */
    w2[1] = (-b + disc) / (2.0 * a);
}

static void test_double_pendulum_frequencies_in_closed_form(void **state)
{
    (void)state;
    Pendulums p = {2, {1.3, 0.6}, {0.9, 1.4}, 0, 0};
    ga_solver *s = pendulums(&p);
    double q[4] = {0.2, -0.7, -0.3, -2.0}, lambda[2];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 50), GA_OK);
    const double want_q[4] = {0.0, -0.9, 0.0, -2.3};
    for (int i = 0; i < 4; ++i)
        assert_true(fabs(q[i] - want_q[i]) <= 1e-14);
    /* the rods carry the weight below them: lambda_i L_i */
    assert_rel(lambda[0] * 0.9, (1.3 + 0.6) * g_acc, 1e-13);
    assert_rel(lambda[1] * 1.4, 0.6 * g_acc, 1e-13);
    double w2[2], want[2], shapes[8];
    double_pendulum_frequencies(&p, want);
    assert_int_equal(ga_modes(s, 0.0, q, lambda, 2, w2, shapes), GA_OK);
    assert_rel(w2[0], want[0], 1e-12);
    assert_rel(w2[1], want[1], 1e-12);
    /* the modes are M-orthonormal and horizontal */
    const double mdiag[4] = {1.3, 1.3, 0.6, 0.6};
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b) {
            double dot = 0.0;
            for (int i = 0; i < 4; ++i)
                dot += shapes[i + 4 * a] * mdiag[i] * shapes[i + 4 * b];
            assert_true(fabs(dot - (a == b)) <= 1e-12);
        }
    assert_true(fabs(shapes[1]) + fabs(shapes[3]) + fabs(shapes[5]) + fabs(shapes[7]) <= 1e-12);
    /* ga_linearize's reduced matrices give the same, and C = 0 (no velocity forces) */
    int dof = 0;
    double N[8], Mr[4], Cr[4], Kr[4];
    assert_int_equal(ga_linearize(s, 0.0, q, lambda, 2, &dof, N, Mr, Cr, Kr), GA_OK);
    assert_int_equal(dof, 2);
    const double tr = (Kr[0] * Mr[3] + Kr[3] * Mr[0] - Kr[1] * Mr[2] - Kr[2] * Mr[1]);
    const double det_m = Mr[0] * Mr[3] - Mr[1] * Mr[2], det_k = Kr[0] * Kr[3] - Kr[1] * Kr[2];
    assert_rel(tr / det_m, want[0] + want[1], 1e-12); /* sum and product of the roots */
    assert_rel(det_k / det_m, want[0] * want[1], 1e-12);
    for (int i = 0; i < 4; ++i)
        assert_true(Cr[i] == 0.0);
    /* N spans the null space of Phi_q, orthonormal */
    double J[8];
    pend_jac(0.0, q, J, &p);
    for (int k = 0; k < 2; ++k) {
        for (int r = 0; r < 2; ++r) {
            double d = 0.0;
            for (int i = 0; i < 4; ++i)
                d += J[r + 2 * i] * N[i + 4 * k];
            assert_true(fabs(d) <= 1e-14);
        }
        double nn = 0.0;
        for (int i = 0; i < 4; ++i)
            nn += N[i + 4 * k] * N[i + 4 * k];
        assert_true(fabs(nn - 1.0) <= 1e-14);
    }
    ga_free(s);
}

/* ---- a four-bar with a spring, in natural coordinates ------------------------------ */
/* Ground pivots A = (0, 0), D = (d, 0); crank AB = a, coupler BC = b, rocker DC = c; point
 * masses at B and C; a linear spring from C to the anchor E. q = (B, C). */
typedef struct {
    double d, a, b, c, mB, mC, k, l0, E[2];
} FourBar;

static const FourBar fourbar = {4.0, 1.0, 3.5, 2.5, 2.0, 1.5, 200.0, 1.0, {1.0, 4.0}};

static int fb_mass(double t, const double *q, double *M, void *u)
{
    const FourBar *p = u;
    (void)t, (void)q;
    memset(M, 0, 16 * sizeof(double));
    M[0] = M[5] = p->mB;
    M[10] = M[15] = p->mC;
    return 0;
}

static int fb_force(double t, const double *q, const double *v, double *f, void *u)
{
    const FourBar *p = u;
    (void)t, (void)v;
    const double ex = q[2] - p->E[0], ey = q[3] - p->E[1], l = sqrt(ex * ex + ey * ey);
    const double s = -p->k * (l - p->l0) / l;
    f[0] = 0.0;
    f[1] = -p->mB * g_acc;
    f[2] = s * ex;
    f[3] = s * ey - p->mC * g_acc;
    return 0;
}

static int fb_phi(double t, const double *q, double *phi, void *u)
{
    const FourBar *p = u;
    (void)t;
    const double bx = q[0], by = q[1], cx = q[2], cy = q[3];
    phi[0] = 0.5 * (bx * bx + by * by - p->a * p->a);
    phi[1] = 0.5 * ((cx - bx) * (cx - bx) + (cy - by) * (cy - by) - p->b * p->b);
    phi[2] = 0.5 * ((cx - p->d) * (cx - p->d) + cy * cy - p->c * p->c);
    return 0;
}

static int fb_jac(double t, const double *q, double *J, void *u)
{
    const FourBar *p = u;
    (void)t;
    const double bx = q[0], by = q[1], cx = q[2], cy = q[3];
    memset(J, 0, 12 * sizeof(double));
    J[0 + 3 * 0] = bx;
    J[0 + 3 * 1] = by;
    J[1 + 3 * 0] = -(cx - bx);
    J[1 + 3 * 1] = -(cy - by);
    J[1 + 3 * 2] = cx - bx;
    J[1 + 3 * 3] = cy - by;
    J[2 + 3 * 2] = cx - p->d;
    J[2 + 3 * 3] = cy;
    return 0;
}

/* The four-bar in its crank angle theta: B, C and their first two derivatives. */
typedef struct {
    double B[2], C[2], dB[2], dC[2], ddB[2], ddC[2];
} Pose;

static void solve2(const double r0[2], const double r1[2], const double rhs[2], double x[2])
{
    const double det = r0[0] * r1[1] - r0[1] * r1[0];
    x[0] = (rhs[0] * r1[1] - r0[1] * rhs[1]) / det;
    x[1] = (r0[0] * rhs[1] - rhs[0] * r1[0]) / det;
}

static Pose pose_at(const FourBar *p, double th)
{
    Pose P;
    P.B[0] = p->a * cos(th);
    P.B[1] = p->a * sin(th);
    P.dB[0] = -P.B[1];
    P.dB[1] = P.B[0];
    P.ddB[0] = -P.B[0];
    P.ddB[1] = -P.B[1];
    /* C: the circles |C - B| = b, |C - D| = c meet; the branch left of B -> D (above) */
    const double dx = p->d - P.B[0], dy = -P.B[1], dist = sqrt(dx * dx + dy * dy);
    const double x = (p->b * p->b - p->c * p->c + dist * dist) / (2.0 * dist);
    const double h = sqrt(p->b * p->b - x * x);
    P.C[0] = P.B[0] + (x * dx - h * dy) / dist;
    P.C[1] = P.B[1] + (x * dy + h * dx) / dist;
    /* (C - B).(C' - B') = 0, (C - D).C' = 0, and their derivatives for C'' */
    const double u[2] = {P.C[0] - P.B[0], P.C[1] - P.B[1]};
    const double w[2] = {P.C[0] - p->d, P.C[1]};
    const double r1[2] = {u[0] * P.dB[0] + u[1] * P.dB[1], 0.0};
    solve2(u, w, r1, P.dC);
    const double e[2] = {P.dC[0] - P.dB[0], P.dC[1] - P.dB[1]};
    const double r2[2] = {u[0] * P.ddB[0] + u[1] * P.ddB[1] - (e[0] * e[0] + e[1] * e[1]),
                          -(P.dC[0] * P.dC[0] + P.dC[1] * P.dC[1])};
    solve2(u, w, r2, P.ddC);
    return P;
}

/* V = g (mB yB + mC yC) + k (l - l0)^2 / 2: V'(theta), V''(theta) */
static void potential_derivatives(const FourBar *p, const Pose *P, double *V1, double *V2)
{
    const double ex = P->C[0] - p->E[0], ey = P->C[1] - p->E[1], l = sqrt(ex * ex + ey * ey);
    const double l1 = (ex * P->dC[0] + ey * P->dC[1]) / l;
    const double l2 =
        (P->dC[0] * P->dC[0] + P->dC[1] * P->dC[1] + ex * P->ddC[0] + ey * P->ddC[1]) / l -
        l1 * l1 / l;
    *V1 = g_acc * (p->mB * P->dB[1] + p->mC * P->dC[1]) + p->k * (l - p->l0) * l1;
    *V2 = g_acc * (p->mB * P->ddB[1] + p->mC * P->ddC[1]) + p->k * (l1 * l1 + (l - p->l0) * l2);
}

static ga_solver *fourbar_solver(FourBar *p)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(4, 3, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, fb_mass, fb_force, fb_phi, fb_jac, p), GA_OK);
    return s;
}

/* By hand: Newton on V'(theta) = 0 from th, and omega^2 = V'' / m_eff there. */
static double hand_equilibrium(const FourBar *p, double th, double *w2)
{
    double V1, V2;
    for (int it = 0; it < 60; ++it) {
        const Pose P = pose_at(p, th);
        potential_derivatives(p, &P, &V1, &V2);
        th -= V1 / V2;
    }
    const Pose P = pose_at(p, th);
    potential_derivatives(p, &P, &V1, &V2);
    assert_true(fabs(V1) <= 1e-11);
    const double m_eff = p->mB * (P.dB[0] * P.dB[0] + P.dB[1] * P.dB[1]) +
                         p->mC * (P.dC[0] * P.dC[0] + P.dC[1] * P.dC[1]);
    *w2 = V2 / m_eff;
    return th;
}

static void test_fourbar_with_a_spring_against_its_minimal_coordinate(void **state)
{
    (void)state;
    FourBar p = fourbar;
    double want_w2;
    const double th = hand_equilibrium(&p, 1.2, &want_w2);
    const Pose P = pose_at(&p, th);
    assert_true(want_w2 > 0.0); /* a stable rest */

    /* galpha from the pose 0.15 rad away, off the constraints by a few millimetres */
    ga_solver *s = fourbar_solver(&p);
    const Pose S = pose_at(&p, th + 0.15);
    double q[4] = {S.B[0] + 0.003, S.B[1] - 0.002, S.C[0] + 0.004, S.C[1]}, lambda[3];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_OK);
    assert_true(fabs(q[0] - P.B[0]) <= 1e-12 && fabs(q[1] - P.B[1]) <= 1e-12);
    assert_true(fabs(q[2] - P.C[0]) <= 1e-12 && fabs(q[3] - P.C[1]) <= 1e-12);
    /* a root: the residuals at round-off, by the callbacks themselves */
    double f[4], J[12], phi[3], r[4];
    fb_force(0.0, q, NULL, f, &p);
    fb_jac(0.0, q, J, &p);
    fb_phi(0.0, q, phi, &p);
    for (int i = 0; i < 4; ++i) {
        r[i] = -f[i];
        for (int k = 0; k < 3; ++k)
            r[i] += J[k + 3 * i] * lambda[k];
        assert_true(fabs(r[i]) <= 1e-12 * 200.0);
    }
    for (int k = 0; k < 3; ++k)
        assert_true(fabs(phi[k]) <= 1e-15);
    /* K_t by central differences here (no callback): their error, not round-off (1e-11) */
    double w2[1];
    assert_int_equal(ga_modes(s, 0.0, q, lambda, 1, w2, NULL), GA_OK);
    assert_rel(w2[0], want_w2, 1e-10);
    /* from theta = 1 Newton finds another rest, unstable: the hand's from galpha's angle */
    const Pose U = pose_at(&p, 1.0);
    double qu[4] = {U.B[0], U.B[1], U.C[0], U.C[1]}, want_u;
    assert_int_equal(ga_static_equilibrium(s, 0.0, qu, NULL, 1e-13, 50), GA_OK);
    const double th_u = hand_equilibrium(&p, atan2(qu[1], qu[0]), &want_u);
    const Pose PU = pose_at(&p, th_u);
    assert_true(fabs(qu[0] - PU.B[0]) <= 1e-12 && fabs(qu[3] - PU.C[1]) <= 1e-12);
    assert_true(fabs(th_u - th) > 0.1 && want_u < 0.0);
    assert_int_equal(ga_modes(s, 0.0, qu, NULL, 1, w2, NULL), GA_OK);
    assert_rel(w2[0], want_u, 1e-10);
    ga_free(s);
}

/* ---- consistency with dynamics ------------------------------------------------------ */
static void test_a_run_started_in_the_equilibrium_stays_there(void **state)
{
    (void)state;
    FourBar p = fourbar;
    ga_solver *s = fourbar_solver(&p);
    double w2;
    const Pose S = pose_at(&p, hand_equilibrium(&p, 1.2, &w2) + 0.1); /* near the stable rest */
    double q[4] = {S.B[0], S.B[1], S.C[0], S.C[1]}, lambda[3];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_OK);
    const double v0[4] = {0, 0, 0, 0};
    assert_int_equal(ga_init(s, 0.0, q, v0), GA_OK);
    for (int i = 0; i < 1000; ++i)
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
    double qt[4], vt[4], lt[3];
    ga_get_q(s, qt);
    ga_get_v(s, vt);
    ga_get_lambda(s, lt);
    for (int i = 0; i < 4; ++i) {
        assert_near(qt[i], q[i], 1e-13);
        /* (round-off: 1 000 steps with multipliers of 400 to 1e-16) */
        assert_near(vt[i], 0.0, 1e-11);
    }
    for (int k = 0; k < 3; ++k)
        assert_true(fabs(lt[k] - lambda[k]) <= 1e-10 * fabs(lambda[k]) + 1e-12);
    ga_free(s);
}

static int crossing(double t, const double *q, const double *v, const double *lambda, double *g,
                    void *u)
{
    (void)t, (void)v, (void)lambda, (void)u;
    g[0] = q[0];
    return 0;
}

static void test_free_vibration_has_the_computed_period(void **state)
{
    (void)state;
    Pendulums p = {2, {1.3, 0.6}, {0.9, 1.4}, 0, 0};
    ga_solver *s = pendulums(&p);
    double q[4] = {0.1, -0.8, 0.2, -2.2}, lambda[2], w2[2], shapes[8];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_OK);
    assert_int_equal(ga_modes(s, 0.0, q, lambda, 2, w2, shapes), GA_OK);
    const double period = 2.0 * M_PI / sqrt(w2[0]);
    /* the lowest mode at an amplitude of 1e-5 (amplitude effects ~1e-10), on the circles */
    double q0[4];
    for (int i = 0; i < 4; ++i)
        q0[i] = q[i] + 1e-5 * shapes[i];
    const double v0[4] = {0, 0, 0, 0};
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    const int terminal[1] = {0}, dir[1] = {GA_EVENT_BOTH};
    assert_int_equal(ga_set_events(s, 1, crossing, dir, terminal, 0), GA_OK);
    const double h = period / 2000.0;
    double first = -1.0, last = -1.0;
    int crossings = 0;
    for (int i = 0; i < 2000 * 5; ++i) {
        const int st = ga_step(s, h);
        assert_true(st == GA_OK);
        int count = 0;
        ga_get_event_count(s, &count);
        for (int e = 0; e < count; ++e) {
            double te;
            ga_get_event(s, e, &te, NULL, NULL);
            if (first < 0.0)
                first = te;
            last = te;
            ++crossings;
        }
    }
    assert_true(crossings >= 9);
    const double measured = 2.0 * (last - first) / (crossings - 1);
    assert_rel(measured, period, 1e-5); /* (8.3e-7: the method's period error at h = T/2000) */
    ga_free(s);
}

/* ---- damped and non-conservative modes ------------------------------------------------ */
/* The pendulum with a viscous damper c on its bob: m s^2 + c s + m g / L = 0 in its angle. */
typedef struct {
    double m, L, c;
} Damped;

static int damped_mass(double t, const double *q, double *M, void *u)
{
    const Damped *p = u;
    (void)t, (void)q;
    M[0] = M[3] = p->m;
    M[1] = M[2] = 0.0;
    return 0;
}

static int damped_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Damped *p = u;
    (void)t, (void)q;
    f[0] = -p->c * v[0];
    f[1] = -p->m * g_acc - p->c * v[1];
    return 0;
}

static int circle(double t, const double *q, double *phi, void *u)
{
    const Damped *p = u;
    (void)t;
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p->L * p->L);
    return 0;
}

static int circle_jacobian(double t, const double *q, double *J, void *u)
{
    (void)t, (void)u;
    J[0] = q[0];
    J[1] = q[1];
    return 0;
}

static void test_damped_pendulum_roots_in_closed_form(void **state)
{
    (void)state;
    for (int over = 0; over < 2; ++over) {
        Damped p = {1.5, 0.7, over ? 30.0 : 0.8};
        ga_solver *s = NULL;
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(
            ga_set_callbacks(s, damped_mass, damped_force, circle, circle_jacobian, &p), GA_OK);
        const double q[2] = {0.0, -0.7};
        double re[2], im[2], sr[4], si[4];
        assert_int_equal(ga_modes_damped(s, 0.0, q, NULL, 2, re, im, sr, si), GA_OK);
        const double k = p.m * g_acc / p.L, disc = p.c * p.c - 4.0 * p.m * k;
        if (!over) { /* a decaying oscillation: -c/2m +- i sqrt(4 m k - c^2)/2m */
            assert_rel(re[0], -p.c / (2.0 * p.m), 1e-13);
            assert_rel(im[0], sqrt(-disc) / (2.0 * p.m), 1e-13);
            assert_true(re[1] == re[0] && im[1] == -im[0]);
        } else { /* overdamped: two real roots, the slow one first */
            assert_rel(re[0], (-p.c + sqrt(disc)) / (2.0 * p.m), 1e-13);
            assert_rel(re[1], (-p.c - sqrt(disc)) / (2.0 * p.m), 1e-13);
            assert_true(im[0] == 0.0 && im[1] == 0.0);
        }
        /* the shape: the horizontal direction, its largest entry 1 */
        assert_true(fabs(sr[0] - 1.0) <= 1e-12 && fabs(sr[1]) <= 1e-12 && fabs(si[0]) <= 1e-12);
        ga_free(s);
    }
}

/* f = -K q with K = [2 1; -1 2] (a circulatory force): s^2 = -(2 +- i), one root with
 * Re s > 0, flutter; ga_modes refuses (not symmetric), ga_modes_damped says it. */
static int circulatory(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -(2.0 * q[0] + q[1]);
    f[1] = -(-q[0] + 2.0 * q[1]);
    return 0;
}

static void test_circulatory_force_flutters(void **state)
{
    (void)state;
    Damped unit = {1.0, 1.0, 0.0}; /* (its mass: the identity) */
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, damped_mass, circulatory, NULL, NULL, &unit), GA_OK);
    const double q[2] = {0.0, 0.0};
    double re[4], im[4], w2[2];
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 2, w2, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes_damped(s, 0.0, q, NULL, 4, re, im, NULL, NULL), GA_OK);
    /* the roots of s^4 + 4 s^2 + 5 = 0: s = +-sqrt(-(2 +- i)), all of modulus 5^(1/4) (K_t and
     * C_t by differences of forces linear in q and v: round-off) */
    double complex want[4];
    want[0] = csqrt(-(2.0 + I));
    want[1] = -want[0];
    want[2] = csqrt(-(2.0 - I));
    want[3] = -want[2];
    int flutter = 0;
    for (int k = 0; k < 4; ++k) {
        double best = 1e300;
        for (int j = 0; j < 4; ++j)
            best = fmin(best, cabs(re[k] + I * im[k] - want[j]));
        assert_true(best <= 1e-13);
        assert_rel(cabs(re[k] + I * im[k]), pow(5.0, 0.25), 1e-13);
        flutter += re[k] > 1e-6;
    }
    assert_int_equal(flutter, 2); /* a conjugate pair grows */
    assert_int_equal(ga_modes_damped(s, 0.0, q, NULL, 5, re, im, NULL, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "(4 modes)"));
    ga_free(s);
}

/* ---- the static path through a limit point: the shallow two-bar (von Mises) truss ------ */
/* Bars from (-a, 0) and (a, 0) to the apex q = (x, y), axial stiffness EA / L0 each, the
 * apex on a vertical rail (x = 0, a constraint) under the load mu downwards. Equilibrium in
 * closed form: mu(y) = 2 EA (L0 - L) y / (L0 L), L = sqrt(a^2 + y^2). */
typedef struct {
    double a, h, EA, mu;
    int points;
    double worst, max_mu, last_y, min_y_step;
    int monotone;
    int fail; /* the force callback fails below y = 0.1 */
} Truss;

static double truss_load(const Truss *p, double y)
{
    const double L0 = sqrt(p->a * p->a + p->h * p->h), L = sqrt(p->a * p->a + y * y);
    return 2.0 * p->EA * (L0 - L) * y / (L0 * L);
}

static int truss_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = M[3] = 1.0;
    M[1] = M[2] = 0.0;
    return 0;
}

static int truss_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Truss *p = u;
    (void)t, (void)v;
    const double L0 = sqrt(p->a * p->a + p->h * p->h);
    if (p->fail && q[1] < 0.1)
        return -1;
    f[0] = 0.0;
    f[1] = -p->mu;
    for (int side = -1; side <= 1; side += 2) {
        const double dx = q[0] - side * p->a, dy = q[1], L = sqrt(dx * dx + dy * dy);
        const double N = p->EA * (L - L0) / L0; /* tension */
        f[0] -= N * dx / L;
        f[1] -= N * dy / L;
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

static int truss_point(double load, const double *q, const double *lambda, void *u)
{
    Truss *p = u;
    (void)lambda;
    p->points++;
    p->worst = fmax(p->worst, fabs(load - truss_load(p, q[1])) + fabs(q[0]));
    if (q[1] > 0.0) /* (the snap's limit; past the inverted rest the load rises again) */
        p->max_mu = fmax(p->max_mu, load);
    if (!(q[1] < p->last_y))
        p->monotone = 0;
    p->last_y = q[1];
    return q[1] < -1.5 * p->h; /* past the inverted rest: enough */
}

static ga_solver *truss_solver(Truss *p)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, truss_mass, truss_force, rail, rail_jacobian, p), GA_OK);
    return s;
}

static void test_truss_snaps_through_along_its_closed_curve(void **state)
{
    (void)state;
    Truss p = {1.0, 0.2, 1000.0, 0.0, 0, 0.0, 0.0, 0.2, 0.0, 1, 0};
    /* the limit load from the closed form (golden section on mu(y), 0 < y < h) */
    double lo = 0.0, hi = p.h;
    for (int it = 0; it < 200; ++it) {
        const double m1 = hi - 0.618033988749895 * (hi - lo),
                     m2 = lo + 0.618033988749895 * (hi - lo);
        if (truss_load(&p, m1) < truss_load(&p, m2))
            lo = m1;
        else
            hi = m2;
    }
    const double mu_limit = truss_load(&p, 0.5 * (lo + hi));
    ga_solver *s = truss_solver(&p);
    double q[2] = {0.0, 0.2}, lambda[1];
    const int st = ga_static_path(s, 0.0, &p.mu, q, lambda, 0.05, 5000, 1e-12, truss_point, &p);
    assert_int_equal(st, GA_STOPPED);
    print_message("  %d points, worst |mu - mu(y)| + |x| %.3g, limit %.6f (closed %.6f)\n",
                  p.points, p.worst, p.max_mu, mu_limit);
    assert_true(p.points > 100);
    assert_true(p.worst <= 1e-10 * mu_limit);
    /* through the limit point and down the unstable branch: the apex only goes down */
    assert_true(p.monotone);
    assert_true(p.max_mu <= mu_limit * (1.0 + 1e-12) && p.max_mu >= 0.99 * mu_limit);
    /* the last point is left in q, lambda and the load */
    assert_true(q[1] < -1.5 * p.h && fabs(p.mu - truss_load(&p, q[1])) <= 1e-10 * mu_limit);
    assert_true(fabs(lambda[0]) <= 1e-10 * mu_limit); /* the rail carries nothing: symmetry */
    /* ga_modes along it: stable before the limit, unstable after */
    double w2[1];
    double before[2] = {0.0, 0.18};
    p.mu = truss_load(&p, 0.18);
    assert_int_equal(ga_modes(s, 0.0, before, NULL, 1, w2, NULL), GA_OK);
    assert_true(w2[0] > 0.0);
    double after[2] = {0.0, 0.05};
    p.mu = truss_load(&p, 0.05);
    assert_int_equal(ga_modes(s, 0.0, after, NULL, 1, w2, NULL), GA_OK);
    assert_true(w2[0] < 0.0);
    ga_free(s);
}

/* Load stepping without arc length: each load from the last rest, up to the limit; past it
 * Newton finds nothing in reach and says so, q untouched. Then ga_static_path's refusals. */
static void test_load_stepping_stops_at_the_limit_point(void **state)
{
    (void)state;
    Truss p = {1.0, 0.2, 1000.0, 0.0, 0, 0.0, 0.0, 0.2, 0.0, 1, 0};
    ga_solver *s = truss_solver(&p);
    double q[2] = {0.0, 0.2}, lambda[1];
    for (int k = 0; k <= 11; ++k) { /* up to 2.75, below the limit 2.9605 */
        p.mu = 0.25 * k;
        assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 50), GA_OK);
        assert_true(fabs(truss_load(&p, q[1]) - p.mu) <= 1e-12 * 3.0);
    }
    const double kept[2] = {q[0], q[1]};
    p.mu = 3.0;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 50), GA_ERR_NEWTON);
    assert_non_null(strstr(ga_last_error(s), "limit point"));
    assert_true(q[0] == kept[0] && q[1] == kept[1]);
    /* the path's arguments, each refused with nothing changed */
    double load = 0.0, start[2] = {0.0, 0.2};
    assert_int_equal(ga_static_path(s, 0.0, NULL, start, NULL, 0.05, 10, 1e-12, NULL, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_static_path(s, 0.0, &load, NULL, NULL, 0.05, 10, 1e-12, NULL, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_static_path(s, 0.0, &load, start, NULL, 0.0, 10, 1e-12, NULL, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_static_path(s, 0.0, &load, start, NULL, NAN, 10, 1e-12, NULL, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_static_path(s, 0.0, &load, start, NULL, 0.05, 0, 1e-12, NULL, NULL),
                     GA_ERR_ARG);
    assert_int_equal(ga_static_path(s, 0.0, &load, start, NULL, 0.05, 10, 0.0, NULL, NULL),
                     GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "tol = 0"));
    assert_true(load == 0.0 && start[0] == 0.0 && start[1] == 0.2);
    /* without a callback: max_points points, downwards (ds < 0: the load decreasing first,
     * the apex rising), the last one left in q and the load */
    p.mu = 0.0;
    assert_int_equal(ga_static_path(s, 0.0, &p.mu, start, NULL, -0.05, 20, 1e-12, NULL, NULL),
                     GA_OK);
    assert_true(p.mu < 0.0 && start[1] > 0.2);
    assert_true(fabs(truss_load(&p, start[1]) - p.mu) <= 1e-12 * 3.0);
    /* a callback that fails on the way: its status, the last point reached kept */
    p.fail = 1;
    p.mu = 0.0;
    start[0] = 0.0;
    start[1] = 0.2;
    assert_int_equal(ga_static_path(s, 0.0, &p.mu, start, NULL, 0.05, 5000, 1e-12, NULL, NULL),
                     GA_ERR_CALLBACK);
    assert_true(start[1] >= 0.1 && start[1] < 0.2);
    assert_true(fabs(truss_load(&p, start[1]) - p.mu) <= 1e-12 * 3.0);
    ga_free(s);
}

/* ---- refusals ---------------------------------------------------------------------- */
/* one coordinate, f = -(1 + x^2) (never zero), or a free mass pushed (no stiffness) */
typedef struct {
    int kind; /* 0 no root, 1 free mass, 2 follower force */
} Odd;

static int odd_mass(double t, const double *q, double *M, void *u)
{
    const Odd *o = u;
    (void)t, (void)q;
    const int n = o->kind == 2 ? 2 : 1;
    memset(M, 0, sizeof(double) * (size_t)(n * n));
    for (int i = 0; i < n; ++i)
        M[i + n * i] = 1.0;
    return 0;
}

static int odd_force(double t, const double *q, const double *v, double *f, void *u)
{
    const Odd *o = u;
    (void)t, (void)v;
    if (o->kind == 0)
        f[0] = -(1.0 + q[0] * q[0]);
    else if (o->kind == 1)
        f[0] = 1.0;
    else { /* springs and a circulatory force: K not symmetric */
        f[0] = -q[0] + 0.5 * q[1];
        f[1] = -q[1];
    }
    return 0;
}

static void test_no_equilibrium_a_free_motion_and_a_follower_force_are_refused(void **state)
{
    (void)state;
    for (int kind = 0; kind < 3; ++kind) {
        Odd o = {kind};
        const int n = kind == 2 ? 2 : 1;
        ga_solver *s = NULL;
        assert_int_equal(ga_create(n, 0, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, odd_mass, odd_force, NULL, NULL, &o), GA_OK);
        double q[2] = {0.25, 0.5};
        const int st = ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 40);
        if (kind == 0) {
            assert_int_equal(st, GA_ERR_NEWTON);
            assert_non_null(strstr(ga_last_error(s), "no equilibrium"));
        } else if (kind == 1) {
            assert_int_equal(st, GA_ERR_SINGULAR);
            assert_non_null(strstr(ga_last_error(s), "singular"));
        } else {
            assert_int_equal(st, GA_OK); /* it has one, at 0 */
            assert_true(fabs(q[0]) + fabs(q[1]) <= 1e-15);
            double w2[2];
            assert_int_equal(ga_modes(s, 0.0, q, NULL, 2, w2, NULL), GA_ERR_ARG);
            assert_non_null(strstr(ga_last_error(s), "not symmetric"));
            ga_free(s);
            continue;
        }
        /* nothing written */
        assert_true(q[0] == 0.25 && q[1] == 0.5);
        ga_free(s);
    }
}

static void test_modes_refuse_what_is_no_equilibrium(void **state)
{
    (void)state;
    Pendulums p = {1, {1.0, 0}, {1.0, 0}, 0, 0};
    ga_solver *s = pendulums(&p);
    double w2[1] = {-7.0};
    const double tilted[2] = {sin(0.3), -cos(0.3)}, off[2] = {0.0, -1.01};
    assert_int_equal(ga_modes(s, 0.0, tilted, NULL, 1, w2, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "not an equilibrium"));
    assert_int_equal(ga_modes(s, 0.0, off, NULL, 1, w2, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "off the constraints"));
    const double below[2] = {0.0, -1.0}, wrong_lambda[1] = {3.0};
    assert_int_equal(ga_modes(s, 0.0, below, wrong_lambda, 1, w2, NULL), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "does not balance"));
    assert_int_equal(ga_modes(s, 0.0, below, NULL, 2, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "1 degrees of freedom"));
    assert_true(w2[0] == -7.0);
    /* linearize: too small a buffer says how large, and writes nothing */
    int dof = -1;
    double N[2] = {5, 5};
    assert_int_equal(ga_linearize(s, 0.0, below, NULL, 0, &dof, N, NULL, NULL, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "1 degrees of freedom, max_dof = 0"));
    assert_true(dof == -1 && N[0] == 5 && N[1] == 5);
    ga_free(s);
}

/* a point held by two constraints in the plane: nothing left to move */
static int lock_phi(double t, const double *q, double *phi, void *u)
{
    (void)t, (void)u;
    phi[0] = q[0] - 1.0;
    phi[1] = q[1] + 2.0;
    return 0;
}

static int lock_jac(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    J[0] = 1.0, J[1] = 0.0, J[2] = 0.0, J[3] = 1.0;
    return 0;
}

static void test_locked_mechanism(void **state)
{
    (void)state;
    Pendulums p = {1, {1.0, 0}, {1.0, 0}, 1, 0}; /* (its mass and weight) */
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 2, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pend_mass, pend_force, lock_phi, lock_jac, &p), GA_OK);
    double q[2] = {0.0, 0.0}, lambda[2];
    /* the statics is the constraints' root, the multipliers carry the weight */
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 20), GA_OK);
    assert_true(q[0] == 1.0 && q[1] == -2.0);
    assert_true(fabs(lambda[0]) <= 1e-15 && fabs(lambda[1] + g_acc) <= 1e-14);
    double w2[1];
    assert_int_equal(ga_modes(s, 0.0, q, lambda, 1, w2, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "lock the mechanism"));
    ga_free(s);
}

static void test_arguments_state_and_callbacks(void **state)
{
    (void)state;
    Pendulums p = {1, {1.0, 0}, {1.0, 0}, 0, 0};
    ga_solver *s = NULL;
    double q[2] = {0.1, -0.9}, lambda[1] = {42.0}, w2[1];
    int dof;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    /* no callbacks yet */
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 20), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "ga_set_callbacks"));
    assert_int_equal(ga_linearize(s, 0.0, q, NULL, 1, &dof, NULL, NULL, NULL, NULL), GA_ERR_STATE);
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 1, w2, NULL), GA_ERR_STATE);
    assert_int_equal(ga_set_callbacks(s, pend_mass, pend_force, pend_phi, pend_jac, &p), GA_OK);
    assert_int_equal(ga_static_equilibrium(NULL, 0.0, q, lambda, 1e-12, 20), GA_ERR_ARG);
    assert_int_equal(ga_static_equilibrium(s, 0.0, NULL, lambda, 1e-12, 20), GA_ERR_ARG);
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 0.0, 20), GA_ERR_ARG);
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, NAN, 20), GA_ERR_ARG);
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "max_iter = 0"));
    assert_int_equal(ga_static_equilibrium(s, INFINITY, q, lambda, 1e-12, 20), GA_ERR_ARG);
    double bad[2] = {NAN, -1.0};
    assert_int_equal(ga_static_equilibrium(s, 0.0, bad, lambda, 1e-12, 20), GA_ERR_ARG);
    assert_int_equal(ga_linearize(s, 0.0, NULL, NULL, 1, &dof, NULL, NULL, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_linearize(s, 0.0, q, NULL, 1, NULL, NULL, NULL, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_linearize(s, 0.0, bad, NULL, 1, &dof, NULL, NULL, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 0, w2, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 1, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_modes(s, 0.0, bad, NULL, 1, w2, NULL), GA_ERR_ARG);
    assert_true(q[0] == 0.1 && q[1] == -0.9 && lambda[0] == 42.0);
    /* a failing callback: its status, nothing written */
    p.fail_force = 1;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-12, 20), GA_ERR_CALLBACK);
    assert_non_null(strstr(ga_last_error(s), "force"));
    assert_int_equal(ga_linearize(s, 0.0, q, NULL, 1, &dof, NULL, NULL, NULL, NULL),
                     GA_ERR_CALLBACK);
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 1, w2, NULL), GA_ERR_CALLBACK);
    assert_true(q[0] == 0.1 && q[1] == -0.9 && lambda[0] == 42.0);
    p.fail_force = 0;
    ga_free(s);
}

static void test_a_running_solver_is_left_as_it_was(void **state)
{
    (void)state;
    Pendulums p = {2, {1.3, 0.6}, {0.9, 1.4}, 1, 0};
    ga_solver *s = pendulums(&p);
    const double q0[4] = {0.9 * sin(0.4), -0.9 * cos(0.4), 0.9 * sin(0.4), -0.9 * cos(0.4) - 1.4};
    const double v0[4] = {0, 0, 0, 0};
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    for (int i = 0; i < 10; ++i)
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double *before = malloc(len * sizeof(double)), *after = malloc(len * sizeof(double));
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    double q[4] = {0.1, -0.8, 0.2, -2.2}, lambda[2], w2[2];
    int dof;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_OK);
    assert_int_equal(ga_modes(s, 0.0, q, lambda, 2, w2, NULL), GA_OK);
    assert_int_equal(ga_linearize(s, 0.0, q, lambda, 2, &dof, NULL, NULL, NULL, NULL), GA_OK);
    p.fail_force = 1;
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, lambda, 1e-13, 50), GA_ERR_CALLBACK);
    p.fail_force = 0;
    assert_int_equal(ga_get_state(s, after, len), GA_OK);
    assert_memory_equal(before, after, len * sizeof(double));
    /* and it steps on as a twin that was never asked */
    ga_solver *twin = pendulums(&p);
    assert_int_equal(ga_init(twin, 0.0, q0, v0), GA_OK);
    for (int i = 0; i < 10; ++i)
        assert_int_equal(ga_step(twin, 1e-3), GA_OK);
    for (int i = 0; i < 10; ++i) {
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
        assert_int_equal(ga_step(twin, 1e-3), GA_OK);
    }
    double a[4], b[4];
    ga_get_q(s, a);
    ga_get_q(twin, b);
    assert_memory_equal(a, b, sizeof a);
    free(before);
    free(after);
    ga_free(twin);
    ga_free(s);
}

static int fo_force(double t, const double *q, const double *v, const double *y, double *f, void *u)
{
    (void)y;
    return pend_force(t, q, v, f, u);
}

static int fo_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                   void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    ydot[0] = -y[0];
    return 0;
}

/* ---- first-order states: a pendulum pushed by an actuator state ------------------------ */
/* f = (y - c vx, -m g - c vy), y' = -y / tau + k x + u0 (no_root: y' = 1 + y^2) */
static const double act_tau = 0.5, act_k = 2.0, act_u0 = 3.0, act_c = 0.3;
static int act_no_root = 0;

static int act_force(double t, const double *q, const double *v, const double *y, double *f,
                     void *u)
{
    const Pendulums *p = u;
    (void)t, (void)q;
    f[0] = y[0] - act_c * v[0];
    f[1] = -p->m[0] * g_acc - act_c * v[1];
    return 0;
}

static int act_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                    void *u)
{
    (void)t, (void)v, (void)u;
    ydot[0] = act_no_root ? 1.0 + y[0] * y[0] : -y[0] / act_tau + act_k * q[0] + act_u0;
    return 0;
}

static int act_damping(double t, const double *q, const double *v, double *C, void *u)
{
    (void)t, (void)q, (void)v, (void)u;
    C[0] = C[3] = act_c;
    C[1] = C[2] = 0.0;
    return 0;
}

static int act_coupling(double t, const double *q, const double *v, const double *y,
                        double *g_q, double *g_v, double *g_y, double *f_y, void *u)
{
    (void)t, (void)q, (void)v, (void)y, (void)u;
    g_q[0] = act_k; /* (r x n, column-major) */
    g_q[1] = 0.0;
    g_v[0] = g_v[1] = 0.0;
    g_y[0] = -1.0 / act_tau;
    f_y[0] = 1.0; /* (n x r) */
    f_y[1] = 0.0;
    return 0;
}

static double trace_of_power(const double *A, int d, int power)
{
    double P[9], Q[9];
    memcpy(P, A, sizeof(double) * (size_t)(d * d));
    for (int k = 1; k < power; ++k) {
        for (int i = 0; i < d; ++i)
            for (int j = 0; j < d; ++j) {
                Q[i + d * j] = 0.0;
                for (int l = 0; l < d; ++l)
                    Q[i + d * j] += P[i + d * l] * A[l + d * j];
            }
        memcpy(P, Q, sizeof(double) * (size_t)(d * d));
    }
    double tr = 0.0;
    for (int i = 0; i < d; ++i)
        tr += P[i + d * i];
    return tr;
}

/* Oracle in the angle theta: m L^2 theta'' = y L cos(theta) - m g L sin(theta) - c L^2
 * theta', y' = -y / tau + k L sin(theta) + u0; at rest tan(theta) = y / (m g) with
 * y = tau (k L sin(theta) + u0), by a scalar Newton here; the linearization's 3 x 3 matrix in
 * (theta, theta', y) is similar to galpha's in (z, z', y) (z = +-L theta), so the traces of
 * its powers agree. */
static void test_an_actuated_pendulum_rests_and_its_state_space_is_the_closed_form(void **state)
{
    (void)state;
    Pendulums p = {1, {1.3, 0}, {0.9, 0}, 0, 0};
    const double m = p.m[0], L = p.L[0];
    ga_solver *s = pendulums(&p);
    assert_int_equal(ga_set_first_order(s, 1, act_force, act_rate), GA_OK);
    double th = 0.0;
    for (int it = 0; it < 50; ++it) {
        const double F = act_tau * (act_k * L * sin(th) + act_u0) * cos(th) - m * g_acc * sin(th);
        const double dF = act_tau * act_k * L * cos(th) * cos(th) -
                          act_tau * (act_k * L * sin(th) + act_u0) * sin(th) - m * g_acc * cos(th);
        th -= F / dF;
    }
    const double ystar = act_tau * (act_k * L * sin(th) + act_u0);
    double q[2] = {0.1, -0.8}, y[1] = {0.0}, lambda[1];
    assert_int_equal(ga_static_equilibrium_y(s, 0.0, q, y, lambda, 1e-13, 50), GA_OK);
    assert_near(q[0], L * sin(th), 1e-13);
    assert_near(q[1], -L * cos(th), 1e-13);
    assert_rel(y[0], ystar, 1e-12);
    assert_rel(lambda[0], m * g_acc / (L * cos(th)), 1e-12);
    double A[9], N[2];
    int dim = 0;
    const double c = cos(th), sn = sin(th);
    const double B[9] = {0.0, -(ystar * sn + m * g_acc * c) / (m * L), act_k * L * c,
                         1.0, -act_c / m, 0.0,
                         0.0, c / (m * L), -1.0 / act_tau}; /* column-major */
    /* C_t and the coupling blocks by central differences: their round-off is eps |f| over
     * the step (6e-6), 1e-10 of these entries; then by their callbacks, to round-off */
    for (int exact = 0; exact < 2; ++exact) {
        if (exact) {
            assert_int_equal(ga_set_tangents(s, pend_stiff, act_damping), GA_OK);
            assert_int_equal(ga_set_coupling(s, act_coupling), GA_OK);
        }
        assert_int_equal(ga_state_space(s, 0.0, q, y, lambda, 3, &dim, N, A), GA_OK);
        assert_int_equal(dim, 3);
        for (int k = 1; k <= 3; ++k) {
            printf("  tr A^%d: %.15g against %.15g (%s)\n", k, trace_of_power(A, 3, k),
                   trace_of_power(B, 3, k), exact ? "callbacks" : "differences");
            assert_rel(trace_of_power(A, 3, k), trace_of_power(B, 3, k), exact ? 1e-13 : 1e-9);
        }
    }
    assert_near(fabs(N[0]), 1.0 * fabs(c), 1e-13); /* N spans the tangent (cos, sin) */
    /* along a motion at v = 0 in this rest: the same A (x = (z, w, y)), by differences */
    double Am[9];
    const double v0[2] = {0.0, 0.0};
    assert_int_equal(ga_state_space_motion(s, 0.0, q, v0, y, 3, &dim, NULL, Am), GA_OK);
    for (int i = 0; i < 9; ++i)
        assert_near(Am[i], A[i], 1e-7 * (1.0 + fabs(A[i])));
    assert_int_equal(ga_state_space_motion(s, 0.0, q, v0, NULL, 3, &dim, NULL, Am), GA_ERR_ARG);
    /* refusals: y missing, the dimension too large for max_dim, no root of the rate */
    assert_int_equal(ga_state_space(s, 0.0, q, NULL, NULL, 3, &dim, NULL, NULL), GA_ERR_ARG);
    assert_int_equal(ga_state_space(s, 0.0, q, y, NULL, 2, &dim, N, A), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "dimension 3"));
    double qs[2] = {0.1, -0.8}, ys[1] = {0.5};
    assert_int_equal(ga_static_equilibrium_y(s, 0.0, qs, NULL, NULL, 1e-13, 50), GA_ERR_ARG);
    act_no_root = 1;
    assert_int_equal(ga_static_equilibrium_y(s, 0.0, qs, ys, NULL, 1e-13, 50), GA_ERR_NEWTON);
    assert_non_null(strstr(ga_last_error(s), "no equilibrium"));
    act_no_root = 0;
    assert_true(qs[0] == 0.1 && qs[1] == -0.8 && ys[0] == 0.5);
    ga_free(s);
}

/* About a moving state: the pendulum at angle th0 swinging at th0'. In the chart's
 * coordinate z = L sin(theta - th0) (the projection on the tangent), with w = z',
 * z'' = -g cos(D) sin(th0 + D) - sin(D) w^2 / (L cos(D)^2), D = theta - th0, whose derivatives
 * at z = 0 give A = [0, 1; -(g cos(th0) + w0^2 / L) / L, 0]: the centripetal term w0^2 / L^2
 * is what the tangent system at rest lacks. At rest in the equilibrium it equals
 * ga_state_space's A. */
static void test_a_swinging_pendulum_linearized_along_its_motion(void **state)
{
    (void)state;
    Pendulums p = {1, {1.3, 0}, {0.9, 0}, 0, 0};
    const double L = p.L[0], th0 = 0.7, rate = 1.9;
    ga_solver *s = pendulums(&p);
    const double q[2] = {L * sin(th0), -L * cos(th0)};
    const double v[2] = {L * rate * cos(th0), L * rate * sin(th0)};
    double A[4], N[2];
    int dim = 0;
    assert_int_equal(ga_state_space_motion(s, 0.0, q, v, NULL, 2, &dim, N, A), GA_OK);
    assert_int_equal(dim, 2);
    const double w0 = L * rate;
    const double want = -(g_acc * cos(th0) + w0 * w0 / L) / L;
    printf("  swinging: dz''/dz %.12g against %.12g, dz''/dw %.3g\n", A[1], want, A[3]);
    assert_rel(A[1], want, 1e-8);
    assert_near(A[3], 0.0, 1e-8 * fabs(want));
    assert_true(A[0] == 0.0 && A[2] == 1.0);
    assert_near(fabs(N[0]), cos(th0), 1e-14);
    /* at rest in the equilibrium: the same as the tangent system */
    const double qr[2] = {0.0, -L}, vr[2] = {0.0, 0.0};
    double Ar[4], As[4];
    assert_int_equal(ga_state_space_motion(s, 0.0, qr, vr, NULL, 2, &dim, NULL, Ar), GA_OK);
    assert_int_equal(ga_state_space(s, 0.0, qr, NULL, NULL, 2, &dim, NULL, As), GA_OK);
    for (int i = 0; i < 4; ++i)
        assert_near(Ar[i], As[i], 1e-8 * g_acc / L);
    /* refusals: v off the velocity constraint, q off the constraints, max_dim */
    const double vbad[2] = {0.1, 0.5}, qbad[2] = {0.0, -1.2};
    assert_int_equal(ga_state_space_motion(s, 0.0, q, vbad, NULL, 2, &dim, NULL, A), GA_ERR_INCONSISTENT);
    assert_non_null(strstr(ga_last_error(s), "velocity constraint"));
    assert_int_equal(ga_state_space_motion(s, 0.0, qbad, vr, NULL, 2, &dim, NULL, A), GA_ERR_INCONSISTENT);
    assert_int_equal(ga_state_space_motion(s, 0.0, q, v, NULL, 1, &dim, NULL, A), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "dimension 2"));
    assert_int_equal(ga_state_space_motion(s, 0.0, q, NULL, NULL, 2, &dim, NULL, A), GA_ERR_ARG);
    ga_free(s);
}

static void test_rotations_and_first_order_states_are_refused_by_name(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    const int kinds[1] = {GA_SPACE_SO3_QUATERNION}, counts[1] = {1};
    assert_int_equal(ga_create_space(1, kinds, counts, 0, &s), GA_OK);
    Pendulums p = {1, {1.0, 0}, {1.0, 0}, 1, 0};
    assert_int_equal(ga_set_callbacks(s, pend_mass, NULL, NULL, NULL, &p), GA_OK);
    double q[4] = {1, 0, 0, 0}, w2[1];
    assert_int_equal(ga_static_equilibrium(s, 0.0, q, NULL, 1e-12, 20), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "rotations"));
    assert_int_equal(ga_modes(s, 0.0, q, NULL, 1, w2, NULL), GA_ERR_STATE);
    ga_free(s);
    s = pendulums(&p);
    assert_int_equal(ga_set_first_order(s, 1, fo_force, fo_rate), GA_OK);
    double qp[2] = {0.0, -1.0};
    assert_int_equal(ga_static_equilibrium(s, 0.0, qp, NULL, 1e-12, 20), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "first-order"));
    int dof;
    assert_int_equal(ga_linearize(s, 0.0, qp, NULL, 1, &dof, NULL, NULL, NULL, NULL), GA_ERR_STATE);
    ga_free(s);
}

/* D11: the chart's projection stopped only at |Phi| <= 1e-15 |q|, below the round-off of a
 * constraint of size L^2: a pendulum of 10 m at rest, of 100 m or 1000 m (models in mm)
 * swinging, failed with GA_ERR_NEWTON. Now each is the closed form. */
static void test_the_chart_projection_works_at_any_length(void **state)
{
    (void)state;
    const double lengths[3] = {10.0, 100.0, 1000.0};
    for (int k = 0; k < 3; ++k) {
        Pendulums p = {1, {1.0, 0}, {lengths[k], 0}, 0, 0};
        const double L = p.L[0], th0 = 0.7, rate = 2.0;
        ga_solver *s = pendulums(&p);
        const double q[2] = {L * sin(th0), -L * cos(th0)};
        const double v[2] = {L * rate * cos(th0), L * rate * sin(th0)};
        const double qr[2] = {0.0, -L}, vr[2] = {0.0, 0.0};
        double A[4];
        int dim = 0;
        assert_int_equal(ga_state_space_motion(s, 0.0, q, v, NULL, 2, &dim, NULL, A), GA_OK);
        const double w0 = L * rate;
        assert_rel(A[1], -(g_acc * cos(th0) + w0 * w0 / L) / L, 1e-6);
        assert_int_equal(ga_state_space_motion(s, 0.0, qr, vr, NULL, 2, &dim, NULL, A), GA_OK);
        assert_rel(A[1], -g_acc / L, 1e-6);
        ga_free(s);
    }
}

/* ---- D12: a tiny but well-conditioned mass (40 oscillators of 1e-9 kg, omega_i = i) ---- */
enum { kTiny = 40 };
static const double kTinyMass = 1e-9;
static int tiny_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    memset(M, 0, sizeof(double) * kTiny * kTiny);
    for (int i = 0; i < kTiny; ++i)
        M[i + kTiny * i] = kTinyMass;
    return 0;
}
static int tiny_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    for (int i = 0; i < kTiny; ++i)
        f[i] = -kTinyMass * (i + 1) * (i + 1) * q[i];
    return 0;
}

/* Its determinant, 1e-360, underflows; its condition is 1. ga_modes_damped and
 * ga_state_space refused it as singular (a determinant test beside the condition's). */
static void test_a_tiny_mass_is_no_singular_mass(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(kTiny, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, tiny_mass, tiny_force, NULL, NULL, NULL), GA_OK);
    double q[kTiny] = {0}, re[4], im[4];
    assert_int_equal(ga_modes_damped(s, 0.0, q, NULL, 4, re, im, NULL, NULL), GA_OK);
    /* s = +-i, +-2i: by |s|, the positive imaginary part first */
    const double want_im[4] = {1.0, -1.0, 2.0, -2.0};
    for (int k = 0; k < 4; ++k) {
        assert_true(fabs(re[k]) < 1e-9);
        assert_true(fabs(im[k] - want_im[k]) < 1e-9);
    }
    int dim = 0;
    static double A[4 * kTiny * kTiny];
    assert_int_equal(ga_state_space(s, 0.0, q, NULL, NULL, 2 * kTiny, &dim, NULL, A), GA_OK);
    assert_int_equal(dim, 2 * kTiny);
    /* A = [0, I; -diag(i^2), 0] in the free coordinates: the last row block's diagonal */
    for (int i = 0; i < kTiny; ++i)
        assert_true(fabs(A[(kTiny + i) + dim * i] + (double)(i + 1) * (i + 1)) <
                    1e-9 * (i + 1) * (i + 1));
    ga_free(s);
}

/* ---- D3: redundant constraints that contradict each other, Phi = (x, x - 1) ------------ */
static int contra_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1, M[1] = 0, M[2] = 0, M[3] = 1;
    return 0;
}
static int contra_force(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = -q[0], f[1] = -q[1] - 1.0;
    return 0;
}
static int contra_phi(double t, const double *q, double *p, void *u)
{
    (void)t;
    const double gap = *(const double *)u; /* 1: contradicting, 0: the same constraint twice */
    p[0] = q[0], p[1] = q[0] - gap;
    return 0;
}
static int contra_jac(double t, const double *q, double *J, void *u)
{
    (void)t, (void)q, (void)u;
    J[0] = 1, J[1] = 1, J[2] = 0, J[3] = 0;
    return 0;
}

/* Newton stalled at their least-squares point x = 1/2 (|Phi| = 1/2), where the minimum-norm
 * step is zero, and "a full step within tol" returned GA_OK there. The same constraint twice
 * (gap 0) still has its equilibrium (0, -1). */
static void test_contradicting_constraints_have_no_equilibrium(void **state)
{
    (void)state;
    for (int k = 0; k < 2; ++k) {
        double gap = k == 0 ? 1.0 : 0.0;
        ga_solver *s = NULL;
        assert_int_equal(ga_create(2, 2, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, contra_mass, contra_force, contra_phi, contra_jac,
                                          &gap),
                         GA_OK);
        double q[2] = {0.2, 0.3}, lambda[2] = {7.0, 7.0};
        const ga_status st = ga_static_equilibrium(s, 0.0, q, lambda, 1e-10, 50);
        if (k == 0) {
            assert_int_equal(st, GA_ERR_INCONSISTENT);
            assert_non_null(strstr(ga_last_error(s), "cannot all hold: |Phi| = 0.5"));
            assert_true(q[0] == 0.2 && q[1] == 0.3 && lambda[0] == 7.0 && lambda[1] == 7.0);
        } else {
            assert_int_equal(st, GA_OK);
            assert_true(fabs(q[0]) < 1e-12 && fabs(q[1] + 1.0) < 1e-12);
        }
        ga_free(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pendulum_rests_below_and_swings_at_sqrt_g_over_l),
        cmocka_unit_test(test_double_pendulum_frequencies_in_closed_form),
        cmocka_unit_test(test_fourbar_with_a_spring_against_its_minimal_coordinate),
        cmocka_unit_test(test_a_run_started_in_the_equilibrium_stays_there),
        cmocka_unit_test(test_free_vibration_has_the_computed_period),
        cmocka_unit_test(test_damped_pendulum_roots_in_closed_form),
        cmocka_unit_test(test_circulatory_force_flutters),
        cmocka_unit_test(test_truss_snaps_through_along_its_closed_curve),
        cmocka_unit_test(test_load_stepping_stops_at_the_limit_point),
        cmocka_unit_test(test_no_equilibrium_a_free_motion_and_a_follower_force_are_refused),
        cmocka_unit_test(test_modes_refuse_what_is_no_equilibrium),
        cmocka_unit_test(test_an_actuated_pendulum_rests_and_its_state_space_is_the_closed_form),
        cmocka_unit_test(test_a_swinging_pendulum_linearized_along_its_motion),
        cmocka_unit_test(test_locked_mechanism),
        cmocka_unit_test(test_arguments_state_and_callbacks),
        cmocka_unit_test(test_a_running_solver_is_left_as_it_was),
        cmocka_unit_test(test_rotations_and_first_order_states_are_refused_by_name),
        cmocka_unit_test(test_a_tiny_mass_is_no_singular_mass),
        cmocka_unit_test(test_the_chart_projection_works_at_any_length),
        cmocka_unit_test(test_contradicting_constraints_have_no_equilibrium),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
