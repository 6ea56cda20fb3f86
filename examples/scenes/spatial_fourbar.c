/* The spatial RSSR four-bar on (R^3 x SO(3))^3: see spatial_fourbar.h. The rotations come from
 * galpha's own maps (ga_so3_*), as a user's model would take them. */
#include "spatial_fourbar.h"

#include <math.h>
#include <string.h>

#define QX(k) (7 * (k))     /* x of body k in q */
#define QR(k) (7 * (k) + 3) /* its quaternion */
#define VX(k) (6 * (k))     /* x' in v */
#define VW(k) (6 * (k) + 3) /* omega */
#define J_(r, c) J[(r) + FOURBAR_M * (c)]

enum { CRANK, COUPLER, ROCKER };

spatial_fourbar spatial_fourbar_make(void)
{
    spatial_fourbar f = {{0.2, 0.6, 0.4}, {1.0, 2.0, 1.5}, {{0}}, {0.25, 0.1, 0.3}, 9.81};
    const double r = 0.02;
    for (int k = 0; k < FOURBAR_BODIES; ++k) {
        const double m = f.mass[k], L = f.length[k];
        f.inertia[k][0] = f.inertia[k][1] = m * (3 * r * r + L * L) / 12.0;
        f.inertia[k][2] = m * r * r / 2.0;
    }
    return f;
}

void spatial_fourbar_blocks(int *kinds, int *counts)
{
    for (int k = 0; k < FOURBAR_BODIES; ++k) {
        kinds[2 * k] = GA_SPACE_VECTOR;
        counts[2 * k] = 3;
        kinds[2 * k + 1] = GA_SPACE_SO3_QUATERNION;
        counts[2 * k + 1] = 1;
    }
}

/* R of body k, column-major; nonzero if its quaternion is not one (ga_so3_matrix refuses) */
static int rotation(const double *q, int k, double R[9])
{
    return ga_so3_matrix(1, q + QR(k), R) != GA_OK;
}

static void cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* The point at (0, 0, sigma) of body k in space */
static void point(const double *q, int k, const double R[9], double sigma, double out[3])
{
    for (int i = 0; i < 3; ++i)
        out[i] = q[QX(k) + i] + sigma * R[i + 6];
}

/* The loop: (B - C) . (B - C) = L2^2 as P cos phi + Q sin phi = S */
double spatial_fourbar_rocker_angle(const spatial_fourbar *f, double theta, double *dphi)
{
    const double L1 = f->length[CRANK], L2 = f->length[COUPLER], L3 = f->length[ROCKER];
    const double *D = f->pivot;
    const double bx = L1 * cos(theta) - D[0], by = L1 * sin(theta) - D[1];
    const double P = -2.0 * L3 * by, Q = 2.0 * L3 * D[2];
    const double S = L2 * L2 - L3 * L3 - D[2] * D[2] - by * by - bx * bx;
    const double phi = atan2(Q, P) - acos(S / hypot(P, Q));
    if (dphi) { /* from the loop's derivative: (B - C) . (B' - C_phi phi') = 0 */
        const double B[3] = {L1 * cos(theta), L1 * sin(theta), 0.0};
        const double C[3] = {D[0], D[1] + L3 * cos(phi), D[2] + L3 * sin(phi)};
        const double dB[3] = {-L1 * sin(theta), L1 * cos(theta), 0.0};
        const double dC[3] = {0.0, -L3 * sin(phi), L3 * cos(phi)};
        double num = 0.0, den = 0.0;
        for (int i = 0; i < 3; ++i) {
            num += (B[i] - C[i]) * dB[i];
            den += (B[i] - C[i]) * dC[i];
        }
        *dphi = num / den;
    }
    return phi;
}

