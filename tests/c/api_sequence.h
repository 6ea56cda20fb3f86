/* Random sequences of C API calls, shared by tests/c/test_api_sequences.c (choices from a
 * seeded generator) and the libFuzzer harness tests/fuzz/fuzz_api.c (choices from the fuzzer's
 * bytes); see test_api_sequences.c for what they make and what must hold. The includer
 * defines SEQ_FAIL(fmt, ...) (report and stop) and SEQ_REQUIRE(cond), and SEQ_TRACE to have
 * every call and the restart twins printed to stderr (to read what a fuzzer finding does). */
#ifndef GALPHA_TESTS_API_SEQUENCE_H
#define GALPHA_TESTS_API_SEQUENCE_H

#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

/* The model: a planar chain of L = 1 to 3 links in Cartesian coordinates (n = 2 L, the point
 * masses at the links' ends), m = L constraints |p_k - p_(k-1)|^2 = 1 (p_(-1) = 0), or L + 1
 * with the first stated twice (redundant), or none (free particles). With a rotor
 * (run_sequence's `rotor`), a free rigid body follows the chain's coordinates on a group
 * block of ga_create_space -- a rotation stored as a quaternion or a matrix, or an SE(3) pose
 * -- with its gyroscopic force and nothing joining it to the chain: nv = n + 3 or n + 6 and
 * nq = n + 4, 9 or 7 (no rotor: nv = nq = n). */
enum { MAX_LINKS = 3, NMAX = 2 * MAX_LINKS, MMAX = MAX_LINKS + 1, MAX_OPS = 64,
       VMAX = NMAX + 6, QMAX = NMAX + 9,
       STATE_MAX = 1 + QMAX + 3 * VMAX + MMAX + 2 + 2 * (3 * VMAX + MMAX), CKPT_MAX = 2048 };

typedef enum fault_kind { NONE, RETURN_RETRY, RETURN_FATAL, WRITE_NAN, WRITE_INF, WRITE_HUGE,
                          REENTER, FAULT_KINDS } fault_kind;
enum { MASS, FORCE, CONSTRAINT, JACOBIAN, STIFFNESS, ACCEL, DT, RATE, EVENT, COUPLING, FORCE_P,
       MASS_P, CONSTRAINT_P, COST, CALLBACKS };

typedef struct model {
    uint64_t rng;
    const uint8_t *data;   /* fuzzing: the choices come from these bytes (rng unused) */
    size_t size, pos;
    int exhausted;         /* the bytes ran out: the sequence ends after this call */
    int links, n, m;       /* m = links, links + 1 (redundant) or 0 */
    int rotor;             /* 0, or the rotor's kind (GA_SPACE_SO3_QUATERNION, _MATRIX, _SE3) */
    int nv, nq;            /* v's and q's lengths: n plus the rotor's */
    int r;                 /* first-order states: 0, or 1 (y' = v_0 - y, a force y on q_0) */
    fault_kind fault;      /* armed failure */
    int fault_callback;    /* which callback fails */
    long calls, fault_at;  /* it fails from its fault_at-th call on */
    ga_solver *s;
    int impure;            /* a callback returned success with other values than usual */
    int reentry_allowed;   /* a callback's ga_step on its own solver returned other than STATE */
    int sparse_M, sparse_J, sparse_K; /* patterns declared: the callbacks write values only */
    /* the patterns the callbacks write when declared */
    int m_diag[VMAX], m_colptr[VMAX + 1];
    int j_rows[4 * MMAX], j_cols[4 * MMAX], j_nnz;
    int k_rows[3 * NMAX], k_cols[3 * NMAX], k_nnz;
    /* events (ga_set_events): g_k = q_k - level_k, or lambda_0 - level_2 for the third with
     * multipliers */
    int ev_count, ev_dir[3], ev_term[3], ev_lambda;
    double ev_level[3];
    /* sensitivities (ga_set_sensitivity) in p = (gravity, a parameter nothing reads); forward
     * ones are part of the snapshot; an adjoint record refuses checkpoints */
    double p[2];
    int sens, sens_forward, sens_adjoint;
    /* the step hook (ga_set_step_hook): it reads the solver, tries to change it, and stops
     * the call at some t (a function of t alone, so that a restored run stops alike) */
    int hook_stops;
    long hook_calls, hook_wrong; /* calls; reads that disagreed or changes let through */
    /* the step limits last accepted (ga_advance bounds its work with them, then puts them
     * back) and whether the events are the functions of y (ga_set_events_y) */
    double h_min, h_max;
    int ev_y;
} model;

static uint64_t next(model *md)
{
    if (md->data) {
        uint64_t x = 0;
        for (int k = 0; k < 2; ++k, ++md->pos)
            x = x << 8 | (md->pos < md->size ? md->data[md->pos] : 0);
        md->exhausted |= md->pos >= md->size;
        /* two bytes per choice, spread over 64 bits so that uniform() is not always ~0 */
        return x * 0x9E3779B97F4A7C15ull;
    }
    md->rng ^= md->rng << 13;
    md->rng ^= md->rng >> 7;
    md->rng ^= md->rng << 17;
    return md->rng;
}
static int pick(model *md, int k) { return (int)((next(md) >> 32) % (uint64_t)k); }
static double uniform(model *md) { return (double)(next(md) >> 11) * 0x1.0p-53; }

static int misbehave(model *md, int callback, double *out, int len)
{
    if (md->fault == NONE || md->fault_callback != callback || ++md->calls < md->fault_at)
        return 0;
    switch (md->fault) {
    case RETURN_RETRY: return 1;
    case RETURN_FATAL: return -1;
    case WRITE_NAN: out[pick(md, len)] = NAN; return 0;
    case WRITE_INF: out[pick(md, len)] = -INFINITY; return 0;
    case WRITE_HUGE: out[pick(md, len)] = 1e300; md->impure = 1; return 0;
    case REENTER:
        if (ga_step(md->s, 1e-3) != GA_ERR_STATE)
            md->reentry_allowed = 1;
        return 0;
    default: return 0;
    }
}

/* The chain's sizes and patterns: Phi_q row k has the entries of p_(k-1) (k > 0) and p_k;
 * K_t = sum_k lambda_k Phi_k'' has the diagonal and the couplings of neighbouring points. */
static void model_shape(model *md, int links, int m)
{
    md->links = links;
    md->n = 2 * links;
    md->m = m;
    md->nv = md->n + (md->rotor == GA_SPACE_SE3 ? 6 : md->rotor ? 3 : 0);
    md->nq = md->n + (md->rotor == GA_SPACE_SE3              ? 7
                      : md->rotor == GA_SPACE_SO3_QUATERNION ? 4
                      : md->rotor == GA_SPACE_SO3_MATRIX     ? 9
                                                             : 0);
    for (int i = 0; i < md->nv; ++i)
        md->m_diag[i] = md->m_colptr[i] = i;
    md->m_colptr[md->nv] = md->nv;
    int nnz = 0;
    for (int k = 0; k < m; ++k) {
        const int link = k < links ? k : 0;  /* the redundant row repeats row 0 */
        for (int c = link > 0 ? 2 * link - 2 : 2 * link; c < 2 * link + 2; ++c)
            md->j_rows[nnz] = k, md->j_cols[nnz++] = c;
    }
    md->j_nnz = nnz;
    nnz = 0;
    for (int i = 0; i < md->n; ++i)
        md->k_rows[nnz] = i, md->k_cols[nnz++] = i;
    for (int k = 1; k < links; ++k)
        for (int d = 0; d < 2; ++d) {
            md->k_rows[nnz] = 2 * k - 2 + d, md->k_cols[nnz++] = 2 * k + d;
            md->k_rows[nnz] = 2 * k + d, md->k_cols[nnz++] = 2 * k - 2 + d;
        }
    md->k_nnz = nnz;
}

