/* Work against accuracy: galpha against SUNDIALS IDA (Debian's libsundials-dev) on the same
 * model code, measured in the same run.
 *
 * IDA gets the index-1 formulation, with y = (q, v, lambda):
 *     q' - v = 0,   M(q) v' - f(q, v) + Phi_q^T lambda = 0,
 *     Phi_q(q) v' + (Phi_qq(v, v) + ...) = 0        (the acceleration-level constraint),
 * lambda algebraic and excluded from the error test (IDASetSuppressAlg), a dense direct linear
 * solver with IDA's own difference-quotient Jacobian, consistent initial values (the same ones
 * galpha starts from), and rtol = atol swept over half decades. (The stabilized index-2 GGL
 * form was tried first: IDA's corrector fails at t = 0 for rtol <= 1e-5, its iteration matrix
 * being singular to working precision at the tiny first steps.) The index-1 form lets the
 * position and velocity constraints drift by the integration error; galpha keeps them.
 * galpha runs fixed steps swept over h, and adaptive steps (index 2 and 3) over rtol = atol
 * from 1e-3 to 1e-9. For both: the error of the positions at the final time against the reference, that
 * of the multipliers (IDA's own; galpha's consistent output, the default, and the step's own
 * lambda), CPU time (best of REPEATS runs, of SLOW_REPEATS for runs over SLOW_SECONDS,
 * reading the multipliers included), residual
 * evaluations (IDA: including those of its Jacobian) and factorizations.
 *
 * Usage: ida_workprecision [andrews|slider_crank]; CSV on stdout. */
#include <galpha.h>
#include <ida/ida.h>
#include <math.h>
#include <nvector/nvector_serial.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <time.h>

#include "scenes/andrews.h"
#include "scenes/index1_rk4.h"
#include "scenes/slider_crank.h"

/* CPU time of a setting: the best of this many runs, for IDA and galpha alike (this shared
 * virtual machine scatters single runs of a millisecond by up to 50 %; with the best of 11 the
 * ratio of the two still moved by 1.6x between runs of the program). */
#define REPEATS 31
/* Runs that long vary little in time: fewer repetitions keep the bench to minutes. */
#define SLOW_REPEATS 5
#define SLOW_SECONDS 0.2

typedef struct model {
    const char *name;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_stiffness_fn stiffness;
    ga_constraint_accel_fn accel;
    ga_constraint_fn dt; /* Phi_t (0: the scenes' constraints do not depend on t) */
    void *user;
    double q0[AN31_N], v0[AN31_N], t_end, h0;
    int constant_mass;
    const double *ref;  /* reference q at t_end (the compared components) */
    int first, compared; /* compared: q[first .. first + compared) */
    double *M, *f, *J, *phi; /* scratch for the IDA residual */
    const double *lambda_ref; /* reference multipliers at t_end (all m) */
} model;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* max over the compared components of |x_i - ref_i| / |ref_i| */
static double error_of(const model *md, const double *q)
{
    double e = 0.0;
    for (int i = 0; i < md->compared; ++i)
        e = fmax(e, fabs(q[md->first + i] - md->ref[i]) / fabs(md->ref[i]));
    return e;
}

/* max_i |lambda_i - ref_i| / max_i |ref_i| */
static double lambda_error_of(const model *md, const double *lambda)
{
    double e = 0.0, scale = 0.0;
    for (int i = 0; i < md->m; ++i) {
        e = fmax(e, fabs(lambda[i] - md->lambda_ref[i]));
        scale = fmax(scale, fabs(md->lambda_ref[i]));
    }
    return e / scale;
}

