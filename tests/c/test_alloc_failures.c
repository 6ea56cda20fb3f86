/* Every allocation of a call that allocates, failed in turn (issue 17): the call returns
 * GA_ERR_NOMEM with a message, and retried without the failure it works, and the run that
 * follows is bit for bit that of a solver that never met the failure; an option that failed
 * and is not retried leaves the run bit for bit that of a solver that never made the call; a
 * start instead of a failed restore runs as one that never met it. Calls swept: ga_init,
 * ga_set_state (also on a new solver with events on y, a first-order state, sensitivities and a
 * step hook), ga_adjoint_gradient with checkpoints (its segments computed again), and the
 * options that allocate after ga_init (ga_set_formulation to index 2, ga_set_tangent_mode to
 * finite differences, ga_set_output), ga_set_events and ga_set_events_y (replacing an earlier
 * set), ga_set_coupling_pattern -- on the sparse path with
 * finite-difference tangents grouped by pattern. malloc and friends are
 * interposed here (not under the sanitizers, whose allocator cannot be made to fail so; nor
 * under valgrind, which replaces them). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <galpha.h>

#include "scenes/chain.h"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_UNDEFINED__)
#define INTERPOSED 0
#else
#define INTERPOSED 1
static long fail_at = 0; /* the allocation to fail, counted from arming; 0: none */
static long count = 0;
extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
extern void *__libc_memalign(size_t, size_t);
extern void __libc_free(void *);
static int fails(void) { return fail_at > 0 && ++count == fail_at; }
void *malloc(size_t n) { return fails() ? NULL : __libc_malloc(n); }
void *calloc(size_t k, size_t n) { return fails() ? NULL : __libc_calloc(k, n); }
void *realloc(void *p, size_t n) { return fails() ? NULL : __libc_realloc(p, n); }
void *memalign(size_t a, size_t n) { return fails() ? NULL : __libc_memalign(a, n); }
void *aligned_alloc(size_t a, size_t n) { return memalign(a, n); }
int posix_memalign(void **out, size_t a, size_t n)
{
    *out = memalign(a, n);
    return *out ? 0 : 12;
}
void free(void *p) { __libc_free(p); }
#endif

enum { kLinks = 6, N = 3 * kLinks, M = 2 * kLinks };
static chain g_chain;

/* A chain on the sparse path without a K_t callback, so that its finite differences (grouped
 * by the pattern) are part of what is set up. */
static ga_solver *make(void)
{
    ga_solver *s = NULL;
    g_chain = chain_make(kLinks);
    if (ga_create(N, M, &s) != GA_OK)
        return NULL;
    assert_int_equal(chain_declare_patterns(&g_chain, s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, chain_mass, chain_force, chain_constraint,
                                      chain_jacobian, &g_chain),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, chain_constraint_accel), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
    return s;
}

/* A first-order state on the chain: y' = v_0 - y, acting on coordinate 0 as a force y. */
static int chain_force_y(double t, const double *q, const double *v, const double *y, double *f,
                         void *u)
{
    const int rc = chain_force(t, q, v, f, u);
    f[0] += y[0];
    return rc;
}
static int chain_rate(double t, const double *q, const double *v, const double *y, double *ydot,
                      void *u)
{
    (void)t, (void)q, (void)u;
    ydot[0] = v[0] - y[0];
    return 0;
}
static const double kY0[1] = {0.5};
/* The call is made before the start: 1, ga_init_y (SET_FIRST_ORDER); 2, ga_init (the
 * sensitivity settings). */
static int g_start_before_steps;

static void steps(ga_solver *s, double *q)
{
    if (g_start_before_steps) {
        double q0[N], v0[N];
        chain_initial(&g_chain, q0, v0);
        assert_int_equal(g_start_before_steps == 1 ? ga_init_y(s, 0.0, q0, v0, kY0)
                                                   : ga_init(s, 0.0, q0, v0),
                         GA_OK);
    }
    for (int i = 0; i < 5; ++i)
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
    assert_int_equal(ga_get_q(s, q), GA_OK);
}

/* The chain with its first constraint row twice, dropped as redundant (SuiteSparseQR, whose
 * CHOLMOD printed "out of memory" to stdout). */
