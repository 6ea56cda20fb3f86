/* No heap allocation inside ga_step after ga_init: every allocation in the process is counted
 * while ga_step runs (successful steps, steps with finite-difference tangents, and failing
 * steps). Without sanitizers, malloc and friends are interposed here; under AddressSanitizer,
 * its allocation hooks count instead. */
#define _GNU_SOURCE /* dladdr */
#include <dlfcn.h>
#include <execinfo.h>
#include <setjmp.h>
#include <stdarg.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"
#include "chain_solver.h"
#include "electromech.h"

static volatile int armed = 0;
static volatile long allocations = 0, blas_allocations = 0;

/* GA_LINEAR_DENSE_LAPACK calls the system's dgetrf/dgetrs, and some BLAS builds allocate in
 * every call (BLIS: about 100 a step of the 12-link chain; reference BLAS and OpenBLAS none):
 * an allocation whose call stack passes through the BLAS or LAPACK is theirs, counted apart,
 * and galpha's own must still be none. */
static int in_hook = 0;
static int from_the_blas(void)
{
    void *frames[24];
    const int depth = backtrace(frames, 24);
    for (int i = 1; i < depth; ++i) {
        Dl_info info;
        if (dladdr(frames[i], &info) && info.dli_fname) {
            const char *f = info.dli_fname;
            if (strstr(f, "libblas") || strstr(f, "liblapack") || strstr(f, "blis") ||
                strstr(f, "openblas"))
                return 1;
        }
    }
    return 0;
}
static void count(void)
{
    if (!armed || in_hook)
        return;
    in_hook = 1;
    if (from_the_blas())
        ++blas_allocations;
    else
        ++allocations;
    in_hook = 0;
}
/* backtrace loads its unwinder (and allocates) at its first call: before anything is armed */
static void warm_up(void)
{
    void *frames[4];
    (void)backtrace(frames, 4);
}

#if defined(__SANITIZE_ADDRESS__)
/* from <sanitizer/allocator_interface.h>, which GCC does not install */
int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void *, size_t),
                                              void (*free_hook)(const volatile void *));
static void on_malloc(const volatile void *p, size_t n)
{
    (void)p, (void)n;
    count();
}
static void on_free(const volatile void *p) { (void)p; }
static void install(void)
{
    warm_up();
    __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
}
#else
extern void *__libc_malloc(size_t);
extern void *__libc_calloc(size_t, size_t);
extern void *__libc_realloc(void *, size_t);
extern void *__libc_memalign(size_t, size_t);
extern void __libc_free(void *);
void *malloc(size_t n)
{
    count();
    return __libc_malloc(n);
}
void *calloc(size_t k, size_t n)
{
    count();
    return __libc_calloc(k, n);
}
void *realloc(void *p, size_t n)
{
    count();
    return __libc_realloc(p, n);
}
void *memalign(size_t a, size_t n)
{
    count();
    return __libc_memalign(a, n);
}
void *aligned_alloc(size_t a, size_t n) { return memalign(a, n); }
int posix_memalign(void **out, size_t a, size_t n)
{
    *out = memalign(a, n);
    return *out ? 0 : 12;
}
void free(void *p) { __libc_free(p); }
static void install(void) { warm_up(); }
#endif

static int fail_force = 0;
static int force_maybe_failing(double t, const double *q, const double *v, double *f, void *u)
{
    pendulum_force(t, q, v, f, u);
    return fail_force;
}

/* The step functions take fixed steps, or adaptive ones (ga_step_adaptive: one warm-up call
 * first, since the error projection's workspace is made at the first adaptive call). */
static ga_status take_step(ga_solver *s, int adaptive)
{
    return adaptive ? ga_step_adaptive(s, 1e3) : ga_step(s, 1e-3);
}

