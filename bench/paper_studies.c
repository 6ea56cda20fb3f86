/* The paper's studies, regenerated: writes CSV files into the directory given as argv[1]
 * (docs/paper by scripts/studies.sh); scripts/plot_studies.py draws them.
 *   trajectories  like the paper's Figs. 2, 5-7 (slider-crank; Andrews in 31 coordinates)
 *   convergence   like Figs. 3 and 9: relative error at the final time against h
 *   damping       like Fig. 8: rho_inf = 1 against 0.7 on Andrews, multiplier oscillation
 *   scaling       with and without the scaling (10), h from 1e-3 to 1e-7
 *   work          error against CPU time and residual evaluations (work-precision)
 * References: the published Andrews solution and its recomputation (docs/references.md), and the
 * independent index-1 RK4 integrator of examples/scenes for everything else. */
#include <galpha.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "scenes/andrews.h"
#include "scenes/index1_rk4.h"
#include "scenes/slider_crank.h"

typedef struct scene {
    const char *name;
    int n, m;
    ga_mass_fn mass;
    ga_force_fn force;
    ga_constraint_fn constraint;
    ga_jacobian_fn jacobian;
    ga_stiffness_fn stiffness;
    ga_constraint_accel_fn accel;
    void *user;
    double q0[AN31_N], v0[AN31_N];
    double t_end;
} scene;

typedef struct run_opts {
    double h, t_end, rho;
    int scaling;
    FILE *trace; /* per-step output, or NULL */
    void (*write)(FILE *f, double t, const double *q, const double *v, const double *qdd,
                  const double *lam);
} run_opts;

typedef struct run_out {
    ga_status status;
    double q[AN31_N], v[AN31_N], qdd[AN31_N], lam[AN31_M];
    double max_cond, cpu;
    double lam1_tv, lam1_hf; /* total variation and high-frequency energy of lambda_1 */
    long long steps, iters, residuals, factorizations;
} run_out;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static run_out run(const scene *sc, run_opts o)
{
    run_out r;
    ga_solver *s = NULL;
    memset(&r, 0, sizeof r);
    r.status = ga_create(sc->n, sc->m, &s);
    if (!r.status) /* the paper's figures show the method's own multipliers and accelerations */
        r.status = ga_set_output(s, GA_OUTPUT_STEP);
    if (!r.status)
        r.status = ga_set_callbacks(s, sc->mass, sc->force, sc->constraint, sc->jacobian,
                                    sc->user);
    if (!r.status)
        r.status = ga_set_tangents(s, sc->stiffness, NULL);
    if (!r.status)
        r.status = ga_set_constraint_accel(s, sc->accel);
    if (!r.status)
        r.status = ga_set_rho_inf(s, o.rho);
    if (!r.status)
        r.status = ga_set_scaling(s, o.scaling);
    const double t0 = now();
    if (!r.status)
        r.status = ga_init(s, 0.0, sc->q0, sc->v0);
    const long n = lround(o.t_end / o.h);
    double l_prev[2] = {0, 0};
    int have = 0;
    for (long i = 0; i <= n && !r.status; ++i) {
        if (i > 0)
            r.status = ga_step(s, o.h);
        if (r.status)
            break;
        if (o.trace || i > 0) {
            double rc;
            ga_get_info(s, GA_INFO_RCOND, &rc);
            if (i > 0)
                r.max_cond = fmax(r.max_cond, 1.0 / rc);
            ga_get_lambda(s, r.lam);
            /* lambda_1 oscillation: total variation and energy of second differences */
            if (have >= 1)
                r.lam1_tv += fabs(r.lam[0] - l_prev[0]);
            if (have >= 2) {
                const double d2 = r.lam[0] - 2 * l_prev[0] + l_prev[1];
                r.lam1_hf += d2 * d2;
            }
            l_prev[1] = l_prev[0];
            l_prev[0] = r.lam[0];
            ++have;
        }
        if (o.trace) {
            double t;
            ga_get_t(s, &t);
            ga_get_q(s, r.q);
            ga_get_v(s, r.v);
            ga_get_qdd(s, r.qdd);
            o.write(o.trace, t, r.q, r.v, r.qdd, r.lam);
        }
    }
    r.cpu = now() - t0;
    if (!r.status) {
        ga_get_q(s, r.q);
        ga_get_v(s, r.v);
        ga_get_qdd(s, r.qdd);
        ga_get_lambda(s, r.lam);
    }
    ga_get_counter(s, GA_COUNT_STEPS, &r.steps);
    ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &r.iters);
    ga_get_counter(s, GA_COUNT_RESIDUALS, &r.residuals);
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &r.factorizations);
    ga_free(s);
    return r;
}

