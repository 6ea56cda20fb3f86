#include "andrews.h"

#include <math.h>
#include <string.h>

/* ---- data (Test Set "andrews", docs/references.md) -------------------------------------- */
static const double m1 = 0.04325, m2 = 0.00365, m3 = 0.02373, m4 = 0.00706, m5 = 0.07050,
                    m6 = 0.00706, m7 = 0.05498;
static const double i1 = 2.194e-6, i2 = 4.410e-7, i3 = 5.255e-6, i4 = 5.667e-7, i5 = 1.169e-5,
                    i6 = 5.667e-7, i7 = 1.912e-5;
static const double xa = -0.06934, ya = -0.00227, xb = -0.03635, yb = 0.03273, xc = 0.014,
                    yc = 0.072;
static const double d = 0.028, da = 0.0115, e = 0.02, ea = 0.01421, rr = 0.007, ra = 0.00092,
                    ss = 0.035, sa = 0.01874, sb = 0.01043, sc = 0.018, sd = 0.02, ta = 0.02308,
                    tb = 0.00916, u = 0.04, ua = 0.01228, ub = 0.00449, zf = 0.02, zt = 0.04,
                    fa = 0.01421, mom = 0.033, c0 = 4530.0, l0 = 0.07785;

const double andrews_q0[7] = {-0.0617138900142764496358948458001, 0.0,
                              0.455279819163070380255912382449,
                              0.222668390165885884674473185609,
                              0.487364979543842550225598953530,
                              -0.222668390165885884674473185609,
                              1.23054744454982119249735015568};
const double andrews_t_end = 0.03;
const double andrews_q_ref[7] = {0.1581077119629904e+2, -0.1575637105984298e+2,
                                 0.4082224013073101e-1, -0.5347301163226948e+0,
                                 0.5244099658805304e+0, 0.5347301163226948e+0,
                                 0.1048080741042263e+1};
const double andrews_v_ref[7] = {1.1399203022591071e+03, -1.4243792951775408e+03,
                                 1.1032911910616471e+01, 1.9293374105027876e+01,
                                 5.7356991482934772e-01, -1.9293374105027976e+01,
                                 3.2317914924904573e-01};
const double andrews_qdd_ref[7] = {-2.4631763122866058e+04, 5.1850319636450382e+04,
                                   3.2410260070757923e+05, 5.6674942200099642e+05,
                                   1.6743635418346297e+04, -5.6674942200099630e+05,
                                   9.8265078015456347e+03};
const double andrews_lambda_ref[6] = {1.9917534810453967e+02, -2.9755309974973528e+01,
                                      2.3066543611622130e+01, 3.1452725275772760e+01,
                                      2.2642494786394398e+01, 1.1617392352612933e+01};

double andrews_angle_error(const double *q7)
{
    double e = 0.0, r = 0.0;
    for (int i = 0; i < 7; ++i) {
        e += (q7[i] - andrews_q_ref[i]) * (q7[i] - andrews_q_ref[i]);
        r += andrews_q_ref[i] * andrews_q_ref[i];
    }
    return sqrt(e / r);
}

/* ---- 7 relative angles: the Test Set's equations ----------------------------------------- */
enum { BE, TH, GA, PH, DE, OM, EP };

int an7_mass(double t, const double *q, double *M, void *user)
{
    const double cth = cos(q[TH]), sph = sin(q[PH]), som = sin(q[OM]);
    (void)t, (void)user;
    memset(M, 0, sizeof(double) * 49);
#define MM(i, j, x) do { const double val_ = (x); M[(i) + 7 * (j)] = val_; M[(j) + 7 * (i)] = val_; } while (0)
    MM(0, 0, m1 * ra * ra + m2 * (rr * rr - 2 * da * rr * cth + da * da) + i1 + i2);
    MM(1, 0, m2 * (da * da - da * rr * cth) + i2);
    MM(1, 1, m2 * da * da + i2);
    MM(2, 2, m3 * (sa * sa + sb * sb) + i3);
    MM(3, 3, m4 * (e - ea) * (e - ea) + i4);
    MM(4, 3, m4 * ((e - ea) * (e - ea) + zt * (e - ea) * sph) + i4);
    MM(4, 4, m4 * (zt * zt + 2 * zt * (e - ea) * sph + (e - ea) * (e - ea)) +
                 m5 * (ta * ta + tb * tb) + i4 + i5);
    MM(5, 5, m6 * (zf - fa) * (zf - fa) + i6);
    MM(6, 5, m6 * ((zf - fa) * (zf - fa) - u * (zf - fa) * som) + i6);
    MM(6, 6, m6 * ((zf - fa) * (zf - fa) - 2 * u * (zf - fa) * som + u * u) +
                 m7 * (ua * ua + ub * ub) + i6 + i7);
#undef MM
    return 0;
}