/* redundant: the constraint twice, the copy dropped (GA_REDUNDANT_DROP) */
static long count_step_allocations_in(ga_tangent_mode mode, int with_failures, int formulation,
                                      int adaptive, int redundant)
{
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2];
    ga_solver *s = NULL;
    pendulum_state(&p, 1.0, 0.5, q, v);
    assert_int_equal(ga_create(2, redundant ? 2 : 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, force_maybe_failing,
                                      redundant ? pendulum_twice_constraint : pendulum_constraint,
                                      redundant ? pendulum_twice_jacobian : pendulum_jacobian, &p),
                     GA_OK);
    if (redundant)
        assert_int_equal(ga_set_redundant_constraints(s, GA_REDUNDANT_DROP), GA_OK);
    assert_int_equal(ga_set_tangent_mode(s, mode), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    if (adaptive)
        assert_int_equal(take_step(s, adaptive), GA_OK);
    allocations = 0;
    armed = 1;
    long ok = 0;
    for (int i = 0; i < 200; ++i) {
        fail_force = with_failures && i % 7 == 3 ? (i % 2 ? -1 : 1) : 0;
        ok += take_step(s, adaptive) == GA_OK;
    }
    armed = 0;
    fail_force = 0;
    assert_true(ok >= (with_failures ? 170 : 200));
    ga_free(s);
    return allocations;
}

static long count_step_allocations(ga_tangent_mode mode, int with_failures)
{
    return count_step_allocations_in(mode, with_failures, GA_INDEX3, 0, 0);
}

static void counting_works(void **state)
{
    (void)state;
    allocations = 0;
    armed = 1;
    void *volatile p = malloc(16); /* the counter must see this one */
    armed = 0;
    free(p);
    assert_int_equal(allocations, 1);
    /* and it sees the library's own allocations (through operator new and Eigen) */
    pendulum pd = {1.0, 1.0, 9.81};
    double q[2] = {0.0, -1.0}, v[2] = {0.0, 0.0};
    ga_solver *s = NULL;
    allocations = 0;
    armed = 1;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &pd),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    armed = 0;
    printf("  allocations in ga_create + ga_init: %ld\n", allocations);
    assert_true(allocations > 10);
    ga_free(s);
}

static void no_allocation_in_step(void **state)
{
    (void)state;
    assert_int_equal(count_step_allocations(GA_TANGENT_AUTO, 0), 0);
    assert_int_equal(count_step_allocations(GA_TANGENT_FD, 0), 0);
    assert_int_equal(count_step_allocations(GA_TANGENT_NEGLECT, 0), 0);
    /* stabilized index 2, and adaptive steps (error estimate, controller, rejections) */
    assert_int_equal(count_step_allocations_in(GA_TANGENT_AUTO, 0, GA_INDEX2_STABILIZED, 0, 0), 0);
    assert_int_equal(count_step_allocations_in(GA_TANGENT_AUTO, 0, GA_INDEX3, 1, 0), 0);
    assert_int_equal(count_step_allocations_in(GA_TANGENT_AUTO, 0, GA_INDEX2_STABILIZED, 1, 0), 0);
}

/* A chain with declared patterns: the sparse path (KLU refactorization, grouped finite
 * differences) or a dense LU kernel forced (solver). */
static long count_chain_step_allocations(int links, int solver, int exact_tangent,
                                         int formulation, int adaptive)
{
    chain c = chain_make(links);
    const int n = 3 * c.links;
    double *q = malloc(sizeof(double) * n), *v = malloc(sizeof(double) * n);
    chain_initial(&c, q, v);
    ga_solver *s = chain_solver(&c, exact_tangent);
    assert_int_equal(ga_set_linear_solver(s, solver), GA_OK);
    assert_int_equal(ga_set_formulation(s, formulation), GA_OK);
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    if (adaptive)
        assert_int_equal(take_step(s, adaptive), GA_OK);
    allocations = 0;
    armed = 1;
    for (int i = 0; i < 30; ++i)
        assert_int_equal(take_step(s, adaptive), GA_OK);
    armed = 0;
    long long factorizations = 0;
    ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &factorizations);
    assert_true(factorizations > 1); /* refactorizations did happen inside ga_step */
    ga_free(s);
    free(q);
    free(v);
    return allocations;
}