static slider_crank SC;

static scene slider_crank_scene(void)
{
    scene s = {"slider_crank", SC_N, SC_M, sc_mass, sc_force, sc_constraint, sc_jacobian,
               sc_stiffness, sc_constraint_accel, &SC, {0}, {0}, 1.0};
    SC = slider_crank_paper();
    sc_initial(&SC, M_PI / 2, s.q0, s.v0);
    return s;
}

static scene andrews7_scene(void)
{
    scene s = {"andrews7", AN7_N, AN7_M, an7_mass, an7_force, an7_constraint, an7_jacobian, NULL,
               an7_constraint_accel, NULL, {0}, {0}, andrews_t_end};
    memcpy(s.q0, andrews_q0, sizeof andrews_q0);
    return s;
}

static scene andrews31_scene(void)
{
    scene s = {"andrews31", AN31_N, AN31_M, an31_mass, an31_force, an31_constraint,
               an31_jacobian, an31_stiffness, an31_constraint_accel, NULL, {0}, {0},
               andrews_t_end};
    double v7[7] = {0};
    an31_from_angles(andrews_q0, v7, s.q0, s.v0);
    return s;
}

static FILE *open_csv(const char *dir, const char *name, const char *header)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        exit(1);
    }
    fprintf(f, "%s\n", header);
    return f;
}

/* ---- trajectories ------------------------------------------------------------------------ */
static void write_sc(FILE *f, double t, const double *q, const double *v, const double *qdd,
                     const double *lam)
{
    (void)v, (void)qdd;
    fprintf(f, "%.9g,%.12g,%.12g,%.12g\n", t, q[SC_TH1], q[SC_X4], lam[0]);
}

/* Andrews in 31 coordinates: point F, its acceleration, beta, and the multipliers of the crank
 * (rows 0-3: the internal forces in body 1) and of E on the triangle (rows 24, 25). */
static void write_an31(FILE *f, double t, const double *q, const double *v, const double *qdd,
                       const double *lam)
{
    (void)v;
    const int F = an31_point('F');
    fprintf(f, "%.9g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g\n", t,
            q[an31_theta(1)], q[F], q[F + 1], qdd[F], qdd[F + 1], lam[2], lam[3], lam[24],
            lam[25]);
}

static void trajectories(const char *dir)
{
    const scene sc = slider_crank_scene(), a31 = andrews31_scene();
    FILE *f = open_csv(dir, "slider_crank_trajectory.csv", "t,theta1,x4,lambda1");
    run(&sc, (run_opts){5e-3, 1.0, 0.7, 1, f, write_sc});
    fclose(f);
    const char *hdr = "t,beta,xF,yF,axF,ayF,lambda_F_x,lambda_F_y,lambda_E_x,lambda_E_y";
    f = open_csv(dir, "andrews_trajectory_rho0.7.csv", hdr);
    run(&a31, (run_opts){3e-4, andrews_t_end, 0.7, 1, f, write_an31});
    fclose(f);
    f = open_csv(dir, "andrews_trajectory_rho1.csv", hdr);
    run(&a31, (run_opts){3e-4, andrews_t_end, 1.0, 1, f, write_an31});
    fclose(f);
    /* reference for the same quantities: RK4 on the index-1 form, sampled at the same times */
    f = open_csv(dir, "andrews_trajectory_reference.csv", hdr);
    rk4_model md = {AN31_N, AN31_M, an31_mass, an31_force, an31_jacobian, an31_constraint_accel,
                    NULL};
    double q[AN31_N], v[AN31_N], qdd[AN31_N], lam[AN31_M];
    memcpy(q, a31.q0, sizeof q);
    memcpy(v, a31.v0, sizeof v);
    index1_rk4(&md, 0.0, 0.0, 1, q, v, qdd, lam);
    write_an31(f, 0.0, q, v, qdd, lam);
    for (int i = 1; i <= 100; ++i) {
        index1_rk4(&md, (i - 1) * 3e-4, i * 3e-4, 60, q, v, qdd, lam);
        write_an31(f, i * 3e-4, q, v, qdd, lam);
    }
    fclose(f);
}