static int first_row[4], nfirst, nnz_own;
static int copy_constraint(double t, const double *q, double *phi, void *u)
{
    chain_constraint(t, q, phi, u);
    phi[M] = phi[0];
    return 0;
}
static int copy_jacobian(double t, const double *q, double *J, void *u)
{
    chain_jacobian(t, q, J, u);
    for (int k = 0; k < nfirst; ++k)
        J[nnz_own + k] = J[first_row[k]];
    return 0;
}
static ga_solver *make_redundant(void)
{
    ga_solver *s = NULL;
    int rows[64], cols[64];
    g_chain = chain_make(kLinks);
    assert_int_equal(ga_create(N, M + 1, &s), GA_OK);
    assert_int_equal(chain_declare_patterns(&g_chain, s), GA_OK);
    nnz_own = chain_pattern(&g_chain, GA_MATRIX_JACOBIAN, rows, cols);
    nfirst = 0;
    for (int k = 0; k < nnz_own; ++k)
        if (rows[k] == 0) {
            rows[nnz_own + nfirst] = M;
            cols[nnz_own + nfirst] = cols[k];
            first_row[nfirst++] = k;
        }
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, nnz_own + nfirst, rows, cols), GA_OK);
    assert_int_equal(ga_set_callbacks(s, chain_mass, chain_force, copy_constraint, copy_jacobian,
                                      &g_chain),
                     GA_OK);
    assert_int_equal(ga_set_constraint_accel(s, NULL), GA_OK);
    assert_int_equal(ga_set_redundant_constraints(s, GA_REDUNDANT_DROP), GA_OK);
    return s;
}

typedef enum call {
    INIT, INIT_INDEX2, INIT_REDUNDANT, SET_STATE, FORMULATION, TANGENT_MODE, OUTPUT, EVENTS,
    SET_FIRST_ORDER, INIT_Y, SET_SENSITIVITY, SENSITIVITY_METHOD, SENSITIVITY_START,
    INIT_SENSITIVITY, ADJOINT_CHECKPOINTS, STEP_HOOK, ADJOINT_GRADIENT, EVENTS_Y,
    COUPLING_PATTERN, SET_STATE_EVERYTHING
} call;
static const char *const kNames[] = {"ga_init", "ga_init (index 2)",
                                     "ga_init (a redundant constraint)", "ga_set_state",
                                     "ga_set_formulation", "ga_set_tangent_mode",
                                     "ga_set_output", "ga_set_events", "ga_set_first_order",
                                     "ga_init_y", "ga_set_sensitivity",
                                     "ga_set_sensitivity_method", "ga_set_sensitivity_start",
                                     "ga_init (sensitivities)", "ga_set_adjoint_checkpoints",
                                     "ga_set_step_hook",
                                     "ga_adjoint_gradient (checkpoints)", "ga_set_events_y",
                                     "ga_set_coupling_pattern",
                                     "ga_set_state (events, y, sensitivities, hook; new "
                                     "solver)"};

/* event functions that never fire */
static int far_away(double t, const double *q, const double *v, const double *lambda,
                    double *g, void *user)
{
    (void)t, (void)v, (void)lambda, (void)user;
    g[0] = 100.0 + q[0];
    g[1] = 100.0 - q[1];
    return 0;
}

/* a step hook that only watches */
static int quiet_hook(const ga_solver *s, double t, const double *q, const double *v,
                      const double *lambda, void *user)
{
    (void)s, (void)t, (void)q, (void)v, (void)lambda, (void)user;
    return 0;
}

/* the same, seeing y */
static int far_away_y(double t, const double *q, const double *v, const double *y,
                      const double *lambda, double *g, void *user)
{
    (void)y;
    return far_away(t, q, v, lambda, g, user);
}

/* The adjoint's cost: the x of link 0's centre at the end; its value and gradient of the
 * call under test, which the retried and the undisturbed call must give alike. */
static double g_J, g_dJ[3];
static int terminal_x(double t, const double *q, const double *v, const double *qdd,
                      const double *lambda, double *value, double *d_q, double *d_v,
                      double *d_qdd, double *d_lambda, double *d_p, void *user)
{
    (void)t, (void)v, (void)qdd, (void)lambda, (void)user;
    memset(d_q, 0, sizeof(double) * N);
    memset(d_v, 0, sizeof(double) * N);
    memset(d_qdd, 0, sizeof(double) * N);
    memset(d_lambda, 0, sizeof(double) * M);
    memset(d_p, 0, sizeof(double) * 3);
    d_q[0] = 1.0;
    *value = q[0];
    return 0;
}

/* Events, a first-order state, sensitivities and a step hook, before any start. */
static void everything(ga_solver *s)
{
    assert_int_equal(ga_set_first_order(s, 1, chain_force_y, chain_rate), GA_OK);
    assert_int_equal(ga_set_events_y(s, 2, far_away_y, NULL, NULL, 1), GA_OK);
    assert_int_equal(ga_set_sensitivity(s, 3, &g_chain.mass, NULL,
                                        GA_DEPENDS_FORCE | GA_DEPENDS_MASS),
                     GA_OK);
    assert_int_equal(ga_set_step_hook(s, quiet_hook, NULL, 1), GA_OK);
}