void spatial_fourbar_initial(const spatial_fourbar *f, double theta, double theta_dot, double *q,
                             double *v)
{
    const double L1 = f->length[CRANK], L2 = f->length[COUPLER], L3 = f->length[ROCKER];
    const double *D = f->pivot;
    double dphi;
    const double phi = spatial_fourbar_rocker_angle(f, theta, &dphi);
    const double B[3] = {L1 * cos(theta), L1 * sin(theta), 0.0};
    const double C[3] = {D[0], D[1] + L3 * cos(phi), D[2] + L3 * sin(phi)};
    const double dB[3] = {-L1 * sin(theta) * theta_dot, L1 * cos(theta) * theta_dot, 0.0};
    const double dC[3] = {0.0, -L3 * sin(phi) * dphi * theta_dot, L3 * cos(phi) * dphi * theta_dot};
    memset(v, 0, FOURBAR_NV * sizeof(double));
    /* the crank: body (x, y, z) to space (y, z, x) (a third of a turn about (1, 1, 1)), then
     * theta about z; the rocker: body (x, y, z) to space (z, x, y), then phi about x */
    const double cyc[4] = {0.5, 0.5, 0.5, 0.5}, anti[4] = {0.5, -0.5, -0.5, -0.5};
    const double turn_z[3] = {0.0, 0.0, theta}, turn_x[3] = {phi, 0.0, 0.0};
    double r[4];
    ga_so3_exp(1, turn_z, r);
    ga_so3_compose(1, r, cyc, q + QR(CRANK));
    ga_so3_exp(1, turn_x, r);
    ga_so3_compose(1, r, anti, q + QR(ROCKER));
    /* the coupler: the shortest turn of z onto its axis e, so that its spin is zero */
    double e[3], de[3], axis[3];
    for (int i = 0; i < 3; ++i) {
        e[i] = (C[i] - B[i]) / L2;
        de[i] = (dC[i] - dB[i]) / L2;
    }
    const double ez[3] = {0.0, 0.0, 1.0};
    cross(ez, e, axis);
    const double s = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    const double angle = atan2(s, e[2]);
    for (int i = 0; i < 3; ++i)
        axis[i] *= angle / s;
    ga_so3_exp(1, axis, q + QR(COUPLER));
    for (int i = 0; i < 3; ++i) {
        q[QX(CRANK) + i] = B[i] / 2.0;
        q[QX(COUPLER) + i] = (B[i] + C[i]) / 2.0;
        q[QX(ROCKER) + i] = (D[i] + C[i]) / 2.0;
        v[VX(CRANK) + i] = dB[i] / 2.0;
        v[VX(COUPLER) + i] = (dB[i] + dC[i]) / 2.0;
        v[VX(ROCKER) + i] = dC[i] / 2.0;
    }
    /* body angular velocities R^T omega: the crank's along its body y (space z), the rocker's
     * likewise (space x), the coupler's e x e' (no spin) */
    v[VW(CRANK) + 1] = theta_dot;
    v[VW(ROCKER) + 1] = dphi * theta_dot;
    double w[3], R[9];
    cross(e, de, w);
    rotation(q, COUPLER, R);
    for (int i = 0; i < 3; ++i)
        v[VW(COUPLER) + i] = R[3 * i] * w[0] + R[3 * i + 1] * w[1] + R[3 * i + 2] * w[2];
}

double spatial_fourbar_crank_angle(const double *q)
{
    double R[9];
    if (rotation(q, CRANK, R))
        return NAN;
    return atan2(R[7], R[6]); /* the rod's axis R e_z in the xy plane */
}

double spatial_fourbar_energy(const spatial_fourbar *f, const double *q, const double *v)
{
    double E = 0.0;
    for (int k = 0; k < FOURBAR_BODIES; ++k)
        for (int i = 0; i < 3; ++i)
            E += 0.5 * f->mass[k] * v[VX(k) + i] * v[VX(k) + i] +
                 0.5 * f->inertia[k][i] * v[VW(k) + i] * v[VW(k) + i];
    for (int k = 0; k < FOURBAR_BODIES; ++k)
        E += f->mass[k] * f->gravity * q[QX(k) + 2];
    return E;
}

int spatial_fourbar_mass(double t, const double *q, double *M, void *user)
{
    (void)t;
    (void)q;
    const spatial_fourbar *f = user;
    memset(M, 0, FOURBAR_NV * FOURBAR_NV * sizeof(double));
    for (int k = 0; k < FOURBAR_BODIES; ++k)
        for (int i = 0; i < 3; ++i) {
            M[(VX(k) + i) * (FOURBAR_NV + 1)] = f->mass[k];
            M[(VW(k) + i) * (FOURBAR_NV + 1)] = f->inertia[k][i];
        }
    return 0;
}