/* ---- convergence ------------------------------------------------------------------------- */
static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

static void convergence(const char *dir)
{
    FILE *f = open_csv(dir, "convergence.csv", "scene,h,quantity,rel_error");
    /* slider-crank against RK4 (h = 5e-6) */
    const scene sc = slider_crank_scene();
    double q[SC_N], v[SC_N], qdd[SC_N], lam[SC_M];
    memcpy(q, sc.q0, sizeof q);
    memcpy(v, sc.v0, sizeof v);
    rk4_model md = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &SC};
    index1_rk4(&md, 0.0, 1.0, 200000, q, v, qdd, lam);
    for (int k = 0; k < 7; ++k) {
        const double h = 5e-3 / (1 << k);
        const run_out r = run(&sc, (run_opts){h, 1.0, 0.7, 1, NULL, NULL});
        fprintf(f, "slider_crank,%.6g,theta1,%.6e\n", h, rel(r.q[SC_TH1], q[SC_TH1]));
        fprintf(f, "slider_crank,%.6g,lambda1,%.6e\n", h, rel(r.lam[0], lam[0]));
    }
    const scene a7 = andrews7_scene(), a31 = andrews31_scene();
    for (int k = 0; k < 8; ++k) {
        const double h = 3e-4 / (1 << k);
        const run_out r = run(&a7, (run_opts){h, andrews_t_end, 0.7, 1, NULL, NULL});
        fprintf(f, "andrews7,%.6g,beta,%.6e\n", h, rel(r.q[0], andrews_q_ref[0]));
        fprintf(f, "andrews7,%.6g,lambda1,%.6e\n", h, rel(r.lam[0], andrews_lambda_ref[0]));
        const run_out s = run(&a31, (run_opts){h, andrews_t_end, 0.7, 1, NULL, NULL});
        fprintf(f, "andrews31,%.6g,beta,%.6e\n", h,
                rel(s.q[an31_theta(1)], andrews_q_ref[0]));
        fprintf(f, "andrews31,%.6g,lambda1,%.6e\n", h, rel(s.lam[24], andrews_lambda_ref[0]));
    }
    fclose(f);
}

/* ---- damping ----------------------------------------------------------------------------- */
static void damping(const char *dir)
{
    FILE *f = open_csv(dir, "damping.csv",
                       "model,rho_inf,h,lambda1_total_variation,lambda1_second_difference_energy,"
                       "lambda1_error_at_end");
    const scene a7 = andrews7_scene();
    const double rhos[] = {0.7, 0.8, 0.9, 0.95, 1.0};
    for (int k = 0; k < 3; ++k) {
        const double h = 3e-4 / (1 << (2 * k));
        for (int j = 0; j < 5; ++j) {
            const run_out r = run(&a7, (run_opts){h, andrews_t_end, rhos[j], 1, NULL, NULL});
            fprintf(f, "andrews7,%g,%.6g,%.6e,%.6e,%.6e\n", rhos[j], h, r.lam1_tv, r.lam1_hf,
                    rel(r.lam[0], andrews_lambda_ref[0]));
        }
        /* the exact lambda_1 sampled on the same grid, by RK4 */
        rk4_model md = {AN7_N, AN7_M, an7_mass, an7_force, an7_jacobian, an7_constraint_accel,
                        NULL};
        double q[7], v[7] = {0}, qdd[7], lam[6], prev[2] = {0, 0}, tv = 0, hf = 0;
        memcpy(q, andrews_q0, sizeof q);
        const long n = lround(andrews_t_end / h);
        for (long i = 0; i <= n; ++i) {
            if (i == 0)
                index1_rk4(&md, 0.0, 0.0, 1, q, v, qdd, lam);
            else
                index1_rk4(&md, (i - 1) * h, i * h, lround(h / 2e-6) + 1, q, v, qdd, lam);
            if (i >= 1)
                tv += fabs(lam[0] - prev[0]);
            if (i >= 2)
                hf += pow(lam[0] - 2 * prev[0] + prev[1], 2);
            prev[1] = prev[0];
            prev[0] = lam[0];
        }
        fprintf(f, "reference,exact,%.6g,%.6e,%.6e,0\n", h, tv, hf);
    }
    fclose(f);
}