/* The call under test on a solver prepared for it. */
static ga_status do_call(ga_solver *s, call c, const double *checkpoint, size_t len)
{
    double q[N], v[N];
    static const int rows[1] = {0}, cols[1] = {0};
    chain_initial(&g_chain, q, v);
    switch (c) {
    case ADJOINT_GRADIENT: return ga_adjoint_gradient(s, NULL, terminal_x, &g_J, g_dJ);
    case EVENTS_Y: return ga_set_events_y(s, 2, far_away_y, NULL, NULL, 1);
    case COUPLING_PATTERN: return ga_set_coupling_pattern(s, GA_COUPLING_G_V, 1, rows, cols);
    case SET_STATE_EVERYTHING: return ga_set_state(s, checkpoint, len);
    case INIT:
    case INIT_INDEX2:
    case INIT_REDUNDANT: return ga_init(s, 0.0, q, v);
    case SET_STATE: return ga_set_state(s, checkpoint, len);
    case FORMULATION: return ga_set_formulation(s, GA_INDEX2_STABILIZED);
    case TANGENT_MODE: return ga_set_tangent_mode(s, GA_TANGENT_FD);
    case EVENTS: return ga_set_events(s, 2, far_away, NULL, NULL, 1);
    case SET_FIRST_ORDER: return ga_set_first_order(s, 1, chain_force_y, chain_rate);
    case INIT_Y: return ga_init_y(s, 0.0, q, v, kY0);
    case INIT_SENSITIVITY: return ga_init(s, 0.0, q, v);
    case SET_SENSITIVITY:
        return ga_set_sensitivity(s, 3, &g_chain.mass, NULL, GA_DEPENDS_FORCE | GA_DEPENDS_MASS);
    case SENSITIVITY_METHOD:
        return ga_set_sensitivity_method(s, GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT, 10);
    case SENSITIVITY_START: return ga_set_sensitivity_start(s, 1, q, v);
    case ADJOINT_CHECKPOINTS: return ga_set_adjoint_checkpoints(s, 2, 3);
    case STEP_HOOK: return ga_set_step_hook(s, quiet_hook, NULL, 1);
    default: return ga_set_output(s, GA_OUTPUT_CONSISTENT);
    }
}

/* A solver ready for the call: options that make the call allocate set the other way first. */
static ga_solver *prepare(call c)
{
    ga_solver *s = c == INIT_REDUNDANT ? make_redundant() : make();
    assert_non_null(s);
    double q[N], v[N];
    chain_initial(&g_chain, q, v);
    if (c == TANGENT_MODE)
        assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_NEGLECT), GA_OK);
    if (c == OUTPUT)
        assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    if (c == INIT_INDEX2)
        assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
    if (c == EVENTS)
        assert_int_equal(ga_set_events(s, 1, far_away, NULL, NULL, 0), GA_OK);
    if (c == INIT_Y || c == EVENTS_Y || c == COUPLING_PATTERN)
        assert_int_equal(ga_set_first_order(s, 1, chain_force_y, chain_rate), GA_OK);
    if (c == EVENTS_Y)  /* (replaced by the call) */
        assert_int_equal(ga_set_events_y(s, 1, far_away_y, NULL, NULL, 0), GA_OK);
    if (c == SET_STATE_EVERYTHING)
        everything(s);
    const int sensitivities = c == SENSITIVITY_METHOD || c == SENSITIVITY_START ||
                              c == INIT_SENSITIVITY || c == ADJOINT_CHECKPOINTS ||
                              c == ADJOINT_GRADIENT;
    if (sensitivities)
        assert_int_equal(ga_set_sensitivity(s, 3, &g_chain.mass, NULL,
                                            GA_DEPENDS_FORCE | GA_DEPENDS_MASS),
                         GA_OK);
    if (c == ADJOINT_CHECKPOINTS)
        assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_OK);
    if (c == ADJOINT_GRADIENT) {  /* a recorded run of 7 steps in segments of 2 */
        assert_int_equal(ga_set_sensitivity_method(s, GA_SENSITIVITY_ADJOINT, 10), GA_OK);
        assert_int_equal(ga_set_adjoint_checkpoints(s, 2, 10), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        for (int i = 0; i < 7; ++i)
            assert_int_equal(ga_step(s, 1e-3), GA_OK);
    }
    g_start_before_steps = c == SET_FIRST_ORDER || c == EVENTS_Y || c == COUPLING_PATTERN
                               ? 1
                           : sensitivities || c == SET_SENSITIVITY ? 2 : 0;
    if (c == INIT_SENSITIVITY || c == ADJOINT_GRADIENT)
        g_start_before_steps = 0;
    if (c != INIT && c != INIT_INDEX2 && c != INIT_REDUNDANT && c != SET_STATE &&
        c != SET_FIRST_ORDER && c != INIT_Y && !g_start_before_steps && c != INIT_SENSITIVITY &&
        c != ADJOINT_GRADIENT && c != SET_STATE_EVERYTHING)
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    return s;
}