/* p_k - p_(k-1) of the link of constraint k (the redundant one: link 0), in x */
static void link_vector(const model *md, int k, const double *x, double d[2])
{
    const int link = k < md->links ? k : 0;
    d[0] = x[2 * link] - (link > 0 ? x[2 * link - 2] : 0.0);
    d[1] = x[2 * link + 1] - (link > 0 ? x[2 * link - 1] : 0.0);
}

/* The rotor's mass matrix diagonal: a pose's mass 2, then the inertia (1, 2, 3) */
static double rotor_inertia(const model *md, int i)
{
    const int k = i - md->n - (md->rotor == GA_SPACE_SE3 ? 3 : 0);
    return k < 0 ? 2.0 : 1.0 + k;
}
static int mass(double t, const double *q, double *M, void *user)
{
    model *md = user;
    const int n = md->n, nv = md->nv;
    (void)t, (void)q;
    if (md->sparse_M) {  /* the diagonal */
        for (int i = 0; i < nv; ++i)
            M[i] = i < n ? 1.0 : rotor_inertia(md, i);
        return misbehave(md, MASS, M, nv);
    }
    memset(M, 0, sizeof(double) * (size_t)(nv * nv));
    for (int i = 0; i < nv; ++i)
        M[i + i * nv] = i < n ? 1.0 : rotor_inertia(md, i);
    return misbehave(md, MASS, M, nv * nv);
}
/* The rotor's force in the body frame: -w x J w, and a pose's -m w x u */
static void rotor_force(const model *md, const double *v, double *f)
{
    if (!md->rotor)
        return;
    const int w0 = md->nv - 3;
    const double *w = v + w0;
    const double Jw[3] = {w[0], 2.0 * w[1], 3.0 * w[2]};
    f[w0] = -(w[1] * Jw[2] - w[2] * Jw[1]);
    f[w0 + 1] = -(w[2] * Jw[0] - w[0] * Jw[2]);
    f[w0 + 2] = -(w[0] * Jw[1] - w[1] * Jw[0]);
    if (md->rotor == GA_SPACE_SE3) {
        const double *u = v + md->n;
        f[md->n] = -2.0 * (w[1] * u[2] - w[2] * u[1]);
        f[md->n + 1] = -2.0 * (w[2] * u[0] - w[0] * u[2]);
        f[md->n + 2] = -2.0 * (w[0] * u[1] - w[1] * u[0]);
    }
}
static int force(double t, const double *q, const double *v, double *f, void *user)
{
    model *md = user;
    (void)t, (void)q;
    for (int i = 0; i < md->n; ++i)
        f[i] = i % 2 ? -md->p[0] : 0.0;
    rotor_force(md, v, f);
    return misbehave(md, FORCE, f, md->nv);
}
static int force_y(double t, const double *q, const double *v, const double *y, double *f,
                   void *user)
{
    const int rc = force(t, q, v, f, user);
    f[0] += y[0];
    return rc;
}
static int rate(double t, const double *q, const double *v, const double *y, double *ydot,
                void *user)
{
    model *md = user;
    (void)t, (void)q;
    ydot[0] = v[0] - y[0];
    return misbehave(md, RATE, ydot, 1);
}
static int constraint(double t, const double *q, double *phi, void *user)
{
    model *md = user;
    (void)t;
    for (int k = 0; k < md->m; ++k) {
        double d[2];
        link_vector(md, k, q, d);
        phi[k] = 0.5 * (d[0] * d[0] + d[1] * d[1] - 1.0);
    }
    return misbehave(md, CONSTRAINT, phi, md->m);
}
static int jacobian(double t, const double *q, double *J, void *user)
{
    model *md = user;
    const int m = md->m;
    (void)t;
    if (!md->sparse_J)
        memset(J, 0, sizeof(double) * (size_t)(m * md->nv));
    int e = 0;
    for (int k = 0; k < m; ++k) {
        double d[2];
        link_vector(md, k, q, d);
        const int link = k < md->links ? k : 0;
        const double values[4] = {-d[0], -d[1], d[0], d[1]};
        for (int c = link > 0 ? 0 : 2; c < 4; ++c) {  /* in the order of j_rows, j_cols */
            const int col = 2 * link - 2 + c;
            if (md->sparse_J)
                J[e++] = values[c];
            else
                J[k + col * m] = values[c];
        }
    }
    return misbehave(md, JACOBIAN, J, md->sparse_J ? md->j_nnz : m * md->nv);
}
/* K_t = d(Phi_q^T lambda)/dq (M constant, f constant) */
static int stiffness(double t, const double *q, const double *v, const double *qdd,
                     const double *lambda, double *K, void *user)
{
    model *md = user;
    const int n = md->n, links = md->links;
    (void)t, (void)q, (void)v, (void)qdd;
    /* lambda_k on the link of constraint k: + on both its points' diagonals, - between them */
    double on_link[MAX_LINKS] = {0.0};
    for (int k = 0; k < md->m; ++k)
        on_link[k < links ? k : 0] += lambda[k];
    double diag[NMAX] = {0.0};
    for (int p = 0; p < links; ++p)
        diag[2 * p] = diag[2 * p + 1] = md->m ? on_link[p] + (p + 1 < links ? on_link[p + 1] : 0.0)
                                              : 0.0;
    if (md->sparse_K) {  /* in the order of k_rows, k_cols */
        int e = 0;
        for (int i = 0; i < n; ++i)
            K[e++] = diag[i];
        for (int k = 1; k < links; ++k)
            for (int d = 0; d < 4; ++d)
                K[e++] = md->m ? -on_link[k] : 0.0;
        return misbehave(md, STIFFNESS, K, md->k_nnz);
    }
    const int nv = md->nv;  /* (the rotor's block is zero: its force is the body frame's) */
    memset(K, 0, sizeof(double) * (size_t)(nv * nv));
    for (int i = 0; i < n; ++i)
        K[i + i * nv] = diag[i];
    for (int k = 1; k < links && md->m; ++k)
        for (int d = 0; d < 2; ++d) {
            const int a = 2 * k - 2 + d, b = 2 * k + d;
            K[a + b * nv] = K[b + a * nv] = -on_link[k];
        }
    return misbehave(md, STIFFNESS, K, nv * nv);
}
static int accel(double t, const double *q, const double *v, double *out, void *user)
{
    model *md = user;
    (void)t, (void)q;
    for (int k = 0; k < md->m; ++k) {  /* Phi_qq(v, v) = |v_k - v_(k-1)|^2 */
        double d[2];
        link_vector(md, k, v, d);
        out[k] = d[0] * d[0] + d[1] * d[1];
    }
    return misbehave(md, ACCEL, out, md->m);
}
static int time_derivative(double t, const double *q, double *phi_t, void *user)
{
    model *md = user;
    (void)t, (void)q;
    for (int i = 0; i < md->m; ++i)
        phi_t[i] = 0.0;
    return misbehave(md, DT, phi_t, md->m);
}

/* The adjoint's costs: q_0 at the end (terminal), q_0^2 / 2 along the run (running). */
static int adjoint_cost(double t, const double *q, const double *v, const double *qdd,
                        const double *lambda, double *value, double *d_q, double *d_v,
                        double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    model *md = user;
    (void)t, (void)v, (void)qdd, (void)lambda;
    memset(d_q, 0, sizeof(double) * (size_t)md->nv);
    memset(d_v, 0, sizeof(double) * (size_t)md->nv);
    memset(d_qdd, 0, sizeof(double) * (size_t)md->nv);
    if (md->m)  /* (NULL without constraints) */
        memset(d_lambda, 0, sizeof(double) * (size_t)md->m);
    d_p[0] = d_p[1] = 0.0;
    d_q[0] = 1.0;
    *value = q[0];
    return misbehave(md, COST, d_q, md->nv);
}
static int running_cost(double t, const double *q, const double *v, const double *qdd,
                        const double *lambda, double *value, double *d_q, double *d_v,
                        double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    const int rc = adjoint_cost(t, q, v, qdd, lambda, value, d_q, d_v, d_qdd, d_lambda, d_p,
                                user);
    d_q[0] = q[0];
    *value = 0.5 * q[0] * q[0];
    return rc;
}