static long count_sparse_step_allocations(int exact_tangent, int formulation, int adaptive)
{
    return count_chain_step_allocations(300, GA_LINEAR_SPARSE, exact_tangent, formulation,
                                        adaptive);
}

static void no_allocation_in_sparse_step(void **state)
{
    (void)state;
    assert_int_equal(count_sparse_step_allocations(1, GA_INDEX3, 0), 0);
    assert_int_equal(count_sparse_step_allocations(0, GA_INDEX3, 0), 0);
    assert_int_equal(count_sparse_step_allocations(1, GA_INDEX2_STABILIZED, 0), 0);
    assert_int_equal(count_sparse_step_allocations(1, GA_INDEX3, 1), 0);
    assert_int_equal(count_sparse_step_allocations(1, GA_INDEX2_STABILIZED, 1), 0);
}

/* The chain's forces, failing (recoverably) while chain_force_fails is set. */
static int chain_force_fails = 0;
static int chain_force_maybe_failing(double t, const double *q, const double *v, double *f,
                                     void *user)
{
    chain_force(t, q, v, f, user);
    return chain_force_fails;
}

/* New pivots on the sparse path: a restart (a checkpoint restored in its layout-2 form, which
 * carries no pivots) makes the next step choose them, with a full factorization (the path a
 * refactorization that comes out numerically singular takes too). The factors' storage is
 * reserved with the workspace, from the fill of the ordering, so that step allocates nothing
 * (new pivots would only if they filled more); nor do the steps after it, failed steps
 * (which keep the pivots) included, nor the first step of a new solver restored from the
 * checkpoint, in either layout. Index 3 and the stabilized index 2. */
static void no_sparse_allocation_after_a_restart(void **state)
{
    (void)state;
    for (int formulation = GA_INDEX3; formulation <= GA_INDEX2_STABILIZED; ++formulation) {
        chain c = chain_make(50);
        double q[150], v[150];
        chain_initial(&c, q, v);
        ga_solver *s =
            sparse_chain_solver(&c, chain_force_maybe_failing, chain_jacobian, formulation);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        for (int i = 0; i < 5; ++i)
            assert_int_equal(ga_step(s, 1e-3), GA_OK);
        size_t len = 0;
        assert_int_equal(ga_state_size(s, &len), GA_OK);
        double *ckpt = malloc(len * sizeof *ckpt);
        assert_non_null(ckpt);
        assert_int_equal(ga_get_state(s, ckpt, len), GA_OK);
        double *ckpt2 = malloc(len * sizeof *ckpt2);
        assert_non_null(ckpt2);
        const size_t len2 = ckpt_as_layout2(ckpt, ckpt2);
        assert_int_equal(ga_set_state(s, ckpt2, len2), GA_OK);
        long long full_before = 0, full_after = 0;
        ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &full_before);
        allocations = 0;
        armed = 1;
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
        armed = 0;
        ga_get_counter(s, GA_COUNT_FACTORIZATIONS, &full_after);
        const long first = allocations;
        allocations = 0;
        armed = 1;
        for (int i = 0; i < 20; ++i) {
            chain_force_fails = i % 5 == 2;
            assert_int_equal(ga_step(s, 1e-3),
                             chain_force_fails ? GA_ERR_CALLBACK_RETRY : GA_OK);
        }
        chain_force_fails = 0;
        armed = 0;
        printf("  sparse, %s: %ld allocations in the step after a restart (new pivots, %lld "
               "factorizations), %ld in the 20 after it (4 of them failing)\n",
               formulation == GA_INDEX3 ? "index 3" : "index 2", first,
               full_after - full_before, allocations);
        assert_true(full_after > full_before);  /* the step did factorize */
        assert_int_equal(first, 0);
        assert_int_equal(allocations, 0);
        /* a new solver restored from the checkpoint, in either layout */
        for (int layout = 2; layout <= 3; ++layout) {
            ga_solver *r = sparse_chain_solver(&c, chain_force, chain_jacobian, formulation);
            assert_int_equal(layout == 2 ? ga_set_state(r, ckpt2, len2)
                                         : ga_set_state(r, ckpt, len),
                             GA_OK);
            allocations = 0;
            armed = 1;
            assert_int_equal(ga_step(r, 1e-3), GA_OK);
            armed = 0;
            printf("  a new solver restored from it (layout %d): %ld allocations in its first "
                   "step\n", layout, allocations);
            assert_int_equal(allocations, 0);
            ga_free(r);
        }
        free(ckpt2);
        free(ckpt);
        ga_free(s);
    }
}