const andrews_params andrews_published = {4530.0, 0.033};

/* The force's parameters: the user pointer's, or the published ones (NULL). */
static const andrews_params *params_of(const void *user)
{
    return user ? (const andrews_params *)user : &andrews_published;
}

/* The spring acts between D on the triangle and the fixed point C. */
static void spring(double c0, double gam, double *xd, double *yd, double *fx, double *fy)
{
    *xd = sd * cos(gam) + sc * sin(gam) + xb;
    *yd = sd * sin(gam) - sc * cos(gam) + yb;
    const double lg = hypot(*xd - xc, *yd - yc);
    const double f = -c0 * (lg - l0) / lg;
    *fx = f * (*xd - xc);
    *fy = f * (*yd - yc);
}

int an7_force(double t, const double *q, const double *v, double *f, void *user)
{
    double xd, yd, fx, fy;
    const andrews_params *p = params_of(user);
    (void)t;
    spring(p->c0, q[GA], &xd, &yd, &fx, &fy);
    const double sth = sin(q[TH]), cph = cos(q[PH]), com = cos(q[OM]);
    f[0] = p->mom - m2 * da * rr * v[TH] * (v[TH] + 2 * v[BE]) * sth;
    f[1] = m2 * da * rr * v[BE] * v[BE] * sth;
    f[2] = fx * (sc * cos(q[GA]) - sd * sin(q[GA])) + fy * (sd * cos(q[GA]) + sc * sin(q[GA]));
    f[3] = m4 * zt * (e - ea) * v[DE] * v[DE] * cph;
    f[4] = -m4 * zt * (e - ea) * v[PH] * (v[PH] + 2 * v[DE]) * cph;
    f[5] = -m6 * u * (zf - fa) * v[EP] * v[EP] * com;
    f[6] = m6 * u * (zf - fa) * v[OM] * (v[OM] + 2 * v[EP]) * com;
    return 0;
}

int an7_constraint(double t, const double *q, double *g, void *user)
{
    const double bt = q[BE] + q[TH], pd = q[PH] + q[DE], oe = q[OM] + q[EP];
    (void)t, (void)user;
    g[0] = rr * cos(q[BE]) - d * cos(bt) - ss * sin(q[GA]) - xb;
    g[1] = rr * sin(q[BE]) - d * sin(bt) + ss * cos(q[GA]) - yb;
    g[2] = rr * cos(q[BE]) - d * cos(bt) - e * sin(pd) - zt * cos(q[DE]) - xa;
    g[3] = rr * sin(q[BE]) - d * sin(bt) + e * cos(pd) - zt * sin(q[DE]) - ya;
    g[4] = rr * cos(q[BE]) - d * cos(bt) - zf * cos(oe) - u * sin(q[EP]) - xa;
    g[5] = rr * sin(q[BE]) - d * sin(bt) - zf * sin(oe) + u * cos(q[EP]) - ya;
    return 0;
}

int an7_jacobian(double t, const double *q, double *G, void *user)
{
    const double bt = q[BE] + q[TH], pd = q[PH] + q[DE], oe = q[OM] + q[EP];
    const double sb_ = sin(q[BE]), cb = cos(q[BE]), sbt = sin(bt), cbt = cos(bt);
    (void)t, (void)user;
    memset(G, 0, sizeof(double) * 42);
#define GG(i, j) G[(i) + 6 * (j)]
    for (int r = 0; r < 6; r += 2) { /* every loop starts with O-F-E */
        GG(r, BE) = -rr * sb_ + d * sbt;
        GG(r, TH) = d * sbt;
        GG(r + 1, BE) = rr * cb - d * cbt;
        GG(r + 1, TH) = -d * cbt;
    }
    GG(0, GA) = -ss * cos(q[GA]);
    GG(1, GA) = -ss * sin(q[GA]);
    GG(2, PH) = -e * cos(pd);
    GG(2, DE) = -e * cos(pd) + zt * sin(q[DE]);
    GG(3, PH) = -e * sin(pd);
    GG(3, DE) = -e * sin(pd) - zt * cos(q[DE]);
    GG(4, OM) = zf * sin(oe);
    GG(4, EP) = zf * sin(oe) - u * cos(q[EP]);
    GG(5, OM) = -zf * cos(oe);
    GG(5, EP) = -zf * cos(oe) - u * sin(q[EP]);
#undef GG
    return 0;
}