/* Options: a failed one not retried must leave the run as if it had not been made. */
static int optional(call c)
{
    return c == FORMULATION || c == TANGENT_MODE || c == OUTPUT || c == EVENTS ||
           c == EVENTS_Y || c == COUPLING_PATTERN || c == SENSITIVITY_START ||
           c == ADJOINT_CHECKPOINTS || c == STEP_HOOK || c == SENSITIVITY_METHOD;
}

static void sweep(call c)
{
#if INTERPOSED
    static double checkpoint[1024];
    size_t len = 0;
    {   /* a checkpoint of the initial state, for ga_set_state */
        ga_solver *s = make();
        double q[N], v[N];
        chain_initial(&g_chain, q, v);
        if (c == SET_STATE_EVERYTHING) {
            everything(s);
            assert_int_equal(ga_init_y(s, 0.0, q, v, kY0), GA_OK);
        } else {
            assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        }
        assert_int_equal(ga_state_size(s, &len), GA_OK);
        assert_true(len <= 1024);
        assert_int_equal(ga_get_state(s, checkpoint, len), GA_OK);
        ga_free(s);
    }
    /* the run of a solver that never made the call (options only) */
    double q_without[N];
    if (optional(c)) {
        ga_solver *s = prepare(c);
        steps(s, q_without);
        ga_free(s);
    }
    /* the run of a solver that never met a failure */
    double q_ref[N], q[N], J_ref = 0.0, dJ_ref[3] = {0};
    {
        ga_solver *s = prepare(c);
        assert_int_equal(do_call(s, c, checkpoint, len), GA_OK);
        J_ref = g_J;
        memcpy(dJ_ref, g_dJ, sizeof dJ_ref);
        steps(s, q_ref);
        ga_free(s);
    }
    /* what the library would print goes to a file, which must stay empty */
    char path[] = "/tmp/galpha_stdout_XXXXXX";
    const int out = mkstemp(path), saved = dup(1);
    assert_true(out >= 0 && saved >= 0);
    unlink(path);
    long k = 1, failed = 0;
    for (;; ++k) {
        ga_solver *s = prepare(c);
        fflush(stdout);
        dup2(out, 1);
        count = 0;
        fail_at = k;
        const ga_status st = do_call(s, c, checkpoint, len);
        const int hit = count >= k;
        fail_at = 0;
        fflush(stdout);
        dup2(saved, 1);
        if (!hit) { /* the call made fewer than k allocations: swept them all */
            assert_int_equal(st, GA_OK);
            ga_free(s);
            break;
        }
        if (st == GA_OK) { /* an allocation whose failure the call survives (a fallback) */
            steps(s, q);
        } else {
            ++failed;
            if (st != GA_ERR_NOMEM)
                fail_msg("%s, allocation %ld failed: status %d (%s)", kNames[c], k, st,
                         ga_last_error(s));
            assert_true(ga_last_error(s)[0] != '\0');
            if (optional(c)) {  /* not retried: as if the call had not been made */
                double q_on[N];
                steps(s, q_on);
                if (memcmp(q_on, q_without, sizeof q_on) != 0)
                    fail_msg("%s, allocation %ld failed: the run differs from one that never "
                             "made the call", kNames[c], k);
                ga_free(s);
                s = prepare(c);  /* the same failure again, to retry it */
                count = 0;
                fail_at = k;
                assert_int_equal(do_call(s, c, checkpoint, len), GA_ERR_NOMEM);
                fail_at = 0;
            }
            if (c == SET_STATE_EVERYTHING) {  /* a start instead of the restore */
                ga_solver *r = prepare(c);
                double q0[N], v0[N], q_start[N];
                chain_initial(&g_chain, q0, v0);
                count = 0;
                fail_at = k;
                assert_int_equal(do_call(r, c, checkpoint, len), GA_ERR_NOMEM);
                fail_at = 0;
                assert_int_equal(ga_init_y(r, 0.0, q0, v0, kY0), GA_OK);
                steps(r, q_start);
                if (memcmp(q_start, q_ref, sizeof q_start) != 0)
                    fail_msg("%s, allocation %ld failed: the start after it differs", kNames[c],
                             k);
                ga_free(r);
            }
            const ga_status retry = do_call(s, c, checkpoint, len);
            if (retry != GA_OK)
                fail_msg("%s, retry after allocation %ld failed: %s", kNames[c], k,
                         ga_last_error(s));
            steps(s, q);
        }
        if (memcmp(q, q_ref, sizeof q) != 0)
            fail_msg("%s, allocation %ld failed: the run differs from one without the failure",
                     kNames[c], k);
        if (c == ADJOINT_GRADIENT && (g_J != J_ref || memcmp(g_dJ, dJ_ref, sizeof g_dJ) != 0))
            fail_msg("%s, allocation %ld failed: the retried gradient differs", kNames[c], k);
        ga_free(s);
    }
    const off_t printed = lseek(out, 0, SEEK_END);
    close(out);
    close(saved);
    printf("  %s: %ld allocations, each failed in turn (%ld reported GA_ERR_NOMEM), %ld bytes "
           "printed\n", kNames[c], k - 1, failed, (long)printed);
    assert_int_equal(printed, 0);
#else
    (void)c, (void)prepare, (void)do_call, (void)kNames, (void)steps, (void)optional;
    printf("  allocation failures cannot be injected under the sanitizers: skipped\n");
#endif
}