/* Every dense LU kernel, index 3 and 2, on a 12-link chain (60 unknowns: GA_LINEAR_DENSE
 * measures the fill of each matrix before it chooses). */
static void no_allocation_with_any_dense_kernel(void **state)
{
    (void)state;
    const int solvers[] = {GA_LINEAR_DENSE, GA_LINEAR_DENSE_UNBLOCKED, GA_LINEAR_DENSE_EIGEN,
                           GA_LINEAR_DENSE_LAPACK};
    for (size_t k = 0; k < sizeof solvers / sizeof solvers[0]; ++k) {
        blas_allocations = 0;
        assert_int_equal(count_chain_step_allocations(12, solvers[k], 1, GA_INDEX3, 0), 0);
        assert_int_equal(
            count_chain_step_allocations(12, solvers[k], 1, GA_INDEX2_STABILIZED, 0), 0);
        /* only the LAPACK kernel calls the BLAS */
        if (solvers[k] != GA_LINEAR_DENSE_LAPACK)
            assert_int_equal(blas_allocations, 0);
        else
            printf("  GA_LINEAR_DENSE_LAPACK: %ld allocations by this system's BLAS/LAPACK in "
                   "60 steps, none by galpha\n", blas_allocations);
    }
}

/* Redundant constraints dropped (GA_REDUNDANT_DROP): the pendulum's constraint twice. */
static void no_allocation_with_dropped_constraints(void **state)
{
    (void)state;
    assert_int_equal(count_step_allocations_in(GA_TANGENT_AUTO, 0, GA_INDEX3, 0, 1), 0);
    assert_int_equal(count_step_allocations_in(GA_TANGENT_AUTO, 0, GA_INDEX2_STABILIZED, 0, 1),
                     0);
}

static void no_allocation_in_failing_step(void **state)
{
    (void)state;
    assert_int_equal(count_step_allocations(GA_TANGENT_AUTO, 1), 0);
}

/* Options that call for finite-difference tangents changed after ga_init (the setter builds
 * what they need, not the next step): exact K_t first, then differences (GA_TANGENT_FD), then
 * a mass matrix no longer constant, then no tangent callback at all. Sparse (chain) and dense
 * (pendulum). */
static long steps_after_option_changes(ga_solver *s, double h)
{
    long total = 0;
    for (int change = 0; change < 3; ++change) {
        if (change == 0)
            assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
        if (change == 1)
            assert_int_equal(ga_set_constant_mass(s, 0), GA_OK);
        if (change == 2) {
            assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_AUTO), GA_OK);
            assert_int_equal(ga_set_tangents(s, NULL, NULL), GA_OK);
        }
        long long before = 0, after = 0;
        ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &before);
        allocations = 0;
        armed = 1;
        for (int i = 0; i < 10; ++i)
            assert_int_equal(ga_step(s, h), GA_OK);
        armed = 0;
        total += allocations;
        ga_get_counter(s, GA_COUNT_STIFFNESS_EVALS, &after);
        if (change < 2)
            assert_true(after > before); /* the differences were computed in these steps */
    }
    return total;
}

/* Events located in steps (x at the vertical, lambda crossing a level, with multipliers; a
 * fast sine, terminal), and event calls failing now and then: fixed steps, adaptive ones and
 * ga_advance, none allocates. */
