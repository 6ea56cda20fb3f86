/* The same method in PETSc: galpha (m = 0) against PETSc's TSALPHA2 (generalized-alpha for
 * second-order systems, Debian's petsc-dev) on one structural model and one model code
 * (examples/scenes/lattice.h: a two-material cantilever lattice sagging under gravity, no
 * constraints), at the same rho_inf (0.9), both with a direct sparse solve by KLU:
 *   galpha: its sparse path (galpha's LU in KLU's ordering), modified Newton with the
 *           matrix kept across steps while it contracts, Newton tolerance tied to h as in
 *           bench/ida_chain.c;
 *   PETSc:  TSALPHA2 with its SNES Newton (line search off: the plain Newton step, as galpha)
 *           and KSPPREONLY + PCLU with MATSOLVERKLU (the symbolic analysis kept, a numeric
 *           factorization per Jacobian); everything else at PETSc's defaults, and any PETSc
 *           option given after the arguments (-snes_rtol, -snes_lag_jacobian, ...) applies.
 * Fixed steps, and each code's own adaptivity (galpha: ga_advance at rtol = atol; PETSc: its
 * basic TSAdapt on alpha2's own error estimate, rtol = atol), error = the largest difference
 * of a displacement at T from a galpha run at a small fixed step (the reference; its own
 * difference to PETSc at that step is printed too), CPU time and peak memory of one run per
 * process.
 *
 *   petsc_alpha2 reference NY T h FILE         galpha at h, q to FILE (and PETSc at h up to
 *                                              20 000 unknowns, its difference printed)
 *   petsc_alpha2 run NY T METHOD VALUE FILE    METHOD: galpha, petsc or petsc_lagged (VALUE =
 *                                              h), galpha_adaptive, petsc_adaptive or
 *                                              petsc_adaptive_lagged (VALUE = tol)
 * petsc_lagged: SNES keeps its Jacobian over up to 50 iterations, across steps
 * (-snes_lag_jacobian 50 -snes_lag_jacobian_persists), PETSc's own way to galpha's reuse.
 * The lattice has NX = 4 NY columns (n = 2 (NX - 1) NY unknowns). CSV line on stdout:
 * unknowns,method,setting,error,cpu_seconds,steps,newton_iterations,factorizations,peak_rss_kib */
#include <galpha.h>
#include <math.h>
#include <petscts.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "scenes/lattice.h"

static const double kSoft = 1e4, kContrast = 1e3, kRho = 0.9;

typedef struct outcome {
    double cpu;
    long long steps, iterations, factorizations;
} outcome;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void fail(const char *what)
{
    fprintf(stderr, "%s\n", what);
    exit(1);
}

/* ---- galpha -------------------------------------------------------------------------------- */

static outcome run_galpha(lattice *l, double T, double h, double tol, double *q)
{
    const double t0 = cpu_now();
    ga_solver *s = NULL;
    const int n = l->n;
    double *v = calloc((size_t)n, sizeof(double));
    if (!v || ga_create(n, 0, &s) || lattice_declare_patterns(l, s) ||
        ga_set_callbacks(s, lattice_mass, lattice_force, NULL, NULL, l) ||
        ga_set_tangents(s, lattice_stiffness, NULL) || ga_set_constant_mass(s, 1) ||
        ga_set_rho_inf(s, kRho) || ga_set_linear_solver(s, GA_LINEAR_SPARSE))
        fail("galpha: set-up failed");
    if (h == 0.0)
        ga_set_tolerances(s, tol, tol);
    else /* well below the discretization error, which falls like h^2 (as ida_chain) */
        ga_set_newton(s, fmin(1e-6, 1e-4 * (h / 1e-2) * (h / 1e-2)), 20);
    memset(q, 0, sizeof(double) * (size_t)n);
    ga_status st = ga_init(s, 0.0, q, v);
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
    outcome o = {cpu_now() - t0, 0, 0, 0};
    ga_get_q(s, q);
    ga_get_counter(s, GA_COUNT_STEPS, &o.steps);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &o.iterations);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &o.factorizations);
    ga_free(s);
    free(v);
    return o;
}