static void init_sweep(void **state) { (void)state; sweep(INIT); }
static void init_index2_sweep(void **state) { (void)state; sweep(INIT_INDEX2); }
static void init_redundant_sweep(void **state) { (void)state; sweep(INIT_REDUNDANT); }
static void set_state_sweep(void **state) { (void)state; sweep(SET_STATE); }
static void formulation_sweep(void **state) { (void)state; sweep(FORMULATION); }
static void tangent_mode_sweep(void **state) { (void)state; sweep(TANGENT_MODE); }
static void output_sweep(void **state) { (void)state; sweep(OUTPUT); }
static void events_sweep(void **state) { (void)state; sweep(EVENTS); }
static void first_order_sweep(void **state) { (void)state; sweep(SET_FIRST_ORDER); }
static void init_y_sweep(void **state) { (void)state; sweep(INIT_Y); }
static void sensitivity_sweep(void **state) { (void)state; sweep(SET_SENSITIVITY); }
static void sensitivity_method_sweep(void **state) { (void)state; sweep(SENSITIVITY_METHOD); }
static void sensitivity_start_sweep(void **state) { (void)state; sweep(SENSITIVITY_START); }
static void init_sensitivity_sweep(void **state) { (void)state; sweep(INIT_SENSITIVITY); }
static void adjoint_checkpoints_sweep(void **state) { (void)state; sweep(ADJOINT_CHECKPOINTS); }
static void step_hook_sweep(void **state) { (void)state; sweep(STEP_HOOK); }
static void adjoint_gradient_sweep(void **state) { (void)state; sweep(ADJOINT_GRADIENT); }
static void events_y_sweep(void **state) { (void)state; sweep(EVENTS_Y); }
static void coupling_pattern_sweep(void **state) { (void)state; sweep(COUPLING_PATTERN); }
static void set_state_everything_sweep(void **state) { (void)state; sweep(SET_STATE_EVERYTHING); }

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(init_sweep),         cmocka_unit_test(init_index2_sweep),
        cmocka_unit_test(init_redundant_sweep),
        cmocka_unit_test(set_state_sweep),
        cmocka_unit_test(formulation_sweep),  cmocka_unit_test(tangent_mode_sweep),
        cmocka_unit_test(output_sweep),       cmocka_unit_test(events_sweep),
        cmocka_unit_test(first_order_sweep),  cmocka_unit_test(init_y_sweep),
        cmocka_unit_test(sensitivity_sweep),  cmocka_unit_test(sensitivity_method_sweep),
        cmocka_unit_test(sensitivity_start_sweep), cmocka_unit_test(init_sensitivity_sweep),
        cmocka_unit_test(adjoint_checkpoints_sweep),
        cmocka_unit_test(step_hook_sweep),
        cmocka_unit_test(adjoint_gradient_sweep),
        cmocka_unit_test(events_y_sweep),
        cmocka_unit_test(coupling_pattern_sweep),
        cmocka_unit_test(set_state_everything_sweep),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