/* ---- IDA, GGL formulation ---------------------------------------------------------------- */
static int ida_residual(double t, N_Vector yy, N_Vector yp, N_Vector rr, void *data)
{
    model *md = data;
    const int n = md->n, m = md->m;
    const double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp);
    double *r = N_VGetArrayPointer(rr);
    const double *q = y, *v = y + n, *lam = y + 2 * n;
    const double *qd = d, *vd = d + n;
    if (md->mass(t, q, md->M, md->user) || md->force(t, q, v, md->f, md->user) ||
        md->accel(t, q, v, md->phi, md->user) || md->jacobian(t, q, md->J, md->user))
        return 1;
    for (int i = 0; i < n; ++i) {
        double dyn = -md->f[i];
        for (int j = 0; j < n; ++j)
            dyn += md->M[i + n * j] * vd[j];
        for (int k = 0; k < m; ++k)
            dyn += md->J[k + m * i] * lam[k];
        r[i] = qd[i] - v[i];
        r[n + i] = dyn;
    }
    for (int k = 0; k < m; ++k) {
        double ga = md->phi[k];
        for (int j = 0; j < n; ++j)
            ga += md->J[k + m * j] * vd[j];
        r[2 * n + k] = ga;
    }
    return 0;
}

typedef struct run_result {
    double err, lambda_err, lambda_step_err, cpu;
    long long residuals, factorizations, steps;
    int ok;
} run_result;

static run_result run_ida(model *md, double tol, const double *qdd0, const double *lam0)
{
    const int n = md->n, m = md->m, N = 2 * n + m;
    run_result r = {0, 0, 0, 0, 0, 0, 0, 0};
    SUNContext ctx;
    SUNContext_Create(NULL, &ctx);
    N_Vector yy = N_VNew_Serial(N, ctx), yp = N_VNew_Serial(N, ctx), id = N_VNew_Serial(N, ctx);
    double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp), *ids = N_VGetArrayPointer(id);
    memset(y, 0, sizeof(double) * N);
    memset(d, 0, sizeof(double) * N);
    memcpy(y, md->q0, sizeof(double) * n);
    memcpy(y + n, md->v0, sizeof(double) * n);
    memcpy(y + 2 * n, lam0, sizeof(double) * m);
    memcpy(d, md->v0, sizeof(double) * n); /* q' = v (mu = 0) */
    memcpy(d + n, qdd0, sizeof(double) * n);
    for (int i = 0; i < N; ++i)
        ids[i] = i < 2 * n ? 1.0 : 0.0;
    SUNMatrix A = SUNDenseMatrix(N, N, ctx);
    SUNLinearSolver LS = SUNLinSol_Dense(yy, A, ctx);
    void *mem = IDACreate(ctx);
    const double t0 = now();
    int flag = IDAInit(mem, ida_residual, 0.0, yy, yp);
    flag |= IDASStolerances(mem, tol, tol);
    flag |= IDASetUserData(mem, md);
    flag |= IDASetLinearSolver(mem, LS, A);
    flag |= IDASetId(mem, id);
    flag |= IDASetSuppressAlg(mem, SUNTRUE);
    flag |= IDASetMaxNumSteps(mem, 200000);
    double tret = 0.0;
    if (!flag)
        flag = IDASolve(mem, md->t_end, &tret, yy, yp, IDA_NORMAL);
    r.cpu = now() - t0;
    if (flag >= 0) {
        long int nre = 0, nrel = 0, nsetups = 0, nsteps = 0;
        IDAGetNumResEvals(mem, &nre);
        IDAGetNumLinResEvals(mem, &nrel);
        IDAGetNumLinSolvSetups(mem, &nsetups);
        IDAGetNumSteps(mem, &nsteps);
        r.residuals = nre + nrel;
        r.factorizations = nsetups;
        r.steps = nsteps;
        r.err = error_of(md, y);
        r.lambda_err = lambda_error_of(md, y + 2 * n); /* IDA's own multipliers */
        r.lambda_step_err = r.lambda_err;
        r.ok = 1;
    }
    IDAFree(&mem);
    SUNLinSolFree(LS);
    SUNMatDestroy(A);
    N_VDestroy(yy);
    N_VDestroy(yp);
    N_VDestroy(id);
    SUNContext_Free(&ctx);
    return r;
}