/* Phi_qq(v, v): every term c cos(phi) or c sin(phi) of g contributes -c cos(phi) phi'^2 or
 * -c sin(phi) phi'^2 (the phi'' part is Phi_q qdd). */
int an7_constraint_accel(double t, const double *q, const double *v, double *out, void *user)
{
    const double bt = q[BE] + q[TH], pd = q[PH] + q[DE], oe = q[OM] + q[EP];
    const double wb = v[BE] * v[BE], wbt = (v[BE] + v[TH]) * (v[BE] + v[TH]);
    const double wg = v[GA] * v[GA], wpd = (v[PH] + v[DE]) * (v[PH] + v[DE]);
    const double wd = v[DE] * v[DE], woe = (v[OM] + v[EP]) * (v[OM] + v[EP]);
    const double we = v[EP] * v[EP];
    const double cx = -rr * cos(q[BE]) * wb + d * cos(bt) * wbt;
    const double cy = -rr * sin(q[BE]) * wb + d * sin(bt) * wbt;
    (void)t, (void)user;
    out[0] = cx + ss * sin(q[GA]) * wg;
    out[1] = cy - ss * cos(q[GA]) * wg;
    out[2] = cx + e * sin(pd) * wpd + zt * cos(q[DE]) * wd;
    out[3] = cy - e * cos(pd) * wpd + zt * sin(q[DE]) * wd;
    out[4] = cx + zf * cos(oe) * woe + u * sin(q[EP]) * we;
    out[5] = cy + zf * sin(oe) * woe - u * cos(q[EP]) * we;
    return 0;
}

static double spring_energy(double xd, double yd)
{
    const double lg = hypot(xd - xc, yd - yc);
    return 0.5 * c0 * (lg - l0) * (lg - l0);
}

double an7_energy(const double *q, const double *v)
{
    double M[49], xd, yd, fx, fy, T = 0.0;
    an7_mass(0.0, q, M, NULL);
    for (int i = 0; i < 7; ++i)
        for (int j = 0; j < 7; ++j)
            T += 0.5 * v[i] * M[i + 7 * j] * v[j];
    spring(c0, q[GA], &xd, &yd, &fx, &fy);
    return T + spring_energy(xd, yd) - mom * (q[BE] - andrews_q0[BE]);
}

void an7_point_f(const double *q, const double *v, const double *qdd, double *pos, double *acc)
{
    const double c = cos(q[BE]), s = sin(q[BE]), w = v[BE] * v[BE];
    pos[0] = rr * c;
    pos[1] = rr * s;
    acc[0] = rr * (-s * qdd[BE] - c * w);
    acc[1] = rr * (c * qdd[BE] - s * w);
}

/* ---- 31 absolute coordinates -------------------------------------------------------------
 * q = (x1, y1, th1, ..., x7, y7, th7, F, E, G, H, D); every constraint pair reads
 *     P - Q - R(th_b) (a, b) = 0,   R(th) (a, b) = (a cos th - b sin th, a sin th + b cos th),
 * P a point of body b given in its own frame by (a, b) from the point Q of the same body. */
enum { PF = 21, PE = 23, PG = 25, PH_ = 27, PD = 29, FIXED_O = -1, FIXED_A = -2, FIXED_B = -3 };
#define CM(b) (3 * ((b)-1))

typedef struct link {
    int p, q, body;
    double a, b;
} link;

/* Ordered so that every point is placed (an31_from_angles) before it is used as a base;
 * links marked closing are the loop closures that placement skips. */