/* gravity on every centre of mass, and the gyroscopic -omega x J omega */
int spatial_fourbar_force(double t, const double *q, const double *v, double *out, void *user)
{
    (void)t;
    (void)q;
    const spatial_fourbar *f = user;
    for (int k = 0; k < FOURBAR_BODIES; ++k) {
        const double *w = v + VW(k);
        const double Jw[3] = {f->inertia[k][0] * w[0], f->inertia[k][1] * w[1],
                              f->inertia[k][2] * w[2]};
        double g[3];
        cross(w, Jw, g);
        out[VX(k)] = 0.0;
        out[VX(k) + 1] = 0.0;
        out[VX(k) + 2] = -f->mass[k] * f->gravity;
        for (int i = 0; i < 3; ++i)
            out[VW(k) + i] = -g[i];
    }
    return 0;
}

int spatial_fourbar_constraint(double t, const double *q, double *phi, void *user)
{
    (void)t;
    const spatial_fourbar *f = user;
    const double h1 = f->length[CRANK] / 2, h2 = f->length[COUPLER] / 2, h3 = f->length[ROCKER] / 2;
    double R1[9], R2[9], R3[9];
    if (rotation(q, CRANK, R1) || rotation(q, COUPLER, R2) || rotation(q, ROCKER, R3))
        return 1;
    double a[3], b[3];
    point(q, CRANK, R1, -h1, a); /* the crank's foot at the origin */
    memcpy(phi, a, sizeof a);
    phi[3] = R1[3]; /* its joint axis R1 e_y along space z: its x and y vanish */
    phi[4] = R1[4];
    point(q, CRANK, R1, h1, a); /* B: crank tip = coupler foot */
    point(q, COUPLER, R2, -h2, b);
    for (int i = 0; i < 3; ++i)
        phi[5 + i] = a[i] - b[i];
    point(q, COUPLER, R2, h2, a); /* C: coupler tip = rocker tip */
    point(q, ROCKER, R3, h3, b);
    for (int i = 0; i < 3; ++i)
        phi[8 + i] = a[i] - b[i];
    point(q, ROCKER, R3, -h3, a); /* the rocker's foot at D */
    for (int i = 0; i < 3; ++i)
        phi[11 + i] = a[i] - f->pivot[i];
    phi[14] = R3[4]; /* its joint axis R3 e_y along space x: its y and z vanish */
    phi[15] = R3[5];
    return 0;
}

/* d/de of the point x_k + R_k exp(e w) (0, 0, sigma) in rows r..r+2, times sign: dx the
 * identity, w the columns R (e_j x sigma e_z) = sigma (-R e_y, R e_x, 0) */
static void point_rows(double *J, int r, int k, const double R[9], double sigma, double sign)
{
    for (int i = 0; i < 3; ++i) {
        J_(r + i, VX(k) + i) = sign;
        J_(r + i, VW(k)) = -sign * sigma * R[i + 3];
        J_(r + i, VW(k) + 1) = sign * sigma * R[i];
    }
}

/* d/de of a . R_k exp(e w) e_y in row r: a . R (e_j x e_y) = (a . R e_z, 0, -a . R e_x) */
static void axis_row(double *J, int r, int k, const double R[9], int a)
{
    J_(r, VW(k)) = R[a + 6];
    J_(r, VW(k) + 2) = -R[a];
}

int spatial_fourbar_jacobian(double t, const double *q, double *J, void *user)
{
    (void)t;
    const spatial_fourbar *f = user;
    const double h1 = f->length[CRANK] / 2, h2 = f->length[COUPLER] / 2, h3 = f->length[ROCKER] / 2;
    double R1[9], R2[9], R3[9];
    if (rotation(q, CRANK, R1) || rotation(q, COUPLER, R2) || rotation(q, ROCKER, R3))
        return 1;
    memset(J, 0, FOURBAR_M * FOURBAR_NV * sizeof(double));
    point_rows(J, 0, CRANK, R1, -h1, 1.0);
    axis_row(J, 3, CRANK, R1, 0);
    axis_row(J, 4, CRANK, R1, 1);
    point_rows(J, 5, CRANK, R1, h1, 1.0);
    point_rows(J, 5, COUPLER, R2, -h2, -1.0);
    point_rows(J, 8, COUPLER, R2, h2, 1.0);
    point_rows(J, 8, ROCKER, R3, h3, -1.0);
    point_rows(J, 11, ROCKER, R3, -h3, 1.0);
    axis_row(J, 14, ROCKER, R3, 1);
    axis_row(J, 15, ROCKER, R3, 2);
    return 0;
}

int spatial_fourbar_constraint_dt(double t, const double *q, double *phi_t, void *user)
{
    (void)t;
    (void)q;
    (void)user;
    memset(phi_t, 0, FOURBAR_M * sizeof(double)); /* fixed joints */
    return 0;
}