/* ---- galpha, fixed steps ------------------------------------------------------------------ */
/* galpha fixed steps (h > 0, index 3) or adaptive (h = 0, tolerance rtol, in `formulation`) */
static run_result run_galpha_mode(const model *md, double h, double newton_tol, int tangent_mode,
                                  double rtol, int formulation)
{
    run_result r = {0, 0, 0, 0, 0, 0, 0, 0};
    ga_solver *s = NULL;
    double q[AN31_N], lambda[AN31_M];
    ga_create(md->n, md->m, &s);
    ga_set_callbacks(s, md->mass, md->force, md->constraint, md->jacobian, md->user);
    ga_set_tangents(s, md->stiffness, NULL);
    ga_set_constraint_accel(s, md->accel);
    ga_set_constraint_dt(s, md->dt);
    ga_set_constant_mass(s, md->constant_mass);
    ga_set_rho_inf(s, 0.7);
    if (newton_tol > 0.0) /* else the default: a tenth of the local tolerance in adaptive mode */
        ga_set_newton(s, newton_tol, 20);
    ga_set_tangent_mode(s, tangent_mode);
    if (h == 0.0) {
        ga_set_formulation(s, formulation);
        ga_set_tolerances(s, rtol, rtol);
    }
    const long steps = h > 0.0 ? lround(md->t_end / h) : 0;
    const double t0 = now();
    ga_status st = ga_init(s, 0.0, md->q0, md->v0);
    for (long k = 0; k < steps && !st; ++k)
        st = ga_step(s, h);
    if (!st && h == 0.0)
        st = ga_advance(s, md->t_end);
    if (!st)
        st = ga_get_lambda(s, lambda); /* consistent output: its cost is counted */
    r.cpu = now() - t0;
    if (!st) {
        ga_get_q(s, q);
        r.err = error_of(md, q);
        r.lambda_err = lambda_error_of(md, lambda);
        ga_set_output(s, GA_OUTPUT_STEP);
        ga_get_lambda(s, lambda);
        r.lambda_step_err = lambda_error_of(md, lambda);
        ga_get_counter(s, GA_COUNT_RESIDUALS, &r.residuals);
        ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &r.factorizations);
        ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
        r.ok = 1;
    }
    ga_free(s);
    return r;
}

static void print_row(const char *scene, const char *method, double setting, run_result r)
{
    if (r.ok)
        printf("%s,%s,%.6g,%.6e,%.6e,%.6e,%.6e,%lld,%lld,%lld\n", scene, method, setting, r.err,
               r.lambda_err, r.lambda_step_err, r.cpu, r.residuals, r.factorizations, r.steps);
    else
        printf("%s,%s,%.6g,nan,nan,nan,nan,0,0,0\n", scene, method, setting);
    fflush(stdout);
}

static slider_crank SC;
static double SC_REF[SC_N], SC_LAMBDA_REF[SC_M];