static int event_failure = 0;
static int watch(double t, const double *q, const double *v, const double *lambda, double *g,
                 void *user)
{
    (void)t, (void)v, (void)user;
    g[0] = q[0];
    g[1] = lambda[0] - 9.0;
    g[2] = sin(200.0 * t); /* many roots */
    return event_failure;
}

static void no_allocation_with_events(void **state)
{
    (void)state;
    for (int mode = 0; mode < 3; ++mode) {
        pendulum p = {1.0, 1.0, 9.81};
        double q[2], v[2];
        ga_solver *s = NULL;
        pendulum_state(&p, 1.5, 0.0, q, v);
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                          pendulum_jacobian, &p),
                         GA_OK);
        const int terminal[3] = {0, 0, 1};
        assert_int_equal(ga_set_events(s, 3, watch, NULL, terminal, 1), GA_OK);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        if (mode > 0)
            assert_true(ga_step_adaptive(s, 1e3) >= GA_OK);
        allocations = 0;
        armed = 1;
        long events = 0, failed = 0;
        for (int i = 0; i < 300; ++i) {
            event_failure = i % 11 == 5 ? (i % 2 ? -1 : 1) : 0;
            const ga_status st = mode == 0 ? ga_step(s, 3e-3)
                                 : mode == 1 ? ga_step_adaptive(s, 1e3)
                                             : ga_advance(s, 0.01 * (i + 1));
            events += st == GA_EVENT;
            failed += st < GA_OK;
        }
        armed = 0;
        event_failure = 0;
        printf("  mode %d: %ld stops at events, %ld failed calls, %ld allocations\n", mode,
               events, failed, allocations);
        assert_true(events > 0 && failed > 0);
        assert_int_equal(allocations, 0);
        ga_free(s);
    }
}

/* The step hook with multipliers, reading the solver (dense output) and stopping now and then;
 * with events and failing steps, fixed and adaptive, both formulations. */
static long hook_calls;
static int reading_hook(const ga_solver *s, double t, const double *q, const double *v,
                        const double *lambda, void *user)
{
    (void)q, (void)v, (void)lambda, (void)user;
    double h, qi[2], vi[2], li;
    if (ga_get_h_last(s, &h) != GA_OK || ga_interpolate(s, t - 0.5 * h, qi, vi, &li) != GA_OK)
        return -1;
    return ++hook_calls % 7 == 0;
}

static void no_allocation_with_step_hook(void **state)
{
    (void)state;
    for (int mode = 0; mode < 6; ++mode) {
        pendulum p = {1.0, 1.0, 9.81};
        double q[2], v[2];
        ga_solver *s = NULL;
        pendulum_state(&p, 1.5, 0.0, q, v);
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, pendulum_mass, force_maybe_failing,
                                          pendulum_constraint, pendulum_jacobian, &p),
                         GA_OK);
        if (mode >= 3)
            assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
        const int terminal[3] = {0, 0, 1};
        assert_int_equal(ga_set_events(s, 3, watch, NULL, terminal, 1), GA_OK);
        assert_int_equal(ga_set_step_hook(s, reading_hook, NULL, 1), GA_OK);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        if (mode % 3 > 0)
            assert_true(ga_step_adaptive(s, 1e3) >= GA_OK);
        allocations = 0;
        hook_calls = 0;
        armed = 1;
        long stops = 0, failed = 0;
        for (int i = 0; i < 300; ++i) {
            fail_force = i % 13 == 6 ? (i % 2 ? -1 : 1) : 0;
            const ga_status st = mode % 3 == 0 ? ga_step(s, 3e-3)
                                 : mode % 3 == 1 ? ga_step_adaptive(s, 1e3)
                                                 : ga_advance(s, 0.01 * (i + 1));
            stops += st == GA_STOPPED;
            failed += st < GA_OK;
        }
        armed = 0;
        fail_force = 0;
        printf("  mode %d: %ld hook calls, %ld stops, %ld failed calls, %ld allocations\n",
               mode, hook_calls, stops, failed, allocations);
        assert_true(stops > 0 && failed > 0);
        assert_int_equal(allocations, 0);
        ga_free(s);
    }
}