/* A pattern declaration: the model's own, or one ga_set_pattern must refuse. */
static ga_status declare_pattern(model *md, ga_solver *s, int *must_fail)
{
    static const int bad_rows[] = {0, 5, -1, 2}, bad_cols[] = {0, 1, 2, 4};
    const int k = pick(md, 9);
    *must_fail = k >= 5;
    switch (k) {
    case 0: {
        const ga_status st = ga_set_pattern(s, GA_MATRIX_MASS, md->nv, md->m_diag, md->m_diag);
        md->sparse_M |= st == GA_OK;
        return st;
    }
    case 1: {
        const ga_status st = ga_set_pattern_csc(s, GA_MATRIX_MASS, md->m_colptr, md->m_diag);
        md->sparse_M |= st == GA_OK;
        return st;
    }
    case 2: {
        const ga_status st =
            ga_set_pattern(s, GA_MATRIX_JACOBIAN, md->j_nnz, md->j_rows, md->j_cols);
        md->sparse_J |= st == GA_OK;
        return st;
    }
    case 3: {
        const ga_status st =
            ga_set_pattern(s, GA_MATRIX_STIFFNESS, md->k_nnz, md->k_rows, md->k_cols);
        md->sparse_K |= st == GA_OK;
        return st;
    }
    case 4: return ga_set_pattern(s, GA_MATRIX_DAMPING, 0, NULL, NULL);
    /* each of these must be refused: an index out of range, NULL arrays with entries, an
     * unknown matrix, a negative count, a decreasing colptr */
    case 5: return ga_set_pattern(s, pick(md, 4), 4, bad_rows, bad_cols);
    case 6: return ga_set_pattern(s, pick(md, 4), 3, NULL, md->m_diag);
    case 7: return ga_set_pattern(s, 4 + pick(md, 3), 2, md->m_diag, md->m_diag);
    default: {
        static const int decreasing[] = {0, 2, 1, 3, 4, 5, 6};
        return pick(md, 2) ? ga_set_pattern(s, GA_MATRIX_MASS, -1, md->m_diag, md->m_diag)
                           : ga_set_pattern_csc(s, GA_MATRIX_MASS, decreasing, md->m_diag);
    }
    }
}

static int events(double t, const double *q, const double *v, const double *lambda, double *g,
                  void *user)
{
    (void)t, (void)v;
    model *md = user;
    for (int k = 0; k < md->ev_count; ++k)
        g[k] = (k == 2 && lambda && md->m > 0 ? lambda[0] : q[k % md->n]) - md->ev_level[k];
    return md->ev_count ? misbehave(md, EVENT, g, md->ev_count) : 0;
}
/* ga_set_events_y's functions: the second sees y_0 */
static int events_y(double t, const double *q, const double *v, const double *y,
                    const double *lambda, double *g, void *user)
{
    const int rc = events(t, q, v, lambda, g, user);
    const model *md = user;
    if (md->ev_count > 1)
        g[1] = y[0] - md->ev_level[1];
    return rc;
}
/* The exact coupling of rate() and force_y(): g_v = e_0^T, g_y = -1, f_y = e_0 */
static int coupling(double t, const double *q, const double *v, const double *y, double *g_q,
                    double *g_v, double *g_y, double *f_y, void *user)
{
    model *md = user;
    (void)t, (void)q, (void)v, (void)y;
    memset(g_q, 0, sizeof(double) * (size_t)md->nv);
    memset(g_v, 0, sizeof(double) * (size_t)md->nv);
    memset(f_y, 0, sizeof(double) * (size_t)md->nv);
    g_v[0] = 1.0;
    g_y[0] = -1.0;
    f_y[0] = 1.0;
    return misbehave(md, COUPLING, g_v, md->nv);
}
/* df/dp: gravity enters every odd force as -p_0; p_1 nothing. M and Phi do not depend on p. */
static int force_p(double t, const double *q, const double *v, int j, double *f_p, void *user)
{
    model *md = user;
    (void)t, (void)q, (void)v;
    for (int i = 0; i < md->nv; ++i)
        f_p[i] = j == 0 && i % 2 && i < md->n ? -1.0 : 0.0;
    return misbehave(md, FORCE_P, f_p, md->nv);
}
static int mass_p(double t, const double *q, int j, const double *a, double *out, void *user)
{
    model *md = user;
    (void)t, (void)q, (void)j, (void)a;
    memset(out, 0, sizeof(double) * (size_t)md->nv);
    return misbehave(md, MASS_P, out, md->nv);
}
static int constraint_p(double t, const double *q, int j, double *phi_p, double *Phi_q_p,
                        double *Phi_t_p, void *user)
{
    model *md = user;
    (void)t, (void)q, (void)j;
    memset(phi_p, 0, sizeof(double) * (size_t)md->m);
    memset(Phi_q_p, 0, sizeof(double) * (size_t)(md->sparse_J ? md->j_nnz : md->m * md->nv));
    if (Phi_t_p)
        memset(Phi_t_p, 0, sizeof(double) * (size_t)md->m);
    return md->m ? misbehave(md, CONSTRAINT_P, phi_p, md->m) : 0;
}

/* The events of `md` set on s (again: the search starts afresh from the current state). */
static int step_hook(const ga_solver *s, double t, const double *q, const double *v,
                     const double *lambda, void *user)
{
    model *md = user;
    double x[QMAX], h = 0.0, qi[QMAX], vi[VMAX], li[MMAX];
    (void)v, (void)lambda;
    ++md->hook_calls;
    if (ga_get_q(s, x) != GA_OK || memcmp(x, q, sizeof(double) * (size_t)md->nq) != 0)
        ++md->hook_wrong;
    if (ga_get_h_last(s, &h) == GA_OK && h > 0.0)  /* may fail with the callbacks: allowed */
        ga_interpolate(s, t - 0.5 * h, qi, vi, md->m ? li : NULL);
    if (ga_set_rho_inf((ga_solver *)s, 0.5) != GA_ERR_STATE ||
        ga_step((ga_solver *)s, 1e-3) != GA_ERR_STATE)
        ++md->hook_wrong;
    return md->hook_stops && sin(1e4 * t) > 0.5;
}

static ga_status set_events(const model *md, ga_solver *s)
{
    if (md->ev_y)
        return ga_set_events_y(s, md->ev_count, md->ev_count ? events_y : NULL, md->ev_dir,
                               md->ev_term, md->ev_lambda);
    return ga_set_events(s, md->ev_count, md->ev_count ? events : NULL, md->ev_dir, md->ev_term,
                         md->ev_lambda);
}

/* The log of the last stepping call: in time order, not after t, entries of known functions;
 * at least one after GA_EVENT. */
static void check_event_log(const model *md, ga_solver *s, ga_status st, int seq)
{
    int count = -1;
    double t = 0.0, last = -INFINITY;
    SEQ_REQUIRE(ga_get_event_count(s, &count) == GA_OK);
    ga_get_t(s, &t);
    if (st == GA_EVENT && count < 1)
        SEQ_FAIL("sequence %d: GA_EVENT with an empty event log", seq);
    for (int i = 0; i < count; ++i) {
        double te;
        int index, direction;
        SEQ_REQUIRE(ga_get_event(s, i, &te, &index, &direction) == GA_OK);
        if (!(te >= last && te <= t) || index < 0 || index >= md->ev_count ||
            (direction != 1 && direction != -1) ||
            (md->ev_dir[index] != 0 && md->ev_dir[index] != direction))
            SEQ_FAIL("sequence %d: event %d of %d: t = %.17g (t %.17g), function %d, "
                     "direction %d", seq, i, count, te, t, index, direction);
        last = te;
    }
    SEQ_REQUIRE(ga_get_event(s, count, &t, NULL, NULL) == GA_ERR_ARG);
}

