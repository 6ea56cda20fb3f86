/* The N-link chain (examples/scenes/chain.h) on the sparse path: galpha (KLU) against SUNDIALS
 * IDA with its KLU linear solver (Debian's libsundials-dev), on the same model code.
 *
 * IDA gets the index-1 formulation with y = (q, v, lambda), 8N unknowns:
 *     q' - v = 0,   M v' - f + Phi_q^T lambda = 0,   Phi_q v' + Phi_qq(v, v) = 0,
 * lambda algebraic and out of the error test (IDASetSuppressAlg), KLU in the natural ordering
 * (its fastest here), its Jacobian
 * dF/dy + c_j dF/dy' assembled here in compressed rows (the chain's derivatives, written out
 * below), consistent initial values from galpha's ga_init. galpha takes fixed steps (index 3,
 * exact K_t, declared patterns, the Newton tolerance min(1e-6, 1e-4 (h / 1e-2)^2) as in
 * ida_workprecision) or adaptive ones (rtol = atol, everything else default).
 *
 * The error is the largest absolute difference from a reference run over all coordinates
 * (x, y in m for links of 1 m, theta in rad) at t_end. The reference is galpha at a small
 * fixed step; the `reference` mode also reports the difference to the run at twice that step
 * (its own error is about a third of it, order 2).
 *
 * Usage:
 *   ida_chain reference N T h FILE       galpha at h to T, q written to FILE (binary doubles)
 *   ida_chain run N T METHOD VALUE FILE  METHOD: galpha (VALUE = h), galpha_adaptive or ida
 *                                        (VALUE = rtol = atol); one CSV line on stdout:
 *   links,method,setting,error,cpu_seconds,steps,factorizations,peak_rss_kib
 * One run per process, so that the peak resident memory is that run's. */
#include <galpha.h>
#include <ida/ida.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_sparse.h>
#include <time.h>

#include "scenes/chain.h"

enum { X = 0, Y = 1, TH = 2 };
#define Q(i, k) (3 * (i) + (k))

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static long peak_rss_kib(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long kib = -1;
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "VmHWM:", 6) == 0)
            kib = atol(line + 6);
    if (f)
        fclose(f);
    return kib;
}

/* ---- galpha --------------------------------------------------------------------------------- */

static ga_solver *chain_solver(chain *c)
{
    ga_solver *s = NULL;
    if (ga_create(3 * c->links, 2 * c->links, &s) || chain_declare_patterns(c, s) ||
        ga_set_callbacks(s, chain_mass, chain_force, chain_constraint, chain_jacobian, c) ||
        ga_set_tangents(s, chain_stiffness, NULL) || ga_set_constraint_accel(s, chain_constraint_accel) ||
        ga_set_constraint_dt(s, chain_constraint_dt) || ga_set_constant_mass(s, 1) ||
        ga_set_linear_solver(s, GA_LINEAR_SPARSE)) {
        fprintf(stderr, "galpha setup: %s\n", s ? ga_last_error(s) : "no memory");
        exit(1);
    }
    return s;
}

typedef struct outcome {
    double cpu;
    long long steps, factorizations;
} outcome;

/* h > 0: fixed steps; h == 0: adaptive at rtol = atol = tol */
static outcome run_galpha(chain *c, double T, double h, double tol, double *q)
{
    const double t0 = now();
    ga_solver *s = chain_solver(c);
    const int n = 3 * c->links;
    double *q0 = malloc(sizeof(double) * (size_t)n), *v0 = malloc(sizeof(double) * (size_t)n);
    if (!q0 || !v0)
        exit(1);
    chain_initial(c, q0, v0);
    if (h == 0.0)
        ga_set_tolerances(s, tol, tol);
    else  /* well below the discretization error, which falls like h^2 (as ida_workprecision) */
        ga_set_newton(s, fmin(1e-6, 1e-4 * (h / 1e-2) * (h / 1e-2)), 20);
    ga_status st = ga_init(s, 0.0, q0, v0);
    if (h > 0.0) {
        const long steps = lround(T / h);
        for (long k = 0; k < steps && !st; ++k)
            st = ga_step(s, T / (double)steps);
    } else if (!st) {
        st = ga_advance(s, T);
    }
    if (st) {
        fprintf(stderr, "galpha: %s\n", ga_last_error(s));
        exit(1);
    }
    outcome o = {now() - t0, 0, 0};
    ga_get_q(s, q);
    ga_get_counter(s, GA_COUNT_STEPS, &o.steps);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &o.factorizations);
    ga_free(s);
    free(q0);
    free(v0);
    return o;
}

/* ---- IDA, index-1 form -------------------------------------------------------------------- */