/* First-order states: coupling blocks by differences and by callback, both formulations, fixed
 * and adaptive steps, dense and sparse, rate callbacks that fail now and then; with forward
 * sensitivities. */
static int rate_failure;
static int sometimes_failing_rate(double t, const double *q, const double *v, const double *y,
                                  double *ydot, void *u)
{
    return rate_failure ? rate_failure : em_rate(t, q, v, y, ydot, u);
}

static void no_allocation_with_first_order_states(void **state)
{
    (void)state;
    for (int variant = 0; variant < 12; ++variant) {  /* 6 ... 11: with sensitivities */
        const int mode = variant % 6, sensitivities = variant >= 6;
        ga_solver *s = NULL;
        const int sparse = mode >= 4; /* modes 4, 5: the sparse path */
        assert_int_equal(ga_create(EM_N, EM_M, &s), GA_OK);
        if (sparse)
            assert_int_equal(em_declare_sparse(s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, sparse ? em_mass_diag : em_mass, NULL, em_constraint,
                                          sparse ? em_jacobian_values : em_jacobian, NULL),
                         GA_OK);
        assert_int_equal(ga_set_first_order(s, EM_R, em_force, sometimes_failing_rate), GA_OK);
        static double unread[1] = {1.0}; /* sensitivities in a parameter nothing reads */
        if (sensitivities)
            assert_int_equal(ga_set_sensitivity(s, 1, unread, NULL,
                                                GA_DEPENDS_FORCE | GA_DEPENDS_RATE),
                             GA_OK);
        if (sensitivities) /* and the adjoint's record (its y and y' too) */
            assert_int_equal(ga_set_sensitivity_method(
                                 s, GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT, 2000),
                             GA_OK);
        if (mode & 1)
            assert_int_equal(ga_set_coupling(s, em_coupling), GA_OK);
        if (mode >= 2)
            assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
        assert_int_equal(ga_set_tangent_mode(s, GA_TANGENT_FD), GA_OK);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        const double q0[EM_N] = {0, 0}, v0[EM_N] = {0, 0}, y0[EM_R] = {0, 0};
        assert_int_equal(ga_init_y(s, 0.0, q0, v0, y0), GA_OK);
        assert_int_equal(ga_step(s, 1e-3), GA_OK);
        if (mode >= 2)
            assert_int_equal(ga_step_adaptive(s, 1e3), GA_OK);
        allocations = 0;
        armed = 1;
        long failed = 0;
        for (int i = 0; i < 200; ++i) {
            rate_failure = i % 13 == 7 ? (i % 2 ? -1 : 1) : 0;
            const ga_status st = mode < 2 ? ga_step(s, 1e-3) : ga_step_adaptive(s, 1e3);
            failed += st < GA_OK;
        }
        armed = 0;
        rate_failure = 0;
        printf("  mode %d%s: %ld failed calls, %ld allocations\n", mode,
               sensitivities ? " with sensitivities" : "", failed, allocations);
        assert_true(failed > 0);
        assert_int_equal(allocations, 0);
        ga_free(s);
    }
}

/* Forward sensitivities: the pendulum's mass and length as parameters (they enter M, f and
 * Phi: differences of each), index 3 and 2, fixed and adaptive steps, forces that fail now and then (the step and
 * its sensitivities are dropped); the chain on the sparse path (its link length, mass,
 * inertia and gravity); the adjoint record, with and
 * without forward sensitivities. */