/* ---- scaling: where methods fail ----------------------------------------------------------- */
static void scaling(const char *dir)
{
    FILE *f = open_csv(dir, "scaling.csv",
                       "scene,scaled,h,status,max_condition,newton_iters_per_step,"
                       "lambda1_rel_error,q_rel_error");
    const scene scenes[2] = {andrews7_scene(), slider_crank_scene()};
    const int steps = 50; /* from the consistent start; the reference is RK4 to t = 50 h */
    for (int si = 0; si < 2; ++si) {
        const scene *sc = &scenes[si];
        rk4_model md = {sc->n, sc->m, sc->mass, sc->force, sc->jacobian, sc->accel, sc->user};
        for (int e = 0; e <= 16; ++e) {
            const double h = pow(10.0, -3.0 - 0.25 * e);
            const double t_end = steps * h;
            double q[AN31_N], v[AN31_N], qdd[AN31_N], lam[AN31_M];
            memcpy(q, sc->q0, sizeof q);
            memcpy(v, sc->v0, sizeof v);
            index1_rk4(&md, 0.0, t_end, 2000, q, v, qdd, lam);
            for (int scaled = 1; scaled >= 0; --scaled) {
                const run_out r = run(sc, (run_opts){h, t_end, 0.7, scaled, NULL, NULL});
                double qe = 0.0, qn = 0.0;
                for (int i = 0; i < sc->n; ++i) {
                    qe = fmax(qe, fabs(r.q[i] - q[i]));
                    qn = fmax(qn, fabs(q[i]));
                }
                fprintf(f, "%s,%d,%.6g,%s,%.6e,%.4f,%.6e,%.6e\n", sc->name, scaled, h,
                        r.status ? ga_strerror(r.status) : "ok", r.max_cond,
                        r.steps ? (double)r.iters / (double)r.steps : 0.0,
                        r.status ? NAN : rel(r.lam[0], lam[0]), r.status ? NAN : qe / qn);
            }
        }
    }
    fclose(f);
}

/* ---- work-precision ---------------------------------------------------------------------- */
static void work(const char *dir)
{
    FILE *f = open_csv(dir, "work_precision.csv",
                       "scene,h,rel_error,cpu_seconds,residuals,factorizations,steps");
    const scene scenes[3] = {slider_crank_scene(), andrews7_scene(), andrews31_scene()};
    /* references */
    double q_sc[SC_N], v_sc[SC_N];
    memcpy(q_sc, scenes[0].q0, sizeof q_sc);
    memcpy(v_sc, scenes[0].v0, sizeof v_sc);
    rk4_model md = {SC_N, SC_M, sc_mass, sc_force, sc_jacobian, sc_constraint_accel, &SC};
    index1_rk4(&md, 0.0, 1.0, 200000, q_sc, v_sc, NULL, NULL);
    for (int si = 0; si < 3; ++si) {
        const scene *sc = &scenes[si];
        for (int k = 0; k < 8; ++k) {
            const double h = (si == 0 ? 5e-3 : 3e-4) / (1 << k);
            run_out best = {0};
            for (int rep = 0; rep < 3; ++rep) { /* CPU time: best of three */
                const run_out r = run(sc, (run_opts){h, sc->t_end, 0.7, 1, NULL, NULL});
                if (rep == 0 || r.cpu < best.cpu)
                    best = r;
            }
            double err;
            if (si == 0) {
                err = rel(best.q[SC_TH1], q_sc[SC_TH1]);
            } else {
                double ang[7], e = 0, r2 = 0;
                if (si == 1)
                    memcpy(ang, best.q, sizeof ang);
                else
                    an31_to_angles(best.q, ang);
                for (int i = 0; i < 7; ++i) {
                    e += pow(ang[i] - andrews_q_ref[i], 2);
                    r2 += pow(andrews_q_ref[i], 2);
                }
                err = sqrt(e / r2);
            }
            fprintf(f, "%s,%.6g,%.6e,%.6e,%lld,%lld,%lld\n", sc->name, h, err, best.cpu,
                    best.residuals, best.factorizations, best.steps);
        }
    }
    fclose(f);
}