typedef struct ida_data {
    chain *c;
    int N;                 /* links */
    double *f, *J, *accel; /* scratch: force (3N), Phi_q values (pattern order), Phi_qq(v, v) */
} ida_data;

/* Phi_q's entries in chain_jacobian's order: per link i, the x row (x_i, th_i[, x_{i-1},
 * th_{i-1}]) then the y row; the offset of link i's first entry. */
static long jac_offset(int i) { return i == 0 ? 0 : 4 + 8L * (i - 1); }

static int ida_residual(double t, N_Vector yy, N_Vector yp, N_Vector rr, void *data)
{
    ida_data *d = data;
    const int N = d->N, n = 3 * N;
    const double *y = N_VGetArrayPointer(yy), *dy = N_VGetArrayPointer(yp);
    double *r = N_VGetArrayPointer(rr);
    const double *q = y, *v = y + n, *lam = y + 2 * n, *qd = dy, *vd = dy + n;
    chain_force(t, q, v, d->f, d->c);
    chain_jacobian(t, q, d->J, d->c);
    chain_constraint_accel(t, q, v, d->accel, d->c);
    for (int j = 0; j < n; ++j) {
        const double m = j % 3 == TH ? d->c->inertia : d->c->mass;
        r[j] = qd[j] - v[j];
        r[n + j] = m * vd[j] - d->f[j];
    }
    for (int i = 0; i < N; ++i) {
        const double *J = d->J + jac_offset(i);
        const int w = i > 0 ? 4 : 2; /* entries per row */
        for (int dim = 0; dim < 2; ++dim) {
            const double *row = J + dim * w;
            const int k = 2 * i + dim;
            /* Phi_q v' + Phi_qq(v, v) */
            double g = d->accel[k] + row[0] * vd[Q(i, dim)] + row[1] * vd[Q(i, TH)];
            if (i > 0)
                g += row[2] * vd[Q(i - 1, dim)] + row[3] * vd[Q(i - 1, TH)];
            r[2 * n + k] = g;
            /* Phi_q^T lambda */
            r[n + Q(i, dim)] += row[0] * lam[k];
            r[n + Q(i, TH)] += row[1] * lam[k];
            if (i > 0) {
                r[n + Q(i - 1, dim)] += row[2] * lam[k];
                r[n + Q(i - 1, TH)] += row[3] * lam[k];
            }
        }
    }
    return 0;
}