static double edge_value(model *md)
{
    static const double values[] = {0.0, -1.0, 1.0, 0.5, 1e-3, 1e-12, 1e300, -1e300, 1e-320,
                                    2.0, 0.9, 0.7, 1e-6, 1e-10, 10.0};
    const int k = pick(md, 18);
    return k < 15 ? values[k] : k == 15 ? NAN : k == 16 ? INFINITY : uniform(md);
}
static double step_size(model *md)
{
    static const double values[] = {1e-3, 1e-2, 1e-4, 0.1, 1.0, 1e-8, 1e-15, 0.0, -1e-3, 1e3,
                                    5e-3, NAN, INFINITY};
    return values[pick(md, 13)];
}

/* t, q, v, qdd, a, lambda (and y, y'); 0 before ga_init */
static int snapshot(const model *md, ga_solver *s, double *x)
{
    const int n = md->nv, q = md->nq;  /* (v, qdd, a after q's storage) */
    if (ga_get_t(s, x) != GA_OK)
        return 0;
    SEQ_REQUIRE(ga_get_q(s, x + 1) == GA_OK);
    SEQ_REQUIRE(ga_get_v(s, x + 1 + q) == GA_OK);
    SEQ_REQUIRE(ga_get_qdd(s, x + 1 + q + n) == GA_OK);
    SEQ_REQUIRE(ga_get_a(s, x + 1 + q + 2 * n) == GA_OK);
    SEQ_REQUIRE(ga_get_lambda(s, md->m ? x + 1 + q + 3 * n : NULL) == GA_OK);
    if (md->r)
        SEQ_REQUIRE(ga_get_y(s, x + 1 + q + 3 * n + md->m, x + 2 + q + 3 * n + md->m) == GA_OK);
    int len = 1 + q + 3 * n + md->m + 2 * md->r;
    for (int j = 0; md->sens_forward && j < 2; ++j) {
        double *d = x + len;
        SEQ_REQUIRE(ga_get_sensitivity(s, j, d, d + n, d + 2 * n, md->m ? d + 3 * n : NULL) ==
                    GA_OK);
        len += 3 * n + md->m;
    }
    return len;
}

static void check(ga_solver *s, ga_status st, int changes_solver, const char *call, int seq)
{
    const int stepping = strcmp(call, "ga_step") == 0 || strcmp(call, "ga_step_adaptive") == 0 ||
                         strcmp(call, "ga_advance") == 0;
    if (st > (stepping ? GA_STOPPED : GA_OK) || st < GA_ERR_DERIVATIVE)
        SEQ_FAIL("sequence %d: %s returned %d, not a ga_status", seq, call, st);
    if (st < GA_OK && changes_solver && ga_last_error(s)[0] == '\0')
        SEQ_FAIL("sequence %d: %s failed (%s) without a message", seq, call, ga_strerror(st));
    /* a failed read names itself: its message, not one an earlier failure left */
    if (st < GA_OK && !changes_solver && strncmp(call, "ga_get_", 7) == 0 &&
        !strstr(ga_last_error(s), call))
        SEQ_FAIL("sequence %d: %s failed (%s) with the message '%s'", seq, call,
                 ga_strerror(st), ga_last_error(s));
}

/* A failed step must leave the state as it was. */
static void check_transaction(const model *md, ga_solver *s, ga_status st,
                              const double *before, int len, const char *call, int seq)
{
    double after[STATE_MAX];
    if (st >= GA_OK || len == 0)
        return;
    SEQ_REQUIRE(snapshot(md, s, after) == len);
    if (memcmp(before, after, sizeof(double) * (size_t)len) != 0)
        SEQ_FAIL("sequence %d: %s failed (%s: %s) but changed the state", seq, call,
                 ga_strerror(st), ga_last_error(s));
}

/* Operating points, in a phase of their own after the calls above (so that the bytes of
 * those decode as before): the static problem, linearization and modes at the current q
 * (or the chain's start before ga_init), with edge-value arguments and the armed faults.
 * None of them changes the solver's state, whatever it returns; a failed one writes none of
 * its outputs. */
static long long operating_points_phase(model *md, ga_solver *s, int seq)
{
    long long ok = 0;
    for (int k = 0; k < 3 && !md->exhausted; ++k) {
        double before[STATE_MAX], after[STATE_MAX], t = 0.0, q[QMAX] = {0}, keep[QMAX];
        double lambda[MMAX] = {0}, w2[2 * VMAX], im[2 * VMAX],
               shapes[(2 * VMAX + 1) * (2 * VMAX + 1)],
               shapes_im[2 * VMAX * VMAX], stiff[VMAX * VMAX];
        const int len = snapshot(md, s, before);
        if (ga_get_t(s, &t) != GA_OK || ga_get_q(s, q) != GA_OK) {
            t = 0.0;
            for (int l = 0; l < md->links; ++l) {
                q[2 * l] = sin(0.4) + l;
                q[2 * l + 1] = -cos(0.4);
            }
        }
        if (pick(md, 4) == 0)
            q[pick(md, md->nq)] += edge_value(md);
        memcpy(keep, q, sizeof q);
        for (int i = 0; i < 2 * VMAX; ++i)
            w2[i] = im[i] = -7.0;
        const double sentinel = w2[0];
        double *lam = pick(md, 2) && md->m ? lambda : NULL;
        const int count = pick(md, md->nv + 2) - 1;
        ga_status st = GA_OK;
        const char *call = "";
        int writes_q = 0;
        switch (pick(md, 9)) {
        case 8: {
            double v[VMAX] = {0};
            int dim = -1;
            if (ga_get_v(s, v) != GA_OK || pick(md, 4) == 0)
                v[pick(md, md->nv)] += edge_value(md);
            call = "ga_state_space_motion";
            const double y[1] = {0.3};
            st = ga_state_space_motion(s, t, q, v, y, pick(md, 2 * md->nv + 3) - 1, &dim,
                                       pick(md, 2) ? shapes_im : NULL, pick(md, 2) ? shapes : NULL);
            break;
        }
        case 6: {
            double y[1] = {pick(md, 2) ? 0.3 : edge_value(md)}, ykeep[1];
            ykeep[0] = y[0];
            call = "ga_static_equilibrium_y";
            st = ga_static_equilibrium_y(s, t, q, md->r ? y : NULL, lam, 1e-10, pick(md, 30) - 2);
            if (st != GA_OK && memcmp(y, ykeep, sizeof y) != 0)
                SEQ_FAIL("sequence %d: %s failed but wrote y", seq, call);
            writes_q = 1;
            break;
        }
        case 7: {
            double y[1] = {0.3};
            int dim = -1;
            call = "ga_state_space";
            st = ga_state_space(s, t, q, y, lam, pick(md, 2 * md->nv + 3) - 1, &dim,
                                pick(md, 2) ? shapes_im : NULL, pick(md, 2) ? shapes : NULL);
            break;
        }
        case 0:
            call = "ga_static_equilibrium";
            st = ga_static_equilibrium(s, t, q, lam, pick(md, 2) ? 1e-10 : edge_value(md),
                                       pick(md, 30) - 2);
            writes_q = 1;
            break;
        case 1:
            call = "ga_modes";
            st = ga_modes(s, t, q, lam, count, w2, pick(md, 2) ? shapes : NULL);
            break;
        case 2:
            call = "ga_modes_near";
            st = ga_modes_near(s, t, q, lam, pick(md, 2) ? 0.0 : edge_value(md), count, w2,
                               pick(md, 2) ? shapes : NULL);
            break;
        case 3:
            call = "ga_modes_damped";
            st = ga_modes_damped(s, t, q, lam, count, w2, im, pick(md, 2) ? shapes : NULL,
                                 pick(md, 2) ? shapes_im : NULL);
            break;
        case 4: {
            int dof = -1;
            call = "ga_linearize";
            st = ga_linearize(s, t, q, lam, count, &dof, shapes_im, shapes, NULL,
                              pick(md, 2) ? stiff : NULL);
            break;
        }
        default: {
            double load = md->p[0];
            call = "ga_static_path";
            st = ga_static_path(s, t, &load, q, lam, pick(md, 2) ? 0.05 : edge_value(md),
                                pick(md, 5) - 1, 1e-10, NULL, NULL);
            writes_q = -1; /* the path's last point, consistent, whatever the status */
            break;
        }
        }
        check(s, st, 1, call, seq);
        ok += st == GA_OK;
        if (len && (snapshot(md, s, after) != len ||
                    memcmp(before, after, sizeof(double) * (size_t)len) != 0))
            SEQ_FAIL("sequence %d: %s (%s) changed the solver's state", seq, call,
                     ga_strerror(st));
        if (st != GA_OK && writes_q >= 0 &&
            (memcmp(q, keep, sizeof q) != 0 || (writes_q == 0 && w2[0] != sentinel)))
            SEQ_FAIL("sequence %d: %s failed (%s: %s) but wrote its outputs", seq, call,
                     ga_strerror(st), ga_last_error(s));
#ifdef SEQ_TRACE
        fprintf(stderr, "%s: %d %s\n", call, st, st ? ga_last_error(s) : "");
#endif
    }
    return ok;
}