static const link links[15] = {
    {PF, FIXED_O, 1, rr, 0.0},            /* F on the crank */
    {CM(1), FIXED_O, 1, ra, 0.0},         /* crank centre of mass */
    {PE, PF, 2, -d, 0.0},                 /* E at the far end of FE */
    {CM(2), PF, 2, -da, 0.0},             /* FE centre of mass */
    {CM(3), FIXED_B, 3, sb, -sa},         /* triangle centre of mass */
    {PD, FIXED_B, 3, sd, -sc},            /* spring attachment D */
    {PG, FIXED_A, 5, zt, 0.0},            /* G at the end of GA */
    {CM(5), FIXED_A, 5, ta, tb},          /* GA centre of mass */
    {CM(4), PG, 4, 0.0, -(e - ea)},       /* EG centre of mass */
    {PH_, FIXED_A, 7, 0.0, -u},           /* H at the end of AH */
    {CM(7), FIXED_A, 7, ub, -ua},         /* AH centre of mass */
    {CM(6), PH_, 6, zf - fa, 0.0},        /* HE centre of mass */
    {PE, FIXED_B, 3, 0.0, -ss},           /* closing: E on the triangle */
    {PE, PG, 4, 0.0, -e},                 /* closing: E on EG */
    {PE, PH_, 6, zf, 0.0},                /* closing: E on HE */
};
enum { PLACING_LINKS = 12 };

static void base_point(int q_index, const double *q, double *out)
{
    switch (q_index) {
    case FIXED_O: out[0] = 0.0; out[1] = 0.0; break;
    case FIXED_A: out[0] = xa; out[1] = ya; break;
    case FIXED_B: out[0] = xb; out[1] = yb; break;
    default: out[0] = q[q_index]; out[1] = q[q_index + 1];
    }
}

static void rotate(double th, double a, double b, double *out)
{
    const double c = cos(th), s = sin(th);
    out[0] = a * c - b * s;
    out[1] = a * s + b * c;
}

static const double body_mass[8] = {0, m1, m2, m3, m4, m5, m6, m7};
static const double body_inertia[8] = {0, i1, i2, i3, i4, i5, i6, i7};

int an31_mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    memset(M, 0, sizeof(double) * AN31_N * AN31_N);
    for (int b = 1; b <= 7; ++b) {
        const int k = CM(b);
        M[k + AN31_N * k] = body_mass[b];
        M[(k + 1) + AN31_N * (k + 1)] = body_mass[b];
        M[(k + 2) + AN31_N * (k + 2)] = body_inertia[b];
    }
    return 0; /* the five points are massless */
}

int an31_force(double t, const double *q, const double *v, double *f, void *user)
{
    const andrews_params *p = params_of(user);
    (void)t, (void)v;
    memset(f, 0, sizeof(double) * AN31_N);
    f[CM(1) + 2] = p->mom;
    const double dx = q[PD] - xc, dy = q[PD + 1] - yc, lg = hypot(dx, dy);
    const double s = -p->c0 * (lg - l0) / lg;
    f[PD] = s * dx;
    f[PD + 1] = s * dy;
    return 0;
}

int an31_constraint(double t, const double *q, double *phi, void *user)
{
    (void)t, (void)user;
    for (int k = 0; k < 15; ++k) {
        const link *L = &links[k];
        double base[2], r[2];
        base_point(L->q, q, base);
        rotate(q[CM(L->body) + 2], L->a, L->b, r);
        phi[2 * k] = q[L->p] - base[0] - r[0];
        phi[2 * k + 1] = q[L->p + 1] - base[1] - r[1];
    }
    return 0;
}

int an31_jacobian(double t, const double *q, double *J, void *user)
{
    (void)t, (void)user;
    memset(J, 0, sizeof(double) * AN31_M * AN31_N);
    for (int k = 0; k < 15; ++k) {
        const link *L = &links[k];
        const int r = 2 * k, th = CM(L->body) + 2;
        double dr[2]; /* -d/dth R(th)(a, b) = R(th)(b, -a) */
        rotate(q[th], L->b, -L->a, dr);
        J[r + AN31_M * L->p] = 1.0;
        J[r + 1 + AN31_M * (L->p + 1)] = 1.0;
        if (L->q >= 0) {
            J[r + AN31_M * L->q] = -1.0;
            J[r + 1 + AN31_M * (L->q + 1)] = -1.0;
        }
        J[r + AN31_M * th] = dr[0];
        J[r + 1 + AN31_M * th] = dr[1];
    }
    return 0;
}