/* dF/dy + cj dF/dy' in compressed rows, columns ascending in each row (y = q | v | lambda). */
static int ida_jacobian(double t, double cj, N_Vector yy, N_Vector yp, N_Vector rr, SUNMatrix A,
                        void *data, N_Vector t1, N_Vector t2, N_Vector t3)
{
    (void)t, (void)rr, (void)t1, (void)t2, (void)t3;
    ida_data *d = data;
    const chain *c = d->c;
    const int N = d->N, n = 3 * N;
    const double h = 0.5 * c->length;
    const double *y = N_VGetArrayPointer(yy), *dy = N_VGetArrayPointer(yp);
    const double *q = y, *v = y + n, *lam = y + 2 * n, *vd = dy + n;
    sunindextype *ptr = SUNSparseMatrix_IndexPointers(A), *col = SUNSparseMatrix_IndexValues(A);
    double *val = SUNSparseMatrix_Data(A);
    long k = 0;
#define PUT(cc, vv)                                                                            \
    do {                                                                                       \
        col[k] = (cc);                                                                         \
        val[k] = (vv);                                                                         \
        ++k;                                                                                   \
    } while (0)
    int row = 0;
    for (int j = 0; j < n; ++j) { /* q' - v */
        ptr[row++] = k;
        PUT(j, cj);
        PUT(n + j, -1.0);
    }
    for (int i = 0; i < N; ++i) { /* M v' - f + Phi_q^T lambda, rows x_i, y_i, th_i */
        const double s = sin(q[Q(i, TH)]), co = cos(q[Q(i, TH)]);
        const int next = i + 1 < N;
        for (int dim = 0; dim < 2; ++dim) {
            ptr[row++] = k;
            PUT(n + Q(i, dim), cj * c->mass);
            PUT(2 * n + 2 * i + dim, 1.0);
            if (next)
                PUT(2 * n + 2 * (i + 1) + dim, -1.0);
        }
        /* th_i: joint i as the link's start (h sin, -h cos), joint i+1 as the previous end */
        ptr[row++] = k;
        double lx = lam[2 * i], ly = lam[2 * i + 1];
        if (next)
            lx += lam[2 * (i + 1)], ly += lam[2 * (i + 1) + 1];
        PUT(Q(i, TH), h * (co * lx + s * ly));
        PUT(n + Q(i, TH), cj * c->inertia);
        PUT(2 * n + 2 * i, h * s);
        PUT(2 * n + 2 * i + 1, -h * co);
        if (next) {
            PUT(2 * n + 2 * (i + 1), h * s);
            PUT(2 * n + 2 * (i + 1) + 1, -h * co);
        }
    }
    for (int i = 0; i < N; ++i) { /* Phi_q v' + Phi_qq(v, v), rows 2i (x) and 2i+1 (y) */
        const double s = sin(q[Q(i, TH)]), co = cos(q[Q(i, TH)]), w = v[Q(i, TH)];
        const double sp = i > 0 ? sin(q[Q(i - 1, TH)]) : 0.0;
        const double cp = i > 0 ? cos(q[Q(i - 1, TH)]) : 0.0;
        const double wp = i > 0 ? v[Q(i - 1, TH)] : 0.0;
        const double a = vd[Q(i, TH)], ap = i > 0 ? vd[Q(i - 1, TH)] : 0.0;
        /* x: v'_x + h s a [- v'_xp + h sp ap] + h co w^2 [+ h cp wp^2] */
        ptr[row++] = k;
        if (i > 0)
            PUT(Q(i - 1, TH), h * cp * ap - h * sp * wp * wp);
        PUT(Q(i, TH), h * co * a - h * s * w * w);
        if (i > 0) {
            PUT(n + Q(i - 1, X), -cj);
            PUT(n + Q(i - 1, TH), cj * h * sp + 2.0 * h * cp * wp);
        }
        PUT(n + Q(i, X), cj);
        PUT(n + Q(i, TH), cj * h * s + 2.0 * h * co * w);
        /* y: v'_y - h co a [- v'_yp - h cp ap] + h s w^2 [+ h sp wp^2] */
        ptr[row++] = k;
        if (i > 0)
            PUT(Q(i - 1, TH), h * sp * ap + h * cp * wp * wp);
        PUT(Q(i, TH), h * s * a + h * co * w * w);
        if (i > 0) {
            PUT(n + Q(i - 1, Y), -cj);
            PUT(n + Q(i - 1, TH), -cj * h * cp + 2.0 * h * sp * wp);
        }
        PUT(n + Q(i, Y), cj);
        PUT(n + Q(i, TH), -cj * h * co + 2.0 * h * s * w);
    }
#undef PUT
    ptr[row] = k;
    return 0;
}

/* at most: 2 per q' - v row, 3 + 3 + 6 per link's dynamics rows, 6 + 6 per joint's rows */
static long jacobian_entries(int N) { return 6L * N + 12L * N + 12L * N; }