typedef struct seq_stats {
    long long calls, steps_ok, sparse_ok, twin_steps_ok, events, sensitivity_steps_ok,
        adjoint_ok, hook_calls, hook_stops, advance_ok, operating_points_ok;
} seq_stats;

/* The restart twin: a few steps from a checkpoint, then the checkpoint restored in the same
 * solver and the same steps again must give the same statuses and the same checkpoint, bit
 * for bit (callbacks do not fail meanwhile: the failures armed count their calls). */
static int restart_twin(model *md, ga_solver *s, const double *ckpt, size_t len, int seq)
{
    enum { TWIN_STEPS = 4 };
    const fault_kind fault = md->fault;
    double h[TWIN_STEPS], end[2][CKPT_MAX];
    int adaptive[TWIN_STEPS];
    ga_status st[2][TWIN_STEPS];
    const int k = 1 + pick(md, TWIN_STEPS);
    for (int i = 0; i < k; ++i) {
        h[i] = step_size(md);
        adaptive[i] = pick(md, 2);
    }
    md->fault = NONE;
#ifdef SEQ_TRACE
    fprintf(stderr, "  twin on %s, sparse M %d J %d K %d\n", ga_linear_solver_name(s),
            md->sparse_M, md->sparse_J, md->sparse_K);
#endif
    for (int run = 0; run < 2; ++run) {
        /* the event search is not part of a checkpoint: set_state starts it afresh, and so
         * does setting the events again for the first run */
        if (run == 0)
            SEQ_REQUIRE(set_events(md, s) == GA_OK);
        if (run == 1 && ga_set_state(s, ckpt, len) != GA_OK)
            SEQ_FAIL("sequence %d: a solver refused its own checkpoint: %s", seq,
                     ga_last_error(s));
        for (int i = 0; i < k; ++i) {
            double t = 0.0;
            ga_get_t(s, &t);
            st[run][i] = adaptive[i] ? ga_step_adaptive(s, t + h[i]) : ga_step(s, h[i]);
#ifdef SEQ_TRACE
            {
                long long it = 0, fa = 0, re = 0;
                ga_get_counter(s, GA_COUNT_NEWTON_ITERS, &it);
                ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &fa);
                ga_get_counter(s, GA_COUNT_RESIDUALS, &re);
                fprintf(stderr, "  twin run %d step %d: %s (counters: %lld iterations, %lld "
                        "factorizations, %lld residuals)\n",
                        run, i, ga_last_error(s), it, fa, re);
            }
#endif
        }
        SEQ_REQUIRE(ga_get_state(s, end[run], len) == GA_OK);
    }
    md->fault = fault;
#ifdef SEQ_TRACE
    for (int i = 0; i < k; ++i)
        fprintf(stderr, "  twin step %d: h = %g adaptive %d: %d / %d\n", i, h[i], adaptive[i],
                st[0][i], st[1][i]);
    for (size_t i = 0; i < len; ++i)
        if (memcmp(&end[0][i], &end[1][i], sizeof(double)) != 0)
            fprintf(stderr, "  entry %zu: %.17g / %.17g\n", i, end[0][i], end[1][i]);
#endif
    if (memcmp(st[0], st[1], sizeof st[0][0] * (size_t)k) != 0 ||
        memcmp(end[0], end[1], sizeof(double) * len) != 0)
        SEQ_FAIL("sequence %d: %d steps from a restored checkpoint differ from the same steps "
                 "after it was taken", seq, k);
    int accepted = 0;
    for (int i = 0; i < k; ++i)
        accepted += st[0][i] >= GA_OK;
    return accepted;
}


/* The checks after a stepping call, and what it counts. */
static void after_step(const model *md, ga_solver *s, ga_status st, const double *before,
                       int len, const char *call, int seq, seq_stats *stats)
{
    check_transaction(md, s, st, before, len, call, seq);
    check_event_log(md, s, st, seq);
    stats->steps_ok += st >= GA_OK;
    stats->events += st == GA_EVENT;
    stats->hook_stops += st == GA_STOPPED;
    stats->sensitivity_steps_ok += st >= GA_OK && md->sens;
    stats->sparse_ok += st >= GA_OK && strstr(ga_linear_solver_name(s), "sparse") != NULL;
}

/* One sequence: its choices from `data` (fuzzing; the sequence ends with the bytes) or from a
 * generator seeded by `seq`; with `rotor`, on the chain and a rotor of a kind the sequence
 * draws (the chain's runs draw nothing for it: their choices stay those of the bytes). */