/* ---- accuracy on demand: adaptive steps on Andrews (7 angles) ------------------------------ */

static void adaptive(const char *dir)
{
    FILE *f = open_csv(dir, "adaptive.csv",
                       "mode,formulation,setting,angle_error,residuals,steps,rejected,failed");
    FILE *hist = open_csv(dir, "adaptive_steps.csv", "t,h,formulation");
    const scene a7 = andrews7_scene();
    for (int form = 0; form < 2; ++form) {
        for (int k = 0; k <= 10; ++k) {
            const double rtol = pow(10.0, -2.0 - 0.5 * k);
            ga_solver *s = NULL;
            ga_create(7, 6, &s);
            ga_set_callbacks(s, a7.mass, a7.force, a7.constraint, a7.jacobian, NULL);
            ga_set_constraint_accel(s, a7.accel);
            ga_set_constraint_dt(s, an7_constraint_dt); /* Phi_t = 0, no differences in t */
            ga_set_rho_inf(s, 0.7);
            ga_set_formulation(s, form);
            ga_set_tolerances(s, rtol, rtol);
            ga_init(s, 0.0, a7.q0, a7.v0);
            ga_status st = GA_OK;
            double t = 0.0;
            while (!st && t < andrews_t_end) {
                st = ga_step_adaptive(s, andrews_t_end);
                ga_get_t(s, &t);
                if (!st && k == 6) {
                    double h;
                    ga_get_h_last(s, &h);
                    fprintf(hist, "%.9g,%.6g,%s\n", t, h, form ? "index2" : "index3");
                }
            }
            double q[7];
            long long res, steps, rej, fail;
            ga_get_q(s, q);
            ga_get_counter(s, GA_COUNT_RESIDUALS, &res);
            ga_get_counter(s, GA_COUNT_STEPS, &steps);
            ga_get_counter(s, GA_COUNT_REJECTED_STEPS, &rej);
            ga_get_counter(s, GA_COUNT_FAILED_STEPS, &fail);
            fprintf(f, "adaptive,%s,%.3g,%.6e,%lld,%lld,%lld,%lld\n", form ? "index2" : "index3",
                    rtol, st ? NAN : andrews_angle_error(q), res, steps, rej, fail);
            ga_free(s);
        }
    }
    for (int k = 0; k < 9; ++k) {
        const double h = 3e-4 / (1 << k);
        const run_out r = run(&a7, (run_opts){h, andrews_t_end, 0.7, 1, NULL, NULL});
        fprintf(f, "fixed,index3,%.6g,%.6e,%lld,%lld,0,0\n", h, andrews_angle_error(r.q), r.residuals,
                r.steps);
    }
    fclose(f);
    fclose(hist);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    const char *only = argc > 2 ? argv[2] : NULL;
    struct {
        const char *name;
        void (*fn)(const char *);
    } studies[] = {{"trajectories", trajectories}, {"convergence", convergence},
                   {"damping", damping},           {"scaling", scaling},
                   {"work", work},                 {"adaptive", adaptive}};
    for (size_t i = 0; i < sizeof studies / sizeof studies[0]; ++i) {
        if (only && strcmp(only, studies[i].name))
            continue;
        const double t0 = now();
        studies[i].fn(dir);
        printf("  %-13s %.1f s\n", studies[i].name, now() - t0);
    }
    return 0;
}