int main(int argc, char **argv)
{
    const char *which = argc > 1 ? argv[1] : "andrews";
    model md;
    memset(&md, 0, sizeof md);
    if (strcmp(which, "slider_crank") == 0) {
        SC = slider_crank_paper();
        md = (model){"slider_crank", SC_N, SC_M, sc_mass, sc_force, sc_constraint, sc_jacobian,
                     sc_stiffness, sc_constraint_accel, sc_constraint_dt, &SC, {0}, {0}, 1.0,
                     5e-3, 1, NULL, 0,
                     0, NULL, NULL, NULL, NULL, NULL};
        sc_initial(&SC, M_PI / 2, md.q0, md.v0);
        /* reference: independent RK4 on the index-1 form, 400 000 steps */
        double v[SC_N];
        memcpy(SC_REF, md.q0, sizeof SC_REF);
        memcpy(v, md.v0, sizeof v);
        rk4_model rk = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &SC};
        index1_rk4(&rk, 0.0, 1.0, 400000, SC_REF, v, NULL, SC_LAMBDA_REF);
        md.lambda_ref = SC_LAMBDA_REF;
        md.ref = SC_REF + SC_TH1; /* compared: the crank angle */
        md.first = SC_TH1;
        md.compared = 1;
    } else {
        md = (model){"andrews7", AN7_N, AN7_M, an7_mass, an7_force, an7_constraint,
                     an7_jacobian, NULL, an7_constraint_accel, an7_constraint_dt, NULL, {0},
                     {0}, andrews_t_end,
                     3e-4, 0, andrews_q_ref, 0, 7, NULL, NULL, NULL, NULL,
                     andrews_lambda_ref};
        memcpy(md.q0, andrews_q0, sizeof andrews_q0);
    }
    md.M = malloc(sizeof(double) * md.n * md.n);
    md.f = malloc(sizeof(double) * md.n);
    md.J = malloc(sizeof(double) * md.m * md.n);
    md.phi = malloc(sizeof(double) * md.m);
    /* consistent initial accelerations and multipliers for IDA: galpha's ga_init */
    double qdd0[AN31_N], lam0[AN31_M];
    {
        ga_solver *s = NULL;
        ga_create(md.n, md.m, &s);
        ga_set_callbacks(s, md.mass, md.force, md.constraint, md.jacobian, md.user);
        ga_set_constraint_accel(s, md.accel);
        ga_init(s, 0.0, md.q0, md.v0);
        ga_get_qdd(s, qdd0);
        ga_get_lambda(s, lam0);
        ga_free(s);
    }
    /* The settings: IDA over rtol = atol; galpha at fixed steps (over half octaves of h, so
     * that the best fixed step for an error is found to within 1.4x) with full Newton tangents
     * (default) and simplified Newton (tangents neglected: the right choice when beta h^2 K_t
     * is small against M, as here), and adaptive with the default tangents (in the index-2
     * formulation they include the curvature of the velocity constraint, without which Newton
     * converges only linearly: on Andrews 25 % more residuals and 10 % more time). The
     * repetitions are the outer loop, so that every setting samples the same phases of the
     * machine's speed. */
    enum { N_IDA = 17, N_FIXED = 19, N_ADAPTIVE = 13 };
    enum { N_SETTINGS = N_IDA + 2 * N_FIXED + 2 * N_ADAPTIVE };
    typedef struct setting {
        const char *method;
        double value, h, newton_tol, rtol;
        int tangent_mode, formulation;
    } setting;
    setting set[N_SETTINGS];
    run_result best[N_SETTINGS];
    int ns = 0;
    for (int k = 0; k < N_IDA; ++k)
        set[ns++] = (setting){"ida", pow(10.0, -2.0 - 0.5 * k), 0, 0, 0, 0, 0};
    for (int k = 0; k < N_FIXED; ++k) {
        /* a whole number of steps to t_end */
        const double h = md.t_end / (double)lround(md.t_end / (md.h0 * 4.0 / pow(2.0, 0.5 * k)));
        /* Newton tolerance well below the discretization error, which falls like h^2 */
        const double tol = fmin(1e-6, 1e-4 * (h / md.h0) * (h / md.h0));
        set[ns++] = (setting){"galpha", h, h, tol, 0, GA_TANGENT_AUTO, GA_INDEX3};
        set[ns++] = (setting){"galpha_simplified", h, h, tol, 0, GA_TANGENT_NEGLECT, GA_INDEX3};
    }
    for (int k = 0; k < N_ADAPTIVE; ++k) {
        const double rtol = pow(10.0, -3.0 - 0.5 * k);
        set[ns++] = (setting){"galpha_adaptive", rtol, 0.0, 0.0, rtol, GA_TANGENT_AUTO,
                              GA_INDEX2_STABILIZED};
        set[ns++] = (setting){"galpha_adaptive_index3", rtol, 0.0, 0.0, rtol, GA_TANGENT_AUTO,
                              GA_INDEX3};
    }
    for (int rep = 0; rep < REPEATS; ++rep)
        for (int i = 0; i < N_SETTINGS; ++i) {
            const setting *c = &set[i];
            if (rep >= SLOW_REPEATS && best[i].ok && best[i].cpu > SLOW_SECONDS)
                continue;
            const run_result r = c->method[0] == 'i'
                                     ? run_ida(&md, c->value, qdd0, lam0)
                                     : run_galpha_mode(&md, c->h, c->newton_tol,
                                                       c->tangent_mode, c->rtol,
                                                       c->formulation);
            if (rep == 0 || (r.ok && r.cpu < best[i].cpu))
                best[i] = r;
        }
    printf("scene,method,setting,error,lambda_error,lambda_step_error,cpu_seconds,residuals,"
           "factorizations,steps\n");
    for (int i = 0; i < N_SETTINGS; ++i)
        print_row(md.name, set[i].method, set[i].value, best[i]);
    free(md.M);
    free(md.f);
    free(md.J);
    free(md.phi);
    return 0;
}
