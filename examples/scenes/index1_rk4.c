#include "index1_rk4.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct work {
    int n, m, N;
    double *M, *J, *A, *rhs, *c, *f;
} work;

/* Solves A x = rhs (N x N, column-major) in place by Gaussian elimination with partial
 * pivoting. */
static int gauss(int N, double *A, double *x)
{
    for (int k = 0; k < N; ++k) {
        int p = k;
        for (int i = k + 1; i < N; ++i)
            if (fabs(A[i + N * k]) > fabs(A[p + N * k]))
                p = i;
        if (A[p + N * k] == 0.0)
            return -1;
        if (p != k) {
            for (int j = 0; j < N; ++j) {
                const double tmp = A[k + N * j];
                A[k + N * j] = A[p + N * j];
                A[p + N * j] = tmp;
            }
            const double tmp = x[k];
            x[k] = x[p];
            x[p] = tmp;
        }
        for (int i = k + 1; i < N; ++i) {
            const double l = A[i + N * k] / A[k + N * k];
            if (l == 0.0)
                continue;
            for (int j = k; j < N; ++j)
                A[i + N * j] -= l * A[k + N * j];
            x[i] -= l * x[k];
        }
    }
    for (int k = N - 1; k >= 0; --k) {
        double s = x[k];
        for (int j = k + 1; j < N; ++j)
            s -= A[k + N * j] * x[j];
        x[k] = s / A[k + N * k];
    }
    return 0;
}

/* qdd and lambda at (t, q, v, y); ydot = rate(t, q, v, y) with first-order states. */
static int accelerations(const rk4_model *md, const rk4_first_order *fo, work *w, double t,
                         const double *q, const double *v, const double *y, double *qdd,
                         double *lambda, double *ydot)
{
    const int n = md->n, m = md->m, N = w->N;
    const int forced = fo && fo->force_y ? fo->force_y(t, q, v, y, w->f, md->user)
                       : md->force             ? md->force(t, q, v, w->f, md->user)
                                               : (memset(w->f, 0, sizeof(double) * n), 0);
    if (md->mass(t, q, w->M, md->user) || forced)
        return -1;
    if (fo && fo->rate(t, q, v, y, ydot, md->user))
        return -1;
    if (m > 0 && (md->jacobian(t, q, w->J, md->user) || md->accel(t, q, v, w->c, md->user)))
        return -1;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i)
            w->A[i + N * j] = w->M[i + n * j];
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < n; ++j) {
            w->A[(n + i) + N * j] = w->J[i + m * j];
            w->A[j + N * (n + i)] = w->J[i + m * j];
        }
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j)
            w->A[(n + i) + N * (n + j)] = 0.0;
    memcpy(w->rhs, w->f, sizeof(double) * n);
    for (int i = 0; i < m; ++i)
        w->rhs[n + i] = -w->c[i];
    if (gauss(N, w->A, w->rhs))
        return -1;
    memcpy(qdd, w->rhs, sizeof(double) * n);
    if (lambda)
        memcpy(lambda, w->rhs + n, sizeof(double) * m);
    return 0;
}

int index1_rk4(const rk4_model *md, double t0, double t_end, long steps, double *q, double *v,
               double *qdd_out, double *lambda_out)
{
    return index1_rk4_y(md, NULL, t0, t_end, steps, q, v, NULL, qdd_out, lambda_out, NULL);
}

int index1_rk4_y(const rk4_model *md, const rk4_first_order *fo, double t0, double t_end,
                 long steps, double *q, double *v, double *y, double *qdd_out, double *lambda_out,
                 double *ydot_out)
{
    const int n = md->n, m = md->m, N = n + m, r = fo ? fo->r : 0;
    if (fo && (r < 0 || !y || !fo->rate))
        return -1;
    work w = {n, m, N, NULL, NULL, NULL, NULL, NULL, NULL};
    double *buf = calloc((size_t)(n * n + m * n + N * N + N + m + n + 12 * n + m + 1 + 6 * r),
                         sizeof(double));
    if (!buf)
        return -1;
    w.M = buf;
    w.J = w.M + n * n;
    w.A = w.J + m * n;
    w.rhs = w.A + N * N;
    w.c = w.rhs + N;
    w.f = w.c + m;
    double *kq[4], *kv[4], *ky[4], *qs = w.f + n + 8 * n, *vs = qs + n, *lam = vs + n;
    double *ys = lam + m + 1;
    for (int s = 0; s < 4; ++s) {
        kq[s] = w.f + n + 2 * s * n;
        kv[s] = kq[s] + n;
        ky[s] = ys + r + s * r;
    }
    const double h = (t_end - t0) / (double)steps;
    static const double c[4] = {0.0, 0.5, 0.5, 1.0}, b[4] = {1.0, 2.0, 2.0, 1.0};
    int status = 0;
    for (long i = 0; i < steps && !status; ++i) {
        const double t = t0 + (double)i * h;
        for (int s = 0; s < 4 && !status; ++s) {
            for (int j = 0; j < n; ++j) {
                qs[j] = q[j] + (s ? c[s] * h * kq[s - 1][j] : 0.0);
                vs[j] = v[j] + (s ? c[s] * h * kv[s - 1][j] : 0.0);
            }
            for (int j = 0; j < r; ++j)
                ys[j] = y[j] + (s ? c[s] * h * ky[s - 1][j] : 0.0);
            memcpy(kq[s], vs, sizeof(double) * n);
            status = accelerations(md, fo, &w, t + c[s] * h, qs, vs, ys, kv[s], NULL, ky[s]);
        }
        for (int j = 0; j < n && !status; ++j) {
            q[j] += h / 6.0 * (b[0] * kq[0][j] + b[1] * kq[1][j] + b[2] * kq[2][j] + b[3] * kq[3][j]);
            v[j] += h / 6.0 * (b[0] * kv[0][j] + b[1] * kv[1][j] + b[2] * kv[2][j] + b[3] * kv[3][j]);
        }
        for (int j = 0; j < r && !status; ++j)
            y[j] += h / 6.0 * (b[0] * ky[0][j] + b[1] * ky[1][j] + b[2] * ky[2][j] + b[3] * ky[3][j]);
    }
    if (!status && (qdd_out || lambda_out || ydot_out)) {
        double *qdd = qdd_out ? qdd_out : kv[0];
        status = accelerations(md, fo, &w, t_end, q, v, y, qdd, lambda_out ? lambda_out : lam,
                               ydot_out ? ydot_out : ky[0]);
    }
    free(buf);
    return status;
}