static void no_allocation_with_sensitivities(void **state)
{
    (void)state;
    for (int mode = 0; mode < 9; ++mode) { /* 6, 7: the adjoint record, with and without */
        const int adaptive = mode & 1, index2 = (mode >> 1) & 1, sparse = mode == 4 || mode == 5;
        const int record = mode >= 6; /* 8: the record with checkpoints, fixed steps */
        pendulum p = {1.0, 1.0, 9.81};
        chain c = chain_make(8);
        const int n = sparse ? 24 : 2, m = sparse ? 16 : 1;
        double q[24], v[24];
        ga_solver *s = NULL;
        assert_int_equal(ga_create(n, m, &s), GA_OK);
        if (sparse) {
            chain_initial(&c, q, v);
            assert_int_equal(ga_set_callbacks(s, chain_mass, chain_force, chain_constraint,
                                              chain_jacobian, &c),
                             GA_OK);
            assert_int_equal(chain_declare_patterns(&c, s), GA_OK);
            assert_int_equal(ga_set_sensitivity(s, 4, &c.length, NULL,
                                                GA_DEPENDS_FORCE | GA_DEPENDS_MASS |
                                                    GA_DEPENDS_CONSTRAINT),
                             GA_OK);
        } else {
            pendulum_state(&p, 1.0, 0.5, q, v);
            assert_int_equal(ga_set_callbacks(s, pendulum_mass, force_maybe_failing,
                                              pendulum_constraint, pendulum_jacobian, &p),
                             GA_OK);
            assert_int_equal(ga_set_sensitivity(s, 2, &p.mass, NULL,
                                                GA_DEPENDS_FORCE | GA_DEPENDS_MASS |
                                                    GA_DEPENDS_CONSTRAINT),
                             GA_OK);
        }
        if (record)
            assert_int_equal(ga_set_sensitivity_method(
                                 s, (mode == 6 ? GA_SENSITIVITY_FORWARD : 0) |
                                        GA_SENSITIVITY_ADJOINT, 1000),
                             GA_OK);
        if (mode == 8)
            assert_int_equal(ga_set_adjoint_checkpoints(s, 16, 40), GA_OK);
        assert_int_equal(ga_set_formulation(s, index2 ? GA_INDEX2_STABILIZED : GA_INDEX3),
                         GA_OK);
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        assert_int_equal(take_step(s, adaptive), GA_OK);
        allocations = 0;
        armed = 1;
        long failed = 0;
        for (int i = 0; i < 200; ++i) {
            fail_force = !sparse && i % 7 == 3 ? (i % 2 ? -1 : 1) : 0;
            failed += take_step(s, adaptive) < GA_OK;
        }
        armed = 0;
        fail_force = 0;
        printf("  mode %d: %ld failed calls, %ld allocations\n", mode, failed, allocations);
        assert_true(sparse || failed > 0);
        assert_int_equal(allocations, 0);
        ga_free(s);
    }
}

static void no_allocation_after_tangent_options_change(void **state)
{
    (void)state;
    chain c = chain_make(50);
    double q[150], v[150];
    chain_initial(&c, q, v);
    ga_solver *s = chain_solver(&c, 1);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(steps_after_option_changes(s, 1e-3), 0);
    ga_free(s);

    pendulum p = {1.0, 1.0, 9.81};
    pendulum_state(&p, 1.0, 0.5, q, v);
    s = pendulum_new_solver(&p, 1);
    assert_non_null(s);
    assert_int_equal(ga_set_constant_mass(s, 1), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(steps_after_option_changes(s, 1e-2), 0);
    ga_free(s);
}

int main(void)
{
    install();
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(counting_works),
        cmocka_unit_test(no_allocation_in_step),
        cmocka_unit_test(no_allocation_in_failing_step),
        cmocka_unit_test(no_allocation_in_sparse_step),
        cmocka_unit_test(no_sparse_allocation_after_a_restart),
        cmocka_unit_test(no_allocation_with_dropped_constraints),
        cmocka_unit_test(no_allocation_with_any_dense_kernel),
        cmocka_unit_test(no_allocation_after_tangent_options_change),
        cmocka_unit_test(no_allocation_with_events),
        cmocka_unit_test(no_allocation_with_step_hook),
        cmocka_unit_test(no_allocation_with_first_order_states),
        cmocka_unit_test(no_allocation_with_sensitivities),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