static outcome run_ida(chain *c, double T, double tol, double *q_out)
{
    const int Nl = c->links, n = 3 * Nl, m = 2 * Nl, NY = 2 * n + m;
    const double t0 = now();
    /* consistent initial values: galpha's (not timed: IDA is given them) */
    double *q0 = malloc(sizeof(double) * (size_t)n), *v0 = malloc(sizeof(double) * (size_t)n);
    double *qdd0 = malloc(sizeof(double) * (size_t)n), *lam0 = malloc(sizeof(double) * (size_t)m);
    if (!q0 || !v0 || !qdd0 || !lam0)
        exit(1);
    chain_initial(c, q0, v0);
    ga_solver *g = chain_solver(c);
    if (ga_init(g, 0.0, q0, v0) || ga_get_qdd(g, qdd0) || ga_get_lambda(g, lam0))
        exit(1);
    ga_free(g);
    const double untimed = now() - t0;

    ida_data d = {c, Nl, malloc(sizeof(double) * (size_t)n),
                  malloc(sizeof(double) * (size_t)chain_pattern(c, GA_MATRIX_JACOBIAN, NULL, NULL)),
                  malloc(sizeof(double) * (size_t)m)};
    SUNContext ctx;
    SUNContext_Create(NULL, &ctx);
    N_Vector yy = N_VNew_Serial(NY, ctx), yp = N_VNew_Serial(NY, ctx), id = N_VNew_Serial(NY, ctx);
    double *y = N_VGetArrayPointer(yy), *dy = N_VGetArrayPointer(yp), *ids = N_VGetArrayPointer(id);
    memset(dy, 0, sizeof(double) * (size_t)NY);
    memcpy(y, q0, sizeof(double) * (size_t)n);
    memcpy(y + n, v0, sizeof(double) * (size_t)n);
    memcpy(y + 2 * n, lam0, sizeof(double) * (size_t)m);
    memcpy(dy, v0, sizeof(double) * (size_t)n);
    memcpy(dy + n, qdd0, sizeof(double) * (size_t)n);
    for (int i = 0; i < NY; ++i)
        ids[i] = i < 2 * n ? 1.0 : 0.0;
    SUNMatrix A = SUNSparseMatrix(NY, NY, jacobian_entries(Nl), CSR_MAT, ctx);
    SUNLinearSolver LS = SUNLinSol_KLU(yy, A, ctx);
    /* KLU's fastest ordering here: the natural one of y = (q, v, lambda), 3 to 6 times faster
     * than its default AMD (or COLAMD) at 1 000 and 10 000 links, for the same steps */
    SUNLinSol_KLUSetOrdering(LS, 2);
    void *mem = IDACreate(ctx);
    int flag = IDAInit(mem, ida_residual, 0.0, yy, yp);
    flag |= IDASStolerances(mem, tol, tol);
    flag |= IDASetUserData(mem, &d);
    flag |= IDASetLinearSolver(mem, LS, A);
    flag |= IDASetJacFn(mem, ida_jacobian);
    flag |= IDASetId(mem, id);
    flag |= IDASetSuppressAlg(mem, SUNTRUE);
    flag |= IDASetMaxNumSteps(mem, 10000000);
    double tret = 0.0;
    if (!flag)
        flag = IDASolve(mem, T, &tret, yy, yp, IDA_NORMAL);
    if (flag < 0) {
        fprintf(stderr, "IDA failed: flag %d\n", flag);
        exit(1);
    }
    outcome o = {now() - t0 - untimed, 0, 0};
    long nsteps = 0, nsetups = 0;
    IDAGetNumSteps(mem, &nsteps);
    IDAGetNumLinSolvSetups(mem, &nsetups);
    o.steps = nsteps;
    o.factorizations = nsetups;
    memcpy(q_out, y, sizeof(double) * (size_t)n);
    IDAFree(&mem);
    SUNLinSolFree(LS);
    SUNMatDestroy(A);
    N_VDestroy(yy);
    N_VDestroy(yp);
    N_VDestroy(id);
    SUNContext_Free(&ctx);
    free(d.f);
    free(d.J);
    free(d.accel);
    free(q0);
    free(v0);
    free(qdd0);
    free(lam0);
    return o;
}

static double max_difference(const double *a, const double *b, int n)
{
    double e = 0.0;
    for (int i = 0; i < n; ++i)
        e = fmax(e, fabs(a[i] - b[i]));
    return e;
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: ida_chain reference N T h FILE | ida_chain run N T "
                        "galpha|galpha_adaptive|ida VALUE FILE\n");
        return 2;
    }
    const int reference = strcmp(argv[1], "reference") == 0;
    chain c = chain_make(atoi(argv[2]));
    const double T = atof(argv[3]);
    const int n = 3 * c.links;
    double *q = malloc(sizeof(double) * (size_t)n), *ref = malloc(sizeof(double) * (size_t)n);
    if (!q || !ref)
        return 1;
    if (reference) {
        const double h = atof(argv[4]);
        run_galpha(&c, T, 2.0 * h, 0.0, ref);
        const outcome o = run_galpha(&c, T, h, 0.0, q);
        FILE *f = fopen(argv[5], "wb");
        if (!f || fwrite(q, sizeof(double), (size_t)n, f) != (size_t)n)
            return 1;
        fclose(f);
        fprintf(stderr, "reference: %d links, h = %g to t = %g, %.1f s; difference to h = %g: "
                        "%.2e\n", c.links, h, T, o.cpu, 2.0 * h, max_difference(q, ref, n));
        return 0;
    }
    if (argc < 7)
        return 2;
    const char *method = argv[4];
    const double value = atof(argv[5]);
    FILE *f = fopen(argv[6], "rb");
    if (!f || fread(ref, sizeof(double), (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "no reference for %d links in %s\n", c.links, argv[6]);
        return 1;
    }
    fclose(f);
    outcome o;
    if (strcmp(method, "galpha") == 0)
        o = run_galpha(&c, T, value, 0.0, q);
    else if (strcmp(method, "galpha_adaptive") == 0)
        o = run_galpha(&c, T, 0.0, value, q);
    else if (strcmp(method, "ida") == 0)
        o = run_ida(&c, T, value, q);
    else
        return 2;
    printf("%d,%s,%g,%.6e,%.6e,%lld,%lld,%ld\n", c.links, method, value, max_difference(q, ref, n),
           o.cpu, o.steps, o.factorizations, peak_rss_kib());
    free(q);
    free(ref);
    return 0;
}