/* -d^2/dth^2 R(th)(a, b) th'^2 = R(th)(a, b) th'^2 */
int an31_constraint_accel(double t, const double *q, const double *v, double *out, void *user)
{
    (void)t, (void)user;
    for (int k = 0; k < 15; ++k) {
        const link *L = &links[k];
        const int th = CM(L->body) + 2;
        double r[2];
        rotate(q[th], L->a, L->b, r);
        out[2 * k] = r[0] * v[th] * v[th];
        out[2 * k + 1] = r[1] * v[th] * v[th];
    }
    return 0;
}

int an31_stiffness(double t, const double *q, const double *v, const double *qdd,
                   const double *lambda, double *K, void *user)
{
    const double c0 = params_of(user)->c0;
    (void)t, (void)v, (void)qdd;
    memset(K, 0, sizeof(double) * AN31_N * AN31_N);
    /* the Phi_q^T lambda entry of a rotation is lambda_k . R(th)(b, -a); its derivative in th
     * is lambda_k . R(th)(a, b) */
    for (int k = 0; k < 15; ++k) {
        const link *L = &links[k];
        const int th = CM(L->body) + 2;
        double r[2];
        rotate(q[th], L->a, L->b, r);
        K[th + AN31_N * th] += lambda[2 * k] * r[0] + lambda[2 * k + 1] * r[1];
    }
    /* spring: f_D = -c0 (1 - l0/L) (D - C), so -df/dD = c0 ((1 - l0/L) I + l0/L^3 dd^T) */
    const double dx = q[PD] - xc, dy = q[PD + 1] - yc, lg = hypot(dx, dy);
    const double a = c0 * (1.0 - l0 / lg), b = c0 * l0 / (lg * lg * lg);
    K[PD + AN31_N * PD] += a + b * dx * dx;
    K[PD + AN31_N * (PD + 1)] += b * dx * dy;
    K[(PD + 1) + AN31_N * PD] += b * dx * dy;
    K[(PD + 1) + AN31_N * (PD + 1)] += a + b * dy * dy;
    return 0;
}

/* ---- the 31-coordinate model with declared patterns ---------------------------------------- */
ga_status an31_declare_patterns(ga_solver *s)
{
    int rm[21], cm[21], rj[90], cj[90], rk[11], ck[11], k = 0;
    for (int i = 0; i < 21; ++i) /* bodies: x, y, theta; the points are massless */
        rm[i] = cm[i] = i;
    for (int l = 0; l < 15; ++l) {
        const link *L = &links[l];
        const int r = 2 * l, th = CM(L->body) + 2;
        rj[k] = r, cj[k++] = L->p;
        rj[k] = r + 1, cj[k++] = L->p + 1;
        if (L->q >= 0) {
            rj[k] = r, cj[k++] = L->q;
            rj[k] = r + 1, cj[k++] = L->q + 1;
        }
        rj[k] = r, cj[k++] = th;
        rj[k] = r + 1, cj[k++] = th;
    }
    for (int b = 1; b <= 7; ++b)
        rk[b - 1] = ck[b - 1] = CM(b) + 2;
    rk[7] = PD, ck[7] = PD;
    rk[8] = PD, ck[8] = PD + 1;
    rk[9] = PD + 1, ck[9] = PD;
    rk[10] = PD + 1, ck[10] = PD + 1;
    ga_status st = ga_set_pattern(s, GA_MATRIX_MASS, 21, rm, cm);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_JACOBIAN, k, rj, cj);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_STIFFNESS, 11, rk, ck);
    if (!st)
        st = ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL);
    return st;
}

int an31_mass_sparse(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    for (int b = 1; b <= 7; ++b) {
        M[CM(b)] = M[CM(b) + 1] = body_mass[b];
        M[CM(b) + 2] = body_inertia[b];
    }
    return 0;
}

int an31_jacobian_sparse(double t, const double *q, double *J, void *user)
{
    int k = 0;
    (void)t, (void)user;
    for (int l = 0; l < 15; ++l) {
        const link *L = &links[l];
        double dr[2];
        rotate(q[CM(L->body) + 2], L->b, -L->a, dr);
        J[k++] = 1.0;
        J[k++] = 1.0;
        if (L->q >= 0) {
            J[k++] = -1.0;
            J[k++] = -1.0;
        }
        J[k++] = dr[0];
        J[k++] = dr[1];
    }
    return 0;
}