static void run_sequence(int seq, const uint8_t *data, size_t size, seq_stats *stats, int rotor)
{
    model md = {0};
    md.p[0] = 9.81;
    md.rng = 0x9E3779B97F4A7C15ull * (uint64_t)(seq + 1);
    md.data = data;
    md.size = size;
    for (int k = 0; k < 4 && !data; ++k)
        next(&md);
    const int links = 1 + pick(&md, MAX_LINKS);
    const int kinds[] = {links, links + 1, 0};
    const int m = kinds[pick(&md, 3)];
    if (rotor) {
        static const int rotors[3] = {GA_SPACE_SO3_QUATERNION, GA_SPACE_SO3_MATRIX, GA_SPACE_SE3};
        md.rotor = rotors[pick(&md, 3)];
    }
    model_shape(&md, links, m);
    ga_solver *s = NULL;
    if (md.rotor) {
        const int block_kinds[2] = {GA_SPACE_VECTOR, md.rotor}, counts[2] = {md.n, 1};
        SEQ_REQUIRE(ga_create_space(2, block_kinds, counts, md.m, &s) == GA_OK);
    } else {
        SEQ_REQUIRE(ga_create(md.n, md.m, &s) == GA_OK);
    }
#ifdef SEQ_TRACE
    fprintf(stderr, "n = %d, m = %d, rotor %d (nv %d, nq %d)\n", md.n, md.m, md.rotor, md.nv,
            md.nq);
#endif
    md.s = s;
    /* snapshots read the state: the step's qdd and lambda, no callbacks */
    SEQ_REQUIRE(ga_set_output(s, GA_OUTPUT_STEP) == GA_OK);
    SEQ_REQUIRE(ga_set_callbacks(s, mass, force, constraint, jacobian, &md) == GA_OK);
    if (pick(&md, 3) == 0) {  /* a third of the runs on the sparse path */
        md.sparse_M = 1;
        SEQ_REQUIRE(ga_set_pattern(s, GA_MATRIX_MASS, md.nv, md.m_diag, md.m_diag) == GA_OK);
        if (md.m > 0) {
            md.sparse_J = 1;
            SEQ_REQUIRE(ga_set_pattern(s, GA_MATRIX_JACOBIAN, md.j_nnz, md.j_rows, md.j_cols) ==
                        GA_OK);
        }
        if (pick(&md, 2)) {
            md.sparse_K = 1;
            SEQ_REQUIRE(ga_set_pattern(s, GA_MATRIX_STIFFNESS, md.k_nnz, md.k_rows,
                                       md.k_cols) == GA_OK);
        }
        SEQ_REQUIRE(ga_set_linear_solver(s, GA_LINEAR_SPARSE) == GA_OK);
    }
    if (pick(&md, 3) == 0) {  /* a first-order state in a third of the runs */
        md.r = 1;
        SEQ_REQUIRE(ga_set_first_order(s, 1, force_y, rate) == GA_OK);
    }
    if (pick(&md, 3) == 0) {  /* sensitivities in a third: forward, adjoint (not with y), both */
        const int methods = md.r ? GA_SENSITIVITY_FORWARD : 1 + pick(&md, 3);
        md.sens = 1;
        md.sens_forward = methods & GA_SENSITIVITY_FORWARD;
        md.sens_adjoint = (methods & GA_SENSITIVITY_ADJOINT) != 0;
        /* what the parameters enter: the force always; M and Phi (which do not depend on
         * them: derivatives by differences or by mass_p and constraint_p, zero) sometimes */
        const int depends = GA_DEPENDS_FORCE | (pick(&md, 3) == 0 ? GA_DEPENDS_MASS : 0) |
                            (pick(&md, 3) == 0 ? GA_DEPENDS_CONSTRAINT : 0);
        SEQ_REQUIRE(ga_set_sensitivity(s, 2, md.p, NULL, depends) == GA_OK);
        SEQ_REQUIRE(ga_set_sensitivity_method(s, methods, 1 + pick(&md, 40)) == GA_OK);
    }
    const int ops = data ? MAX_OPS : 5 + pick(&md, MAX_OPS - 5);
    for (int op = 0; op < ops && !md.exhausted; ++op) {
        if (pick(&md, 6) == 0) {  /* arm a failure (or disarm: NONE) */
            md.fault = (fault_kind)pick(&md, FAULT_KINDS);
            md.fault_callback = pick(&md, CALLBACKS);
            md.calls = 0;
            md.fault_at = 1 + pick(&md, 30);
        }
        double before[STATE_MAX];
        ga_status st = GA_OK;
        int changes = 1, restore_limits = 0;
        const char *call = "";
        switch (pick(&md, 48)) {
        case 0: call = "ga_set_rho_inf"; st = ga_set_rho_inf(s, edge_value(&md)); break;
        case 1: {
            const double am = edge_value(&md), af = edge_value(&md), b = edge_value(&md);
            call = "ga_set_params";
            st = ga_set_params(s, am, af, b, edge_value(&md));
            break;
        }
        case 2: call = "ga_set_newton"; st = ga_set_newton(s, edge_value(&md), pick(&md, 30) - 2); break;
        case 3: call = "ga_set_tangents"; st = ga_set_tangents(s, pick(&md, 2) ? stiffness : NULL, NULL); break;
        case 4: call = "ga_set_tangent_mode"; st = ga_set_tangent_mode(s, pick(&md, 5) - 1); break;
        case 5: call = "ga_set_scaling"; st = ga_set_scaling(s, pick(&md, 3)); break;
        case 6: call = "ga_set_jacobian_reuse"; st = ga_set_jacobian_reuse(s, pick(&md, 3)); break;
        case 7: call = "ga_set_constant_mass"; st = ga_set_constant_mass(s, pick(&md, 3)); break;
        case 8: call = "ga_set_predictor"; st = ga_set_predictor(s, pick(&md, 4)); break;
        case 9: call = "ga_set_linear_solver"; st = ga_set_linear_solver(s, pick(&md, 7) - 1); break;
        case 10: call = "ga_set_formulation"; st = ga_set_formulation(s, pick(&md, 3)); break;
        case 11: call = "ga_set_redundant_constraints"; st = ga_set_redundant_constraints(s, pick(&md, 3)); break;
        case 12: call = "ga_set_rescale"; st = ga_set_rescale(s, pick(&md, 3)); break;
        case 13: call = "ga_set_corrected_start"; st = ga_set_corrected_start(s, pick(&md, 3)); break;
        case 14: {
            const double rtol = edge_value(&md);
            if (pick(&md, 3)) {
                call = "ga_set_tolerances";
                st = ga_set_tolerances(s, rtol, edge_value(&md));
                break;
            }
            /* one atol per coordinate: one entry an edge value, the others a plain one */
            double atol[2 * VMAX + 1];
            const int len = 2 * md.nv + md.r;
            for (int k = 0; k < len; ++k)
                atol[k] = 1e-6 * (1 + k);
            atol[pick(&md, len)] = edge_value(&md);
            call = "ga_set_tolerances_vector";
            st = ga_set_tolerances_vector(s, rtol, pick(&md, 16) ? atol : NULL);
            break;
        }
        case 15: {
            const double h_min = pick(&md, 2) ? 0.0 : edge_value(&md), h_max = edge_value(&md);
            call = "ga_set_step_limits";
            st = ga_set_step_limits(s, h_min, h_max);
            if (st == GA_OK)
                md.h_min = h_min, md.h_max = h_max;
            break;
        }
        case 16: call = "ga_set_initial_step"; st = ga_set_initial_step(s, edge_value(&md)); break;
        case 17: call = "ga_set_constraint_accel"; st = ga_set_constraint_accel(s, pick(&md, 2) ? accel : NULL); break;
        case 18: call = "ga_set_constraint_dt"; st = ga_set_constraint_dt(s, pick(&md, 2) ? time_derivative : NULL); break;
        case 19: {
            const int mode = pick(&md, 3);
            call = "ga_set_init_mode";
            st = ga_set_init_mode(s, mode, edge_value(&md));
            break;
        }
        case 20: case 21: case 34: case 35: {
            const double angle = 0.3 + uniform(&md);
            /* the first link at `angle` from the downward vertical, the others horizontal */
            double q0[QMAX] = {0}, v0[VMAX] = {0};
            for (int k = 0; k < md.links; ++k) {
                q0[2 * k] = sin(angle) + k;
                q0[2 * k + 1] = -cos(angle);
            }
            if (md.rotor) {  /* the rotor at a third of a turn about (1, 1, 1), spinning */
                double *r = q0 + md.n + (md.rotor == GA_SPACE_SE3 ? 3 : 0);
                if (md.rotor == GA_SPACE_SO3_MATRIX) {
                    const double R[9] = {0, 1, 0, 0, 0, 1, 1, 0, 0};
                    memcpy(r, R, sizeof R);
                } else {
                    r[0] = r[1] = r[2] = r[3] = 0.5;
                }
                for (int i = md.n; i < md.nv; ++i)
                    v0[i] = 0.5 + i - md.n;
            }
            /* (a rotor's storage perturbed: no rotation, refused) */
            if (pick(&md, 4) == 0)
                q0[pick(&md, md.nq)] += edge_value(&md);
            if (pick(&md, 4) == 0)
                v0[pick(&md, md.nv)] += edge_value(&md);
            const double t0 = pick(&md, 5) == 0 ? edge_value(&md) : 0.0;
            if (md.r && pick(&md, 4)) {
                const double y0[1] = {pick(&md, 4) == 0 ? edge_value(&md) : 0.3};
                call = "ga_init_y";
                st = ga_init_y(s, t0, q0, v0, y0);
                break;
            }
            call = "ga_init";
            st = ga_init(s, t0, q0, v0);
            break;
        }
        case 22: case 23: case 24: case 25: {
            const int len = snapshot(&md, s, before);
            call = "ga_step";
            st = ga_step(s, step_size(&md));
            after_step(&md, s, st, before, len, call, seq, stats);
            break;
        }
        case 26: {
            double t = 0.0;
            const int len = snapshot(&md, s, before);
            ga_get_t(s, &t);
            const double t_stop = pick(&md, 4) ? t + step_size(&md) : edge_value(&md);
            call = "ga_step_adaptive";
            st = ga_step_adaptive(s, t_stop);
            after_step(&md, s, st, before, len, call, seq, stats);
            break;
        }
        case 27: {
            double t = 0.0, q[QMAX], v[VMAX], lambda[MMAX];
            ga_get_t(s, &t);
            call = "ga_interpolate";
            changes = 0;
            st = ga_interpolate(s, t - 1e-4 * uniform(&md), q, v, md.m ? lambda : NULL);
            break;
        }
        case 28: {
            size_t len = 0;
            double buf[CKPT_MAX];
            SEQ_REQUIRE(ga_state_size(s, &len) == GA_OK);
            SEQ_REQUIRE(len <= CKPT_MAX);
            call = "ga_get_state";
            changes = 0;
            st = ga_get_state(s, buf, len);
            if (st == GA_OK) {
                check(s, st, changes, call, seq);
                /* (values a solver keeps, such as a constant mass matrix, are evaluated
                 * again after a restore: the twins agree when the callbacks are functions) */
                if (pick(&md, 2) == 0 && !md.impure && !md.sens_adjoint)
                    stats->twin_steps_ok += restart_twin(&md, s, buf, len, seq);
                if (pick(&md, 3) == 0)
                    buf[pick(&md, (int)len)] = edge_value(&md);
                call = "ga_set_state";
                changes = 1;
                st = ga_set_state(s, buf, len - (size_t)(pick(&md, 5) == 0));
            }
            break;
        }
        case 29: {
            long long value;
            call = "ga_get_counter";
            changes = 0;
            st = ga_get_counter(s, pick(&md, GA_COUNTER_COUNT + 2) - 1, &value);
            if (pick(&md, 3) == 0) {
                check(s, st, changes, call, seq);
                call = "ga_reset_counters";
                changes = 1;
                st = ga_reset_counters(s);
            }
            break;
        }
        case 31: case 32: {
            int must_fail = 0;
            call = "ga_set_pattern";
            st = declare_pattern(&md, s, &must_fail);
            if (must_fail && st == GA_OK)
                SEQ_FAIL("sequence %d: an invalid pattern was accepted", seq);
            break;
        }
        case 36: {  /* first-order states: reads, the coupling option, a late declaration */
            double t = 0.0, y[1], yd[1];
            ga_get_t(s, &t);
            switch (pick(&md, 5)) {
            case 4: {  /* the rate's own patterns (g_q zero, g_v at (0, 0)), or an index too far */
                static const int zero[1] = {0}, far[1] = {VMAX};
                const int which = pick(&md, 3);  /* 2: unknown, refused */
                call = "ga_set_coupling_pattern";
                st = ga_set_coupling_pattern(s, which, which == 0 ? 0 : 1, zero,
                                             pick(&md, 4) ? zero : far);
                break;
            }
            case 0: call = "ga_get_y"; changes = 0; st = ga_get_y(s, y, yd); break;
            case 1:
                call = "ga_interpolate_y";
                changes = 0;
                st = ga_interpolate_y(s, t - 1e-4 * uniform(&md), y, yd);
                break;
            case 2: call = "ga_set_coupling_exact"; st = ga_set_coupling_exact(s, pick(&md, 2)); break;
            default:
                call = "ga_set_first_order";
                st = ga_set_first_order(s, md.r, force_y, rate);  /* the same, or refused */
            }
            break;
        }
        case 37: {  /* sensitivities: reads, the adjoint sweep, late or bad settings */
            double d[VMAX], J, dJ[2];
            switch (pick(&md, 4)) {
            case 0:
                call = "ga_get_sensitivity";
                changes = 0;
                st = ga_get_sensitivity(s, pick(&md, 4) - 1, d, NULL, NULL, NULL);
                break;
            case 1: {  /* reads the record: leaves the state as it was, whatever its status */
                const int len = snapshot(&md, s, before);
                double after[STATE_MAX];
                call = "ga_adjoint_gradient";
                st = ga_adjoint_gradient(s, NULL, adjoint_cost, &J, dJ);
                stats->adjoint_ok += st == GA_OK;
                if (len && (snapshot(&md, s, after) != len ||
                            memcmp(before, after, sizeof(double) * (size_t)len) != 0))
                    SEQ_FAIL("sequence %d: ga_adjoint_gradient changed the state", seq);
                break;
            }
            case 2:
                call = "ga_set_sensitivity_method";
                st = ga_set_sensitivity_method(s, pick(&md, 5) - 1, pick(&md, 3) - 1);
                if (st == GA_OK) {  /* before any ga_init: the record's size changed */
                    md.sens_forward = 0;
                    SEQ_REQUIRE(ga_set_sensitivity_method(
                                    s, GA_SENSITIVITY_FORWARD |
                                           (md.sens_adjoint ? GA_SENSITIVITY_ADJOINT : 0),
                                    40) == GA_OK);
                    md.sens_forward = md.sens;
                }
                break;
            default:
                call = "ga_set_sensitivity";  /* refused after ga_init or with np < 0 */
                st = ga_set_sensitivity(s, -pick(&md, 2), md.p, NULL, GA_DEPENDS_FORCE);
                if (st == GA_OK)  /* np = 0 before ga_init: sensitivities off */
                    md.sens = md.sens_forward = md.sens_adjoint = 0;
            }
            break;
        }
        case 39: {
            call = "ga_set_step_hook";
            if (pick(&md, 3) == 0) {
                st = ga_set_step_hook(s, NULL, NULL, 0);
            } else {
                md.hook_stops = pick(&md, 2);
                st = ga_set_step_hook(s, step_hook, &md, pick(&md, 2));
            }
            break;
        }
        case 40: {  /* ga_advance over a short interval, its work bounded by h_min */
            double t = 0.0, after = 0.0;
            const int len = snapshot(&md, s, before);
            ga_get_t(s, &t);
            const double span = step_size(&md);
            const double t_out = t + span;
            int limited = 0;
            if (span > 0.0 && isfinite(t_out))
                limited = ga_set_step_limits(s, fmax(md.h_min, span / 256.0),
                                             md.h_max >= span / 256.0 ? md.h_max : 0.0) == GA_OK;
            call = "ga_advance";
            st = ga_advance(s, t_out);
            check_event_log(&md, s, st, seq);
            stats->steps_ok += st >= GA_OK;
            stats->advance_ok += st == GA_OK;
            /* steps accepted before a failure stay: t between where it was and t_out */
            if (len && ga_get_t(s, &after) == GA_OK && !(after >= t && after <= fmax(t, t_out)))
                SEQ_FAIL("sequence %d: ga_advance to %.17g from %.17g ended at %.17g", seq,
                         t_out, t, after);
            restore_limits = limited;  /* after the checks of the call's status and message */
            break;
        }
        case 41: {  /* events that see y, or the plain ones again */
            const model kept = md;
            md.ev_y = md.r && pick(&md, 2);
            md.ev_count = pick(&md, 4);
            for (int k = 0; k < 3; ++k) {
                md.ev_dir[k] = pick(&md, 3) - 1;
                md.ev_term[k] = pick(&md, 2);
                md.ev_level[k] = 0.3 + 0.02 * (uniform(&md) - 0.5);
            }
            call = md.ev_y ? "ga_set_events_y" : "ga_set_events";
            st = set_events(&md, s);
            if (st != GA_OK)
                md = kept;
            break;
        }
        case 42:
            call = "ga_set_coupling";
            st = ga_set_coupling(s, pick(&md, 2) ? coupling : NULL);
            break;
        case 43: {  /* the sensitivities' starts and derivative callbacks */
            double dq0[VMAX], dv0[VMAX];
            for (int i = 0; i < md.nv; ++i)
                dq0[i] = pick(&md, 8) ? 0.1 * uniform(&md) : edge_value(&md),
                dv0[i] = pick(&md, 8) ? 0.1 * uniform(&md) : edge_value(&md);
            switch (pick(&md, 3)) {
            case 0:
                call = "ga_set_sensitivity_start";
                st = ga_set_sensitivity_start(s, pick(&md, 4) - 1, pick(&md, 4) ? dq0 : NULL,
                                              pick(&md, 4) ? dv0 : NULL);
                break;
            case 1:
                call = "ga_set_parameter_derivatives";
                st = ga_set_parameter_derivatives(s, pick(&md, 2) ? force_p : NULL,
                                                  pick(&md, 2) ? mass_p : NULL);
                break;
            default:
                call = "ga_set_constraint_parameter_derivative";
                st = ga_set_constraint_parameter_derivative(s, pick(&md, 2) ? constraint_p : NULL);
            }
            break;
        }
        case 44: {  /* adjoint checkpointing (before ga_init; some refused, none allocating
                     * beyond memory: the fuzzer's malloc limit would take that for a defect) */
            static const long intervals[] = {0, 1, 3, 7, -1, 1L << 40};
            const int k = pick(&md, 6);
            const long interval = intervals[k];
            const long count = k == 5 ? LONG_MAX / 2 : pick(&md, 12) - 1;
            call = "ga_set_adjoint_checkpoints";
            st = ga_set_adjoint_checkpoints(s, interval, count);
            break;
        }
        case 45: {  /* the adjoint with a running cost, a terminal one or both */
            const int len = snapshot(&md, s, before);
            double after[STATE_MAX], J, dJ[2];
            const int which = 1 + pick(&md, 3);
            call = "ga_adjoint_gradient";
            st = ga_adjoint_gradient(s, which & 1 ? running_cost : NULL,
                                     which & 2 ? adjoint_cost : NULL, &J, dJ);
            stats->adjoint_ok += st == GA_OK;
            if (len && (snapshot(&md, s, after) != len ||
                        memcmp(before, after, sizeof(double) * (size_t)len) != 0))
                SEQ_FAIL("sequence %d: ga_adjoint_gradient changed the state (%s: %s)", seq,
                         ga_strerror(st), ga_last_error(s));
            if (st == GA_OK && !(isfinite(J) && isfinite(dJ[0]) && isfinite(dJ[1])))
                SEQ_FAIL("sequence %d: ga_adjoint_gradient returned GA_OK with J = %g, dJ = "
                         "(%g, %g)", seq, J, dJ[0], dJ[1]);
            break;
        }
        case 46: {  /* reads added since the first harness */
            double t = 0.0, x[VMAX], y[1], yd[1], am, af, b, g;
            int n = 0, m = 0;
            ga_get_t(s, &t);
            changes = 0;
            switch (pick(&md, 4)) {
            case 0:
                call = "ga_interpolate_qdd";
                st = ga_interpolate_qdd(s, t - 1e-4 * uniform(&md), x);
                break;
            case 1:
                call = "ga_get_sensitivity_y";
                st = ga_get_sensitivity_y(s, pick(&md, 3) - 1, y, yd);
                break;
            case 2:
                call = "ga_get_params";
                st = ga_get_params(s, &am, &af, &b, &g);
                break;
            default:
                call = "ga_get_size";
                st = ga_get_size(s, &n, &m);
                if (st == GA_OK && (n != md.nv || m != md.m))
                    SEQ_FAIL("sequence %d: ga_get_size said %d, %d", seq, n, m);
            }
            break;
        }
        case 47:
            call = "ga_set_resolution_check";
            st = ga_set_resolution_check(s, pick(&md, 3) ? edge_value(&md) : INFINITY);
            break;
        case 30: {
            double value;
            call = "ga_get_info";
            changes = 0;
            st = ga_get_info(s, pick(&md, GA_INFO_COUNT + 2) - 1, &value);
            break;
        }
        default: {
            if (pick(&md, 2)) {  /* events: sometimes a direction that must be refused */
                const model kept = md;  /* a refused call keeps the events set before */
                const int bad = pick(&md, 8) == 0;
                md.ev_count = pick(&md, 4);
                md.ev_lambda = pick(&md, 2);
                /* levels next to the current values, so that the functions cross soon */
                double q[QMAX] = {0}, lambda[MMAX] = {0};
                ga_get_q(s, q);
                if (md.m)
                    ga_get_lambda(s, lambda);
                for (int k = 0; k < 3; ++k) {
                    md.ev_dir[k] = pick(&md, 3) - 1;
                    md.ev_term[k] = pick(&md, 2);
                    const double now = k == 2 && md.ev_lambda && md.m ? lambda[0] : q[k % md.n];
                    md.ev_level[k] = now + 0.02 * (uniform(&md) - 0.5) * (1.0 + fabs(now));
                }
                if (bad)
                    md.ev_dir[0] = 5;
                call = "ga_set_events";
                st = set_events(&md, s);
                if (bad && md.ev_count > 0 && st != GA_ERR_ARG)
                    SEQ_FAIL("sequence %d: direction 5 was accepted", seq);
                if (st != GA_OK) {
                    md.ev_count = kept.ev_count;
                    md.ev_lambda = kept.ev_lambda;
                    memcpy(md.ev_dir, kept.ev_dir, sizeof md.ev_dir);
                    memcpy(md.ev_term, kept.ev_term, sizeof md.ev_term);
                    memcpy(md.ev_level, kept.ev_level, sizeof md.ev_level);
                }
                break;
            }
            int active[MMAX];
            call = "ga_get_active_constraints";
            changes = 0;
            st = ga_get_active_constraints(s, active);
            break;
        }
        }
        check(s, st, changes, call, seq);
        if (restore_limits)
            SEQ_REQUIRE(ga_set_step_limits(s, md.h_min, md.h_max) == GA_OK);
#ifdef SEQ_TRACE
        {
            double t_now = NAN, h_now = NAN;
            ga_get_t(s, &t_now);
            ga_get_h_last(s, &h_now);
            fprintf(stderr, "%s: %d %s (t %.17g, h_last %g)\n", call, st,
                    st ? ga_last_error(s) : "", t_now, h_now);
        }
#endif
        ++stats->calls;
    }
    stats->operating_points_ok += operating_points_phase(&md, s, seq);
    if (md.reentry_allowed)
        SEQ_FAIL("sequence %d: a callback's ga_step on its own solver was not refused", seq);
    if (md.hook_wrong)
        SEQ_FAIL("sequence %d: the step hook read other values than it was passed, or changed "
                 "the solver (%ld of %ld calls)", seq, md.hook_wrong, md.hook_calls);
    stats->hook_calls += md.hook_calls;
    ga_free(s);
}

#endif