/* ---- PETSc TSALPHA2 ------------------------------------------------------------------------ */

typedef struct petsc_model {
    lattice *l;
    double *values; /* the AIJ matrix's value array (K_t + shift_a M), in the lattice's order */
    int *diagonal;  /* position of each row's diagonal entry */
    long long jacobians; /* each one factorized by the LU preconditioner */
} petsc_model;

/* F(t, U, V, A) = M A - f(U) */
static PetscErrorCode residual(TS ts, PetscReal t, Vec U, Vec V, Vec A, Vec F, void *ctx)
{
    (void)ts;
    (void)V;
    petsc_model *m = ctx;
    const PetscScalar *u, *a;
    PetscScalar *f;
    PetscCall(VecGetArrayRead(U, &u));
    PetscCall(VecGetArrayRead(A, &a));
    PetscCall(VecGetArray(F, &f));
    lattice_force(t, u, NULL, f, m->l);
    for (int i = 0; i < m->l->n; ++i)
        f[i] = m->l->mass * a[i] - f[i];
    PetscCall(VecRestoreArray(F, &f));
    PetscCall(VecRestoreArrayRead(A, &a));
    PetscCall(VecRestoreArrayRead(U, &u));
    return 0;
}

/* dF/dU + shift_v dF/dV + shift_a dF/dA = K_t + shift_a M, written into the matrix's own array */
static PetscErrorCode jacobian(TS ts, PetscReal t, Vec U, Vec V, Vec A, PetscReal shift_v,
                               PetscReal shift_a, Mat J, Mat P, void *ctx)
{
    (void)ts;
    (void)t;
    (void)V;
    (void)A;
    (void)shift_v;
    petsc_model *m = ctx;
    const PetscScalar *u;
    ++m->jacobians;
    PetscCall(VecGetArrayRead(U, &u));
    lattice_stiffness_values(m->l, u, m->values);
    PetscCall(VecRestoreArrayRead(U, &u));
    for (int i = 0; i < m->l->n; ++i)
        m->values[m->diagonal[i]] += shift_a * m->l->mass;
    PetscCall(MatAssemblyBegin(P, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(P, MAT_FINAL_ASSEMBLY));
    if (J != P) {
        PetscCall(MatAssemblyBegin(J, MAT_FINAL_ASSEMBLY));
        PetscCall(MatAssemblyEnd(J, MAT_FINAL_ASSEMBLY));
    }
    return 0;
}

static outcome run_petsc(lattice *l, double T, double h, double tol, int lagged, double *q_out)
{
    const double t0 = cpu_now();
    const int n = l->n;
    petsc_model m = {l, malloc(sizeof(double) * (size_t)l->nnz), malloc(sizeof(int) * (size_t)n), 0};
    if (!m.values || !m.diagonal)
        fail("out of memory");
    for (int i = 0; i < n; ++i)
        for (int p = l->rowptr[i]; p < l->rowptr[i + 1]; ++p)
            if (l->colind[p] == i)
                m.diagonal[i] = p;
    Mat J;
    Vec U, V, F;
    TS ts;
    SNES snes;
    SNESLineSearch ls;
    KSP ksp;
    PC pc;
    PetscCallAbort(PETSC_COMM_SELF, MatCreateSeqAIJWithArrays(PETSC_COMM_SELF, n, n, l->rowptr,
                                                              l->colind, m.values, &J));
    PetscCallAbort(PETSC_COMM_SELF, MatCreateVecs(J, &U, &F));
    PetscCallAbort(PETSC_COMM_SELF, VecDuplicate(U, &V));
    PetscCallAbort(PETSC_COMM_SELF, VecSet(U, 0.0));
    PetscCallAbort(PETSC_COMM_SELF, VecSet(V, 0.0));
    PetscCallAbort(PETSC_COMM_SELF, TSCreate(PETSC_COMM_SELF, &ts));
    PetscCallAbort(PETSC_COMM_SELF, TSSetType(ts, TSALPHA2));
    PetscCallAbort(PETSC_COMM_SELF, TSAlpha2SetRadius(ts, kRho));
    PetscCallAbort(PETSC_COMM_SELF, TSSetI2Function(ts, F, residual, &m));
    PetscCallAbort(PETSC_COMM_SELF, TSSetI2Jacobian(ts, J, J, jacobian, &m));
    PetscCallAbort(PETSC_COMM_SELF, TSSetMaxTime(ts, T));
    PetscCallAbort(PETSC_COMM_SELF, TSSetExactFinalTime(ts, TS_EXACTFINALTIME_MATCHSTEP));
    PetscCallAbort(PETSC_COMM_SELF, TSSetMaxSteps(ts, 100000000));
    PetscCallAbort(PETSC_COMM_SELF, TSSetMaxSNESFailures(ts, -1));
    PetscCallAbort(PETSC_COMM_SELF, TSGetSNES(ts, &snes));
    PetscCallAbort(PETSC_COMM_SELF, SNESGetLineSearch(snes, &ls));
    PetscCallAbort(PETSC_COMM_SELF, SNESLineSearchSetType(ls, SNESLINESEARCHBASIC));
    if (lagged) { /* a Jacobian kept over up to 50 Newton iterations, across steps */
        PetscCallAbort(PETSC_COMM_SELF, SNESSetLagJacobian(snes, 50));
        PetscCallAbort(PETSC_COMM_SELF, SNESSetLagJacobianPersists(snes, PETSC_TRUE));
    }
    PetscCallAbort(PETSC_COMM_SELF, SNESGetKSP(snes, &ksp));
    PetscCallAbort(PETSC_COMM_SELF, KSPSetType(ksp, KSPPREONLY));
    PetscCallAbort(PETSC_COMM_SELF, KSPGetPC(ksp, &pc));
    PetscCallAbort(PETSC_COMM_SELF, PCSetType(pc, PCLU));
    PetscCallAbort(PETSC_COMM_SELF, PCFactorSetMatSolverType(pc, MATSOLVERKLU));
    TSAdapt adapt;
    PetscCallAbort(PETSC_COMM_SELF, TSGetAdapt(ts, &adapt));
    if (h > 0.0) {
        const long steps = lround(T / h);
        PetscCallAbort(PETSC_COMM_SELF, TSSetTimeStep(ts, T / (double)steps));
        PetscCallAbort(PETSC_COMM_SELF, TSAdaptSetType(adapt, TSADAPTNONE));
    } else {
        PetscCallAbort(PETSC_COMM_SELF, TSSetTimeStep(ts, 1e-4));
        PetscCallAbort(PETSC_COMM_SELF, TSSetTolerances(ts, tol, NULL, tol, NULL));
        PetscCallAbort(PETSC_COMM_SELF, TSAdaptSetType(adapt, TSADAPTBASIC));
    }
    PetscCallAbort(PETSC_COMM_SELF, TSSetFromOptions(ts));
    PetscCallAbort(PETSC_COMM_SELF, TS2SetSolution(ts, U, V));
    PetscCallAbort(PETSC_COMM_SELF, TSSolve(ts, U));
    TSConvergedReason reason;
    PetscCallAbort(PETSC_COMM_SELF, TSGetConvergedReason(ts, &reason));
    if (reason < 0)
        fail("PETSc: TSSolve diverged");
    outcome o = {0, 0, 0, m.jacobians};
    PetscInt steps, its;
    PetscCallAbort(PETSC_COMM_SELF, TSGetStepNumber(ts, &steps));
    PetscCallAbort(PETSC_COMM_SELF, TSGetSNESIterations(ts, &its));
    const PetscScalar *u;
    PetscCallAbort(PETSC_COMM_SELF, VecGetArrayRead(U, &u));
    memcpy(q_out, u, sizeof(double) * (size_t)n);
    PetscCallAbort(PETSC_COMM_SELF, VecRestoreArrayRead(U, &u));
    PetscCallAbort(PETSC_COMM_SELF, TSDestroy(&ts));
    PetscCallAbort(PETSC_COMM_SELF, VecDestroy(&U));
    PetscCallAbort(PETSC_COMM_SELF, VecDestroy(&V));
    PetscCallAbort(PETSC_COMM_SELF, VecDestroy(&F));
    PetscCallAbort(PETSC_COMM_SELF, MatDestroy(&J));
    free(m.values);
    free(m.diagonal);
    o.cpu = cpu_now() - t0;
    o.steps = steps;
    o.iterations = its;
    return o;
}

/* ---- driver -------------------------------------------------------------------------------- */

static double max_difference(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int i = 0; i < n; ++i)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

static double max_abs(const double *a, int n)
{
    double d = 0.0;
    for (int i = 0; i < n; ++i)
        d = fmax(d, fabs(a[i]));
    return d;
}

int main(int argc, char **argv)
{
    if (argc < 6 || (strcmp(argv[1], "reference") && strcmp(argv[1], "run")) ||
        (!strcmp(argv[1], "run") && argc < 7)) {
        fprintf(stderr, "usage: petsc_alpha2 reference NY T h FILE | petsc_alpha2 run NY T "
                        "galpha|galpha_adaptive|petsc[_adaptive][_lagged] VALUE FILE "
                        "[PETSc options]\n");
        return 2;
    }
    const int reference = !strcmp(argv[1], "reference");
    const int ny = atoi(argv[2]);
    const double T = atof(argv[3]);
    const char *file = argv[reference ? 5 : 6];
    int petsc_argc = argc - (reference ? 5 : 6);
    char **petsc_argv = argv + (reference ? 5 : 6); /* its argv[0]: the file name */
    PetscCall(PetscInitialize(&petsc_argc, &petsc_argv, NULL, NULL));
    lattice l;
    if (ny < 2 || lattice_make(&l, 4 * ny, ny, kSoft, kContrast))
        fail("bad size or out of memory");
    const int n = l.n;
    double *q = malloc(sizeof(double) * (size_t)n), *ref = malloc(sizeof(double) * (size_t)n);
    if (!q || !ref)
        fail("out of memory");
    if (reference) {
        const double h = atof(argv[4]);
        const outcome g = run_galpha(&l, T, h, 0.0, ref);
        double to_petsc = NAN; /* a cross-check where PETSc's fine run takes minutes at most */
        if (n <= 20000) {
            run_petsc(&l, T, h, 0.0, 0, q);
            to_petsc = max_difference(q, ref, n);
        }
        run_galpha(&l, T, 2.0 * h, 0.0, q);
        fprintf(stderr, "reference: %d unknowns, h = %g to t = %g (%.1f s); max |u| %.3g; "
                        "PETSc at h differs by %.2e, galpha at 2h by %.2e\n",
                n, h, T, g.cpu, max_abs(ref, n), to_petsc, max_difference(q, ref, n));
        FILE *f = fopen(file, "wb");
        if (!f || fwrite(ref, sizeof(double), (size_t)n, f) != (size_t)n || fclose(f))
            fail("cannot write the reference");
    } else {
        FILE *f = fopen(file, "rb");
        if (!f || fread(ref, sizeof(double), (size_t)n, f) != (size_t)n)
            fail("no reference of this size in the file");
        fclose(f);
        const char *method = argv[4];
        const double value = atof(argv[5]);
        outcome o;
        if (!strcmp(method, "galpha"))
            o = run_galpha(&l, T, value, 0.0, q);
        else if (!strcmp(method, "galpha_adaptive"))
            o = run_galpha(&l, T, 0.0, value, q);
        else if (!strcmp(method, "petsc") || !strcmp(method, "petsc_lagged"))
            o = run_petsc(&l, T, value, 0.0, !strcmp(method, "petsc_lagged"), q);
        else if (!strcmp(method, "petsc_adaptive") || !strcmp(method, "petsc_adaptive_lagged"))
            o = run_petsc(&l, T, 0.0, value, !strcmp(method, "petsc_adaptive_lagged"), q);
        else
            fail("unknown method");
        struct rusage ru;
        getrusage(RUSAGE_SELF, &ru);
        printf("%d,%s,%g,%.6e,%.6e,%lld,%lld,%lld,%ld\n", n, method, value,
               max_difference(q, ref, n), o.cpu, o.steps, o.iterations, o.factorizations,
               ru.ru_maxrss);
    }
    free(q);
    free(ref);
    lattice_free(&l);
    PetscCall(PetscFinalize());
    return 0;
}