int an31_stiffness_sparse(double t, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *K, void *user)
{
    const double c0 = params_of(user)->c0;
    (void)t, (void)v, (void)qdd;
    /* the same entries as an31_stiffness, written directly in the declared order */
    for (int b = 0; b < 7; ++b)
        K[b] = 0.0;
    for (int k = 0; k < 15; ++k) {
        const link *L = &links[k];
        double r[2];
        rotate(q[CM(L->body) + 2], L->a, L->b, r);
        K[L->body - 1] += lambda[2 * k] * r[0] + lambda[2 * k + 1] * r[1];
    }
    const double dx = q[PD] - xc, dy = q[PD + 1] - yc, lg = hypot(dx, dy);
    const double a = c0 * (1.0 - l0 / lg), b = c0 * l0 / (lg * lg * lg);
    K[7] = a + b * dx * dx;
    K[8] = b * dx * dy;
    K[9] = b * dx * dy;
    K[10] = a + b * dy * dy;
    return 0;
}

static void absolute_angles(const double *q7, double *th)
{
    th[1] = q7[BE];
    th[2] = q7[BE] + q7[TH];
    th[3] = q7[GA];
    th[4] = q7[PH] + q7[DE];
    th[5] = q7[DE];
    th[6] = q7[OM] + q7[EP];
    th[7] = q7[EP];
}

void an31_from_angles(const double *q7, const double *v7, double *q, double *v)
{
    double th[8], om[8];
    absolute_angles(q7, th);
    absolute_angles(v7, om);
    memset(q, 0, sizeof(double) * AN31_N);
    memset(v, 0, sizeof(double) * AN31_N);
    for (int b = 1; b <= 7; ++b) {
        q[CM(b) + 2] = th[b];
        v[CM(b) + 2] = om[b];
    }
    for (int k = 0; k < PLACING_LINKS; ++k) {
        const link *L = &links[k];
        double base[2], r[2], dr[2];
        base_point(L->q, q, base);
        rotate(th[L->body], L->a, L->b, r);
        rotate(th[L->body], -L->b, L->a, dr); /* d/dth R(th)(a, b) */
        q[L->p] = base[0] + r[0];
        q[L->p + 1] = base[1] + r[1];
        const double vb[2] = {L->q >= 0 ? v[L->q] : 0.0, L->q >= 0 ? v[L->q + 1] : 0.0};
        v[L->p] = vb[0] + dr[0] * om[L->body];
        v[L->p + 1] = vb[1] + dr[1] * om[L->body];
    }
}

void an31_to_angles(const double *q, double *q7)
{
    q7[BE] = q[CM(1) + 2];
    q7[TH] = q[CM(2) + 2] - q[CM(1) + 2];
    q7[GA] = q[CM(3) + 2];
    q7[PH] = q[CM(4) + 2] - q[CM(5) + 2];
    q7[DE] = q[CM(5) + 2];
    q7[OM] = q[CM(6) + 2] - q[CM(7) + 2];
    q7[EP] = q[CM(7) + 2];
}

double an31_energy(const double *q, const double *v)
{
    double T = 0.0;
    for (int b = 1; b <= 7; ++b) {
        const int k = CM(b);
        T += 0.5 * body_mass[b] * (v[k] * v[k] + v[k + 1] * v[k + 1]) +
             0.5 * body_inertia[b] * v[k + 2] * v[k + 2];
    }
    return T + spring_energy(q[PD], q[PD + 1]) - mom * (q[CM(1) + 2] - andrews_q0[BE]);
}

int an31_theta(int body) { return CM(body) + 2; }

int an31_point(char name)
{
    switch (name) {
    case 'F': return PF;
    case 'E': return PE;
    case 'G': return PG;
    case 'H': return PH_;
    case 'D': return PD;
    default: return -1;
    }
}

int an7_constraint_dt(double t, const double *q, double *out, void *user)
{
    (void)t, (void)q, (void)user;
    memset(out, 0, sizeof(double) * AN7_M);
    return 0;
}

int an31_constraint_dt(double t, const double *q, double *out, void *user)
{
    (void)t, (void)q, (void)user;
    memset(out, 0, sizeof(double) * AN31_M);
    return 0;
}
