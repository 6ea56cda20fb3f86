/* Every error path: bad arguments, calls out of order, callback failures (fatal and
 * recoverable), NaN/Inf, singular matrices, Newton failure, inconsistent initial values,
 * out of memory, and re-entrant calls. Each must return its specific status with a readable
 * message, and a failed ga_step must leave the solver bit-identical to its last accepted
 * state, so that the run can go on as if the failure had not happened. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"

/* The pendulum with switchable faults. */
typedef enum fault_site {
    NONE,
    MASS,
    FORCE,
    CONSTRAINT,
    JACOBIAN,
    STIFFNESS,
    DAMPING,
    CONSTRAINT_DT
} fault_site;
typedef struct faulty {
    pendulum p;
    fault_site site;
    int rc;          /* return code to inject (0: inject a value instead) */
    double value;    /* value written into the output when rc == 0 */
    int zero_jacobian;
    int zero_jacobian_from; /* > 0: Phi_q = 0 from this Jacobian call on (jacobian_calls) */
    int jacobian_calls;
    ga_solver *self; /* for the re-entrancy test */
    ga_status reentry_status;
    int reentry_calls;
} faulty;

static int inject(faulty *f, fault_site site, double *out)
{
    if (f->site != site)
        return 0;
    if (f->rc != 0)
        return f->rc;
    out[0] = f->value;
    return 0;
}

static int f_mass(double t, const double *q, double *M, void *u)
{
    faulty *f = u;
    pendulum_mass(t, q, M, &f->p);
    if (f->self) { /* calls back into its own solver: must be refused */
        double tt;
        f->reentry_status = ga_get_t(f->self, &tt);
        if (f->reentry_status == GA_ERR_STATE)
            f->reentry_status = ga_step(f->self, 0.1);
        /* told why, inside the callback */
        if (!strstr(ga_last_error(f->self), "call refused: another call holds this solver"))
            f->reentry_status = GA_ERR_INTERNAL;
        ++f->reentry_calls;
    }
    return inject(f, MASS, M);
}
static int f_force(double t, const double *q, const double *v, double *out, void *u)
{
    faulty *f = u;
    pendulum_force(t, q, v, out, &f->p);
    return inject(f, FORCE, out);
}
static int f_constraint(double t, const double *q, double *phi, void *u)
{
    faulty *f = u;
    pendulum_constraint(t, q, phi, &f->p);
    return inject(f, CONSTRAINT, phi);
}
static int f_jacobian(double t, const double *q, double *J, void *u)
{
    faulty *f = u;
    pendulum_jacobian(t, q, J, &f->p);
    ++f->jacobian_calls;
    if (f->zero_jacobian || (f->zero_jacobian_from > 0 && f->jacobian_calls >= f->zero_jacobian_from))
        J[0] = J[1] = 0.0;
    return inject(f, JACOBIAN, J);
}
static int f_stiffness(double t, const double *q, const double *v, const double *qdd,
                       const double *lambda, double *K, void *u)
{
    faulty *f = u;
    pendulum_stiffness(t, q, v, qdd, lambda, K, &f->p);
    return inject(f, STIFFNESS, K);
}

/* C_t of the pendulum: its force does not depend on v */
static int f_damping(double t, const double *q, const double *v, double *C, void *u)
{
    (void)t, (void)q, (void)v;
    for (int i = 0; i < 4; ++i)
        C[i] = 0.0;
    return inject(u, DAMPING, C);
}

/* Phi_t of the pendulum: its constraint does not depend on t */
static int f_constraint_dt(double t, const double *q, double *out, void *u)
{
    (void)t, (void)q;
    out[0] = 0.0;
    return inject(u, CONSTRAINT_DT, out);
}

typedef struct fixture {
    faulty model;
    ga_solver *s;
} fixture;

/* The fixture's solver: the pendulum after ten steps of 0.01 (NULL on failure). */
static ga_solver *pendulum_after_ten_steps(faulty *model)
{
    ga_solver *s = NULL;
    double q[2], v[2];
    if (ga_create(2, 1, &s) != GA_OK)
        return NULL;
    pendulum_state(&model->p, 1.0, 0.5, q, v);
    int st = ga_set_callbacks(s, f_mass, f_force, f_constraint, f_jacobian, model) ||
             ga_set_tangents(s, f_stiffness, f_damping) || ga_init(s, 0.0, q, v);
    for (int i = 0; i < 10 && !st; ++i)
        st = ga_step(s, 0.01);
    if (st) {
        ga_free(s);
        return NULL;
    }
    return s;
}

static int setup(void **state)
{
    fixture *x = calloc(1, sizeof *x);
    if (!x)
        return -1;
    x->model.p = (pendulum){1.0, 1.0, 9.81};
    x->s = pendulum_after_ten_steps(&x->model);
    if (!x->s)
        return -1;
    *state = x;
    return 0;
}

static int teardown(void **state)
{
    fixture *x = *state;
    ga_free(x->s);
    free(x);
    return 0;
}

enum { STATE_MAX = 256 };
static size_t snapshot(ga_solver *s, double *buf)
{
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    assert_true(len <= STATE_MAX);
    assert_int_equal(ga_get_state(s, buf, len), GA_OK);
    return len;
}

static void expect_message(ga_solver *s, const char *part)
{
    if (!strstr(ga_last_error(s), part))
        fail_msg("message '%s' does not contain '%s'", ga_last_error(s), part);
}

static void continues_undisturbed(fixture *x, double *before, size_t len);

/* Run a failing step; check status, message, bit-identical state, then clear the fault and
 * check that the run continues exactly like an undisturbed solver. */
static void failing_step(fixture *x, ga_status expected, const char *part)
{
    double before[STATE_MAX], after[STATE_MAX];
    const size_t len = snapshot(x->s, before);
    assert_int_equal(ga_step(x->s, 0.01), expected);
    expect_message(x->s, part);
    snapshot(x->s, after);
    assert_true(ckpt_same_state(before, after));

    /* recovery: the same step again, without the fault, equals the undisturbed run */
    x->model.site = NONE;
    x->model.zero_jacobian = 0;
    x->model.zero_jacobian_from = 0;
    continues_undisturbed(x, before, len);
}

/* The next step of x->s equals that of a fresh solver restarted from the checkpoint `before`
 * (default options, the fixture's callbacks; as a restart, layout 2, since a failed step
 * drops its matrix): nothing x->s went through since left a trace. */
static void continues_undisturbed(fixture *x, double *before, size_t len)
{
    double after[STATE_MAX], restart[STATE_MAX];
    ga_solver *ref = NULL;
    assert_int_equal(ga_create(2, 1, &ref), GA_OK);
    assert_int_equal(ga_set_callbacks(ref, f_mass, f_force, f_constraint, f_jacobian, &x->model),
                     GA_OK);
    assert_int_equal(ga_set_tangents(ref, f_stiffness, f_damping), GA_OK);
    assert_int_equal(ga_set_state(ref, restart, ckpt_as_layout2(before, restart)), GA_OK);
    assert_int_equal(ga_step(x->s, 0.01), GA_OK);
    assert_int_equal(ga_step(ref, 0.01), GA_OK);
    snapshot(x->s, after);
    snapshot(ref, before);
    assert_memory_equal(before, after, len * sizeof(double));
    ga_free(ref);
}

/* ---- arguments and order of calls ------------------------------------------------------- */

static void create_rejects_bad_sizes(void **state)
{
    (void)state;
    ga_solver *s = (ga_solver *)0x1;
    assert_int_equal(ga_create(2, 1, NULL), GA_ERR_ARG);
    assert_int_equal(ga_create(0, 0, &s), GA_ERR_ARG);
    assert_null(s);
    assert_int_equal(ga_create(-3, 0, &s), GA_ERR_ARG);
    assert_int_equal(ga_create(2, -1, &s), GA_ERR_ARG);
    assert_int_equal(ga_create(2, 3, &s), GA_ERR_ARG);
    assert_int_equal(ga_create(INT_MAX, INT_MAX, &s), GA_ERR_ARG);
    assert_null(s);
    ga_free(NULL); /* no-op */
}

static void null_pointers_are_refused(void **state)
{
    fixture *x = *state;
    double d;
    long long c;
    int n, m;
    size_t len;
    assert_int_equal(ga_step(NULL, 0.1), GA_ERR_ARG);
    assert_int_equal(ga_init(NULL, 0.0, &d, &d), GA_ERR_ARG);
    assert_int_equal(ga_set_rho_inf(NULL, 0.5), GA_ERR_ARG);
    assert_int_equal(ga_get_t(NULL, &d), GA_ERR_ARG);
    assert_int_equal(ga_set_pattern_csc(NULL, GA_MATRIX_MASS, NULL, NULL), GA_ERR_ARG);
    /* each read that fails says which call and which argument, in place of the message an
     * earlier failure left (issue 17) */
    assert_int_equal(ga_step(x->s, -1.0), GA_ERR_ARG);
    assert_int_equal(ga_get_t(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_t: t is NULL");
    assert_int_equal(ga_get_q(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_q: q is NULL");
    assert_int_equal(ga_get_v(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_v: v is NULL");
    assert_int_equal(ga_get_qdd(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_qdd: qdd is NULL");
    assert_int_equal(ga_get_lambda(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_lambda: lambda is NULL");
    assert_int_equal(ga_get_a(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_a: a is NULL");
    assert_int_equal(ga_get_h_last(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_h_last: h is NULL");
    assert_int_equal(ga_get_counter(x->s, GA_COUNT_STEPS, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_counter: value is NULL or the key is unknown");
    assert_int_equal(ga_get_counter(x->s, 99, &c), GA_ERR_ARG);
    assert_int_equal(ga_get_counter(x->s, -1, &c), GA_ERR_ARG);
    assert_int_equal(ga_get_active_constraints(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_get_active_constraints: active is NULL");
    assert_int_equal(ga_get_size(x->s, NULL, &m), GA_ERR_ARG);
    expect_message(x->s, "ga_get_size: n or m is NULL");
    assert_int_equal(ga_get_size(x->s, &n, &m), GA_OK);
    expect_message(x->s, "ga_get_size: n or m is NULL"); /* a read that succeeds keeps it */
    assert_int_equal(ga_state_size(x->s, NULL), GA_ERR_ARG);
    expect_message(x->s, "ga_state_size: len is NULL");
    assert_int_equal(ga_state_size(x->s, &len), GA_OK);
    assert_int_equal(ga_get_state(x->s, NULL, len), GA_ERR_ARG);
    expect_message(x->s, "ga_get_state: buf is NULL or shorter than ga_state_size");
    assert_int_equal(ga_set_state(x->s, NULL, len), GA_ERR_ARG);
    assert_int_equal(ga_init(x->s, 0.0, NULL, &d), GA_ERR_ARG);
    assert_string_equal(ga_last_error(NULL), "NULL solver");
}

static void bad_step_sizes_are_refused(void **state)
{
    fixture *x = *state;
    double before[STATE_MAX], after[STATE_MAX];
    const size_t len = snapshot(x->s, before);
    const double bad[] = {0.0, -0.01, NAN, INFINITY, -INFINITY, 1e-30};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        assert_int_equal(ga_step(x->s, bad[i]), GA_ERR_ARG);
        expect_message(x->s, "step size h");
    }
    snapshot(x->s, after);
    assert_memory_equal(before, after, len * sizeof(double));
}

static void calls_out_of_order_are_refused(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    double q[2] = {0.0, -1.0}, v[2] = {0.0, 0.0}, t, buf[STATE_MAX];
    pendulum p = {1.0, 1.0, 9.81};
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_ERR_STATE);
    expect_message(s, "before ga_init");
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_STATE);
    expect_message(s, "before ga_set_callbacks");
    assert_int_equal(ga_get_t(s, &t), GA_ERR_STATE);
    expect_message(s, "ga_get_t before ga_init or ga_set_state");
    assert_int_equal(ga_get_q(s, q), GA_ERR_STATE);
    expect_message(s, "ga_get_q before ga_init");
    assert_int_equal(ga_get_qdd(s, q), GA_ERR_STATE);
    expect_message(s, "ga_get_qdd before ga_init");
    assert_int_equal(ga_get_lambda(s, q), GA_ERR_STATE);
    expect_message(s, "ga_get_lambda before ga_init");
    assert_int_equal(ga_get_state(s, buf, STATE_MAX), GA_ERR_STATE);
    expect_message(s, "ga_get_state before ga_init");
    buf[0] = 26465.0; /* a well-formed checkpoint still needs callbacks */
    buf[1] = 2.0;
    buf[2] = 2.0;
    buf[3] = 1.0;
    for (int i = 4; i < 9 + 5 * 2 + 1; ++i)
        buf[i] = 0.0;
    assert_int_equal(ga_set_state(s, buf, 9 + 5 * 2 + 1), GA_ERR_STATE);
    /* callbacks: mass required, constraint + jacobian required for m > 0 */
    assert_int_equal(ga_set_callbacks(s, NULL, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &p),
                     GA_ERR_ARG);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, NULL, pendulum_jacobian,
                                      &p),
                     GA_ERR_ARG);
    expect_message(s, "constraint and jacobian callbacks are required");
    ga_free(s);
}

/* Every refused option names what was wrong and changes nothing: the solver's next steps are
 * those of a twin that was never asked. */
static void bad_options_are_refused(void **state)
{
    fixture *x = *state;
    double d = 0.0;
    int rows[1] = {0};
    ga_solver *twin = pendulum_after_ten_steps(&x->model);
    assert_non_null(twin);
    assert_int_equal(ga_set_newton(x->s, 0.0, 10), GA_ERR_ARG);
    assert_int_equal(ga_set_newton(x->s, 1.0, 10), GA_ERR_ARG);
    assert_int_equal(ga_set_newton(x->s, NAN, 10), GA_ERR_ARG);
    assert_int_equal(ga_set_newton(x->s, 1e-8, 0), GA_ERR_ARG);
    assert_int_equal(ga_set_scaling(x->s, 2), GA_ERR_ARG);
    assert_int_equal(ga_set_tangent_mode(x->s, 7), GA_ERR_ARG);
    assert_int_equal(ga_set_predictor(x->s, 7), GA_ERR_ARG);
    assert_int_equal(ga_set_init_mode(x->s, 7, 1e-10), GA_ERR_ARG);
    assert_int_equal(ga_set_init_mode(x->s, GA_INIT_PROJECT, 0.0), GA_ERR_ARG);
    assert_int_equal(ga_set_init_mode(x->s, GA_INIT_PROJECT, INFINITY), GA_ERR_ARG);
    assert_int_equal(ga_set_jacobian_reuse(x->s, 7), GA_ERR_ARG);
    expect_message(x->s, "unknown reuse mode 7");
    assert_int_equal(ga_set_constant_mass(x->s, 2), GA_ERR_ARG);
    expect_message(x->s, "constant mass must be 0 or 1, got 2");
    assert_int_equal(ga_set_formulation(x->s, 2), GA_ERR_ARG);
    expect_message(x->s, "unknown formulation 2");
    assert_int_equal(ga_set_rescale(x->s, 2), GA_ERR_ARG);
    expect_message(x->s, "rescale must be 0 or 1, got 2");
    assert_int_equal(ga_set_corrected_start(x->s, -1), GA_ERR_ARG);
    expect_message(x->s, "corrected start must be 0 or 1, got -1");
    assert_int_equal(ga_set_rho_inf(x->s, 1.5), GA_ERR_ARG);
    assert_int_equal(ga_set_rho_inf(x->s, NAN), GA_ERR_ARG);
    assert_int_equal(ga_set_tolerances(x->s, 0.0, 1e-6), GA_ERR_ARG);
    assert_int_equal(ga_set_tolerances(x->s, 1e-6, INFINITY), GA_ERR_ARG);
    assert_int_equal(ga_set_tolerances(x->s, NAN, 1e-6), GA_ERR_ARG);
    expect_message(x->s, "must be positive and finite");
    assert_int_equal(ga_set_initial_step(x->s, -1e-3), GA_ERR_ARG);
    assert_int_equal(ga_set_initial_step(x->s, NAN), GA_ERR_ARG);
    expect_message(x->s, "initial step");
    assert_int_equal(ga_set_step_limits(x->s, -1.0, 0.0), GA_ERR_ARG);
    assert_int_equal(ga_set_step_limits(x->s, 0.0, NAN), GA_ERR_ARG);
    assert_int_equal(ga_set_linear_solver(x->s, 99), GA_ERR_ARG);
    expect_message(x->s, "unknown linear solver 99");
    /* choices the workspace was built for are refused after ga_init */
    assert_int_equal(ga_set_linear_solver(x->s, GA_LINEAR_DENSE_EIGEN), GA_ERR_STATE);
    expect_message(x->s, "chosen before ga_init");
    assert_int_equal(ga_set_pattern(x->s, GA_MATRIX_MASS, 1, rows, rows), GA_ERR_STATE);
    expect_message(x->s, "declared before ga_init");
    const int colptr[3] = {0, 1, 1};
    assert_int_equal(ga_set_pattern_csc(x->s, GA_MATRIX_MASS, colptr, rows), GA_ERR_STATE);
    expect_message(x->s, "declared before ga_init");
    /* queries with a bad key or no output */
    assert_int_equal(ga_get_info(x->s, GA_INFO_COUNT, &d), GA_ERR_ARG);
    expect_message(x->s, "unknown key");
    assert_int_equal(ga_get_info(x->s, -1, &d), GA_ERR_ARG);
    assert_int_equal(ga_get_info(x->s, GA_INFO_H_NEXT, NULL), GA_ERR_ARG);
    expect_message(x->s, "value is NULL");
    assert_int_equal(ga_set_jacobian_reuse(NULL, GA_REUSE_AUTO), GA_ERR_ARG);
    assert_int_equal(ga_reset_counters(NULL), GA_ERR_ARG);
    assert_string_equal(ga_linear_solver_name(NULL), "none");

    double a[STATE_MAX], b[STATE_MAX];
    for (int k = 0; k < 5; ++k) {
        assert_int_equal(ga_step(x->s, 0.01), GA_OK);
        assert_int_equal(ga_step(twin, 0.01), GA_OK);
    }
    const size_t len = snapshot(x->s, a);
    snapshot(twin, b);
    assert_memory_equal(a, b, len * sizeof(double));
    ga_free(twin);
}

static void bad_patterns_are_refused(void **state)
{
    (void)state;
    ga_solver *s = NULL, *u = NULL;
    const int r[2] = {0, 1}, c[2] = {0, 1}, c_out[2] = {0, 2}, r_neg[2] = {0, -1};
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_pattern(s, 7, 2, r, c), GA_ERR_ARG);
    expect_message(s, "unknown matrix 7");
    assert_int_equal(ga_set_pattern(s, -1, 2, r, c), GA_ERR_ARG);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 2, NULL, c), GA_ERR_ARG);
    expect_message(s, "needs rows and cols");
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 2, r, NULL), GA_ERR_ARG);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, -1, r, c), GA_ERR_ARG);
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_MASS, 2, r, c_out), GA_ERR_ARG);
    expect_message(s, "pattern entry 1 = (1, 2) is outside the 2 x 2 matrix");
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_STIFFNESS, 2, r_neg, c), GA_ERR_ARG);
    /* Phi_q has m = 1 row: row 1 is outside */
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, 2, r, c), GA_ERR_ARG);
    expect_message(s, "outside the 1 x 2 matrix");
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, 2, c, r), GA_ERR_ARG);
    /* the same checks in compressed-column form, and its own */
    const int ptr_ok[3] = {0, 1, 2}, ptr_base1[3] = {1, 2, 3}, ptr_down[3] = {0, 2, 1};
    const int ptr_jac[3] = {0, 1, 2};
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_MASS, NULL, r), GA_ERR_ARG);
    expect_message(s, "needs colptr");
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_MASS, ptr_base1, r), GA_ERR_ARG);
    expect_message(s, "colptr[0] = 1, not 0");
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_MASS, ptr_down, r), GA_ERR_ARG);
    expect_message(s, "colptr decreases at column 1 (2 -> 1)");
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_MASS, ptr_ok, NULL), GA_ERR_ARG);
    expect_message(s, "needs rows and cols");
    assert_int_equal(ga_set_pattern_csc(s, 9, ptr_ok, r), GA_ERR_ARG);
    expect_message(s, "unknown matrix 9");
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_STIFFNESS, ptr_ok, r_neg), GA_ERR_ARG);
    expect_message(s, "pattern entry 1 = (-1, 1) is outside the 2 x 2 matrix");
    assert_int_equal(ga_set_pattern_csc(s, GA_MATRIX_JACOBIAN, ptr_jac, r), GA_ERR_ARG);
    expect_message(s, "pattern entry 1 = (1, 1) is outside the 1 x 2 matrix");
    assert_int_equal(ga_set_pattern(s, GA_MATRIX_JACOBIAN, 1, r, c), GA_OK);
    /* the sparse solver asked for without the pattern of M (K_t and C_t by differences need
     * theirs too) */
    pendulum p = {1.0, 1.0, 9.81};
    double q[2] = {0.0, -1.0}, v[2] = {0.0, 0.0};
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &p),
                     GA_OK);
    assert_int_equal(ga_set_linear_solver(s, GA_LINEAR_SPARSE), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_ARG);
    expect_message(s, "the sparse solver needs the patterns of M and Phi_q");
    /* without constraints there is no Jacobian to declare */
    assert_int_equal(ga_create(2, 0, &u), GA_OK);
    assert_int_equal(ga_set_pattern(u, GA_MATRIX_JACOBIAN, 1, r, c), GA_ERR_ARG);
    expect_message(u, "m = 0: there is no constraint Jacobian");
    ga_free(u);
    ga_free(s);
}

/* Adaptive calls: before ga_init, and with end times that are not finite or lie behind. */
static void bad_adaptive_calls_are_refused(void **state)
{
    fixture *x = *state;
    ga_solver *s = NULL;
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_step_adaptive(s, 1.0), GA_ERR_STATE);
    expect_message(s, "ga_step_adaptive before ga_init");
    assert_int_equal(ga_advance(s, 1.0), GA_ERR_STATE);
    expect_message(s, "ga_advance before ga_init");
    ga_free(s);

    double before[STATE_MAX], after[STATE_MAX], t;
    const size_t len = snapshot(x->s, before);
    assert_int_equal(ga_get_t(x->s, &t), GA_OK);
    assert_int_equal(ga_step_adaptive(x->s, NAN), GA_ERR_ARG);
    expect_message(x->s, "t_stop = nan is not finite");
    assert_int_equal(ga_step_adaptive(x->s, INFINITY), GA_ERR_ARG);
    assert_int_equal(ga_step_adaptive(x->s, t), GA_ERR_ARG);
    expect_message(x->s, "is not after t");
    assert_int_equal(ga_advance(x->s, -INFINITY), GA_ERR_ARG);
    expect_message(x->s, "t_out = -inf is not finite");
    assert_int_equal(ga_advance(x->s, t - 0.05), GA_ERR_ARG);
    expect_message(x->s, "is before t");
    assert_int_equal(ga_advance(x->s, t), GA_OK); /* already there: nothing to do */
    snapshot(x->s, after);
    assert_memory_equal(before, after, len * sizeof(double));

    /* dense output needs a step: not after ga_set_state; not at NaN or outside the step */
    double q[2];
    assert_int_equal(ga_interpolate(x->s, t, q, NULL, NULL), GA_OK);
    /* each failure with its own message, not the one an earlier failure left (issue 17) */
    assert_int_equal(ga_interpolate(x->s, NAN, q, NULL, NULL), GA_ERR_ARG);
    expect_message(x->s, "t = nan is not finite");
    assert_int_equal(ga_interpolate(x->s, t + 1.0, q, NULL, NULL), GA_ERR_ARG);
    expect_message(x->s, "is outside the last step");
    assert_int_equal(ga_set_state(x->s, before, len), GA_OK);
    assert_int_equal(ga_interpolate(x->s, t, q, NULL, NULL), GA_ERR_STATE);
    expect_message(x->s, "no step since ga_init or ga_set_state");
    assert_int_equal(ga_interpolate(NULL, t, q, NULL, NULL), GA_ERR_ARG);
}

static void bad_checkpoints_are_refused(void **state)
{
    fixture *x = *state;
    double buf[STATE_MAX], before[STATE_MAX], after[STATE_MAX];
    const size_t len = snapshot(x->s, before);
    memcpy(buf, before, len * sizeof(double));
    assert_int_equal(ga_set_state(x->s, buf, len - 1), GA_ERR_ARG);
    expect_message(x->s, "doubles");
    assert_int_equal(ga_get_state(x->s, buf, len - 1), GA_ERR_ARG);
    buf[0] = 1.0;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
    expect_message(x->s, "not a galpha checkpoint");
    buf[0] = before[0];
    buf[2] = 3.0;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
    buf[2] = before[2];
    buf[8] = NAN;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
    expect_message(x->s, "not finite");
    /* the step-size control's entries (t = 0.1 here): h_last 0 or a step that moves t,
     * h_next not negative, err_prev >= 0, grew 0 or 1 */
    const double bad_controls[][2] = {{5, -1e-3}, {5, 1e-320}, {5, 1e-18}, {6, -1.0},
                                      {7, -0.5}, {8, 0.5}, {8, 2.0}};
    for (size_t k = 0; k < sizeof bad_controls / sizeof bad_controls[0]; ++k) {
        memcpy(buf, before, len * sizeof(double));
        buf[(int)bad_controls[k][0]] = bad_controls[k][1];
        assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
        expect_message(x->s, bad_controls[k][0] == 5   ? "is not a step from"
                             : bad_controls[k][0] == 6 ? "is negative"
                                                       : "step-size control");
    }
    /* a proposal that no longer moves t is the solver's own (one made near t = 0, then a
     * ga_step far on: the solver refused its own checkpoint, found by the fuzzer) */
    memcpy(buf, before, len * sizeof(double));
    buf[6] = 1e-320;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_OK);
    {
        pendulum p = {1.0, 1.0, 9.81};
        double q[2], v[2], ckpt[256];
        size_t n_ckpt = 0;
        ga_solver *s = pendulum_new_solver(&p, 1);
        pendulum_state(&p, 0.5, 0.0, q, v);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        assert_int_equal(ga_set_initial_step(s, 1e-17), GA_OK);
        assert_int_equal(ga_step_adaptive(s, 1.0), GA_OK);  /* proposes about 7e-15 */
        for (int k = 0; k < 15000; ++k)  /* to t = 150, where h_next no longer moves t */
            assert_int_equal(ga_step(s, 1e-2), GA_OK);
        assert_int_equal(ga_state_size(s, &n_ckpt), GA_OK);
        assert_true(n_ckpt <= 256);
        assert_int_equal(ga_get_state(s, ckpt, n_ckpt), GA_OK);
        assert_true(ckpt[4] + ckpt[6] == ckpt[4] && ckpt[6] > 0.0);
        assert_int_equal(ga_set_state(s, ckpt, n_ckpt), GA_OK);
        ga_free(s);
    }
    /* the span of slivers (entry 9): at least 0, at most h_last / 100 */
    const double bad_spans[] = {-1e-9, 1.0};
    for (size_t k = 0; k < 2; ++k) {
        memcpy(buf, before, len * sizeof(double));
        buf[9] = bad_spans[k];
        assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
        expect_message(x->s, "sliver_span");
    }
    /* the kept matrix and its reuse (entries 10-18): flags, a step, counts as a solver
     * writes them */
    assert_true(before[10] == 1.0); /* a matrix is kept after ten steps */
    const double bad_matrix[][2] = {{10, 0.5}, {12, 0.0}, {14, 16.0}, {14, 1.5}, {15, -0.5},
                                    {16, 33.0}, {16, -1.0}, {17, 0.0}, {18, 2.0}};
    for (size_t k = 0; k < sizeof bad_matrix / sizeof bad_matrix[0]; ++k) {
        memcpy(buf, before, len * sizeof(double));
        buf[(int)bad_matrix[k][0]] = bad_matrix[k][1];
        assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
        expect_message(x->s, "entries 10-18");
    }
    /* the consistent accelerations of the index-3 error estimate (entries 19-20): how many
     * (0-2), and their distance in t, a step when there are two */
    const double bad_c[][2] = {{3.0, 0.0}, {-1.0, 0.0}, {1.5, 0.0}, {1e300, 0.0}, {1.0, -1e-3},
                               {2.0, 0.0}};
    for (size_t k = 0; k < sizeof bad_c / sizeof bad_c[0]; ++k) {
        memcpy(buf, before, len * sizeof(double));
        buf[19] = bad_c[k][0];
        buf[20] = bad_c[k][1];
        assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
        expect_message(x->s, "entries 19-20");
    }
    /* the constraints in use (entry 45 for the pendulum): flags; a dropped one only for a
     * solver that drops them */
    memcpy(buf, before, len * sizeof(double));
    assert_true(before[45] == 1.0);
    buf[45] = 0.5;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
    expect_message(x->s, "neither 0 nor 1");
    buf[45] = 0.0;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
    expect_message(x->s, "dropped constraint 0");
    /* the pivot blocks (from entry 46 for the pendulum): flags and sizes as written */
    const double bad_pivots[][2] = {{46, 0.5}, {47, -1.0}, {47, 2.5}, {48, 2.0}, {49, 0.5},
                                    {56, 3.0}, {72, 0.5}, {82, 0.5}};
    for (size_t k = 0; k < sizeof bad_pivots / sizeof bad_pivots[0]; ++k) {
        memcpy(buf, before, len * sizeof(double));
        buf[(int)bad_pivots[k][0]] = bad_pivots[k][1];
        assert_int_equal(ga_set_state(x->s, buf, len), GA_ERR_ARG);
        expect_message(x->s, "pivots");
    }
    /* layout 2 (galpha 0.2: no sliver_span, kept matrix or pivots) is read as a restart: the
     * same state, nothing kept; layout 2's size with layout 3's number is refused */
    assert_true(before[9] == 0.0);
    const size_t len2 = ckpt_as_layout2(before, buf);
    assert_int_equal(ga_set_state(x->s, buf, len2), GA_OK);
    assert_int_equal(ga_get_state(x->s, after, len), GA_OK);
    assert_memory_equal(after, before, 10 * sizeof(double));
    assert_memory_equal(after + CKPT_HEADER, before + CKPT_HEADER, 11 * sizeof(double));
    assert_true(after[10] == 0.0);
    buf[1] = 3.0;
    assert_int_equal(ga_set_state(x->s, buf, len2), GA_ERR_ARG);
    expect_message(x->s, "doubles");
    memcpy(buf, before, len * sizeof(double));
    buf[5] = 0.0; /* a checkpoint from before the first step */
    buf[6] = 0.0;
    assert_int_equal(ga_set_state(x->s, buf, len), GA_OK);
    assert_int_equal(ga_set_state(x->s, before, len), GA_OK);
    snapshot(x->s, after);
    assert_memory_equal(before, after, len * sizeof(double));
}

/* ---- failures inside a step --------------------------------------------------------------- */

static void fatal_callback_failure(void **state)
{
    fixture *x = *state;
    const fault_site sites[] = {MASS, FORCE, CONSTRAINT, JACOBIAN, STIFFNESS, DAMPING};
    const char *names[] = {"mass callback returned -7", "force callback returned -7",
                           "constraint callback returned -7", "jacobian callback returned -7",
                           "stiffness callback returned -7", "damping callback returned -7"};
    for (int i = 0; i < 6; ++i) {
        x->model.site = sites[i];
        x->model.rc = -7;
        failing_step(x, GA_ERR_CALLBACK, names[i]);
    }
}

static void recoverable_callback_failure(void **state)
{
    fixture *x = *state;
    x->model.site = FORCE;
    x->model.rc = 3;
    failing_step(x, GA_ERR_CALLBACK_RETRY, "force callback returned 3 (recoverable)");
    long long failed = 0;
    assert_int_equal(ga_get_counter(x->s, GA_COUNT_FAILED_STEPS, &failed), GA_OK);
    assert_int_equal(failed, 1);
}

/* The first step after ga_init computes the corrected starting values (two more consistent
 * accelerations, at t0 -+ h): a callback failing there fails the step like any other. */
static void failure_in_the_corrected_start(void **state)
{
    (void)state;
    const fault_site sites[] = {MASS, FORCE, CONSTRAINT, JACOBIAN};
    const char *names[] = {"mass callback returned", "force callback returned",
                           "constraint callback returned", "jacobian callback returned"};
    for (int i = 0; i < 4; ++i)
        for (int rc = -7; rc <= 7; rc += 14) {
            fixture x = {.model.p = {1.0, 1.0, 9.81}};
            double q[2], v[2];
            pendulum_state(&x.model.p, 1.0, 0.5, q, v);
            assert_int_equal(ga_create(2, 1, &x.s), GA_OK);
            assert_int_equal(ga_set_callbacks(x.s, f_mass, f_force, f_constraint, f_jacobian,
                                              &x.model),
                             GA_OK);
            assert_int_equal(ga_set_tangents(x.s, f_stiffness, f_damping), GA_OK);
            assert_int_equal(ga_init(x.s, 0.0, q, v), GA_OK);
            x.model.site = sites[i];
            x.model.rc = rc;
            failing_step(&x, rc < 0 ? GA_ERR_CALLBACK : GA_ERR_CALLBACK_RETRY, names[i]);
            ga_free(x.s);
        }
}

static void nan_and_inf_in_callback_outputs(void **state)
{
    fixture *x = *state;
    const fault_site sites[] = {MASS, FORCE, CONSTRAINT, JACOBIAN, STIFFNESS, DAMPING};
    const char *names[] = {"mass matrix M(0,0)", "force f[0]", "constraint Phi[0]",
                           "constraint Jacobian Phi_q(0,0)", "tangent stiffness K_t(0,0)",
                           "tangent damping C_t(0,0)"};
    for (int i = 0; i < 6; ++i) {
        x->model.site = sites[i];
        x->model.rc = 0;
        x->model.value = (i % 2) ? INFINITY : NAN;
        failing_step(x, GA_ERR_NONFINITE, names[i]);
    }
}

/* Finite callback outputs whose residual overflows (M(0,0) = 1e308 times an acceleration of
 * g): the check of r^q, which also stands in for the checks of f and Phi_q, reports it as
 * such, the state kept and the run going on without the fault. */
static void overflow_in_the_residual(void **state)
{
    fixture *x = *state;
    x->model.site = MASS;
    x->model.rc = 0;
    x->model.value = 1e308;
    failing_step(x, GA_ERR_NONFINITE, "residual r^q = M qdd - f + Phi_q^T lambda overflows");
}

/* The Phi_t callback is called in every Newton iteration of a stabilized index-2 step: its
 * failures (fatal, recoverable, NaN, Inf) are reported like any callback's, the state kept. */
/* Finite callback outputs whose Newton increment overflows (a force of 1e308 against the small
 * beta' M of a step of 10 s): reported as non-finite, with the state kept, wherever the
 * overflow shows first. */
static void overflow_in_the_newton_increment(void **state)
{
    fixture *x = *state;
    double before[STATE_MAX], after[STATE_MAX];
    const size_t len = snapshot(x->s, before);
    x->model.site = FORCE;
    x->model.rc = 0;
    x->model.value = 1e308;
    /* a step of 10 after steps of 0.01 starts afresh (over 100 times longer), from the
     * acceleration-level equations: the overflow shows in the corrected start, or without it
     * in the predictor */
    assert_int_equal(ga_step(x->s, 10.0), GA_ERR_NONFINITE);
    expect_message(x->s, "corrected starting values");
    assert_int_equal(ga_set_corrected_start(x->s, 0), GA_OK);
    assert_int_equal(ga_step(x->s, 10.0), GA_ERR_NONFINITE);
    expect_message(x->s, "predicted Newton iterate is not finite");
    snapshot(x->s, after);
    assert_true(ckpt_same_state(before, after));
    /* after steps of 0.1 it is a step of Algorithm 1, whose first increment overflows */
    double shifted[STATE_MAX];
    memcpy(shifted, before, len * sizeof(double));
    shifted[5] = 0.1; /* h_last */
    assert_int_equal(ga_set_state(x->s, shifted, len), GA_OK);
    assert_int_equal(ga_step(x->s, 10.0), GA_ERR_NONFINITE);
    expect_message(x->s, "Newton increment is not finite in iteration 1");
    snapshot(x->s, after);
    assert_true(ckpt_same_state(shifted, after));
    assert_int_equal(ga_set_corrected_start(x->s, 1), GA_OK);
    assert_int_equal(ga_set_state(x->s, shifted, ckpt_as_layout2(before, shifted)), GA_OK);
    x->model.site = NONE;
    continues_undisturbed(x, before, len);
}

/* States that overflow while every callback output stays finite are reported as non-finite,
 * with the state kept, and a step that stays in range goes on. Two places: the predictor (a
 * free particle at q = 1e308 moving at 1e308 per second, a step of 10 s) and a Newton update
 * (a repulsive spring f = k q at q0 = 1.15e308 with k h^2 = 1: the predictor, 1.5 q0, is
 * finite, so are the increments, the solution, 1.67 q0, is not). */
static int unit_mass(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = 1.0;
    return 0;
}

static int repulsive_spring(double t, const double *q, const double *v, double *f, void *u)
{
    (void)t, (void)v, (void)u;
    f[0] = q[0];
    return 0;
}

static void overflow_of_the_iterate(void **state)
{
    (void)state;
    const struct {
        ga_force_fn force;
        double q0, v0;
        const char *message;
    } cases[] = {
        {NULL, 1e308, 1e308, "predicted Newton iterate is not finite"},
        {repulsive_spring, 1.15e308, 0.0, "Newton iterate is not finite in iteration"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        ga_solver *s = NULL;
        double q = cases[k].q0, v = cases[k].v0, before[STATE_MAX], after[STATE_MAX];
        assert_int_equal(ga_create(1, 0, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, unit_mass, cases[k].force, NULL, NULL, NULL),
                         GA_OK);
        assert_int_equal(ga_init(s, 0.0, &q, &v), GA_OK);
        snapshot(s, before);
        assert_int_equal(ga_step(s, k == 0 ? 10.0 : 1.0), GA_ERR_NONFINITE);
        expect_message(s, cases[k].message);
        snapshot(s, after);
        assert_true(ckpt_same_state(before, after));
        assert_int_equal(ga_step(s, 0.1), GA_OK);
        assert_int_equal(ga_get_q(s, &q), GA_OK);
        if (k == 0)  /* no force: qdd = 0 and q moves by h v exactly */
            assert_true(q == 1e308 + 0.1 * 1e308);
        else         /* pushed outwards, still finite: q0 (1 + k h^2 / 2 + ...) */
            assert_true(q > cases[k].q0 * (1.0 + 0.5 * 0.01) && isfinite(q));
        ga_free(s);
    }
}

static void callback_failures_in_index2_steps(void **state)
{
    (void)state;
    const struct {
        fault_site site;
        int rc;
        double value;
        ga_status expected;
        const char *part;
    } cases[] = {
        {CONSTRAINT_DT, -7, 0.0, GA_ERR_CALLBACK, "constraint_dt callback returned -7"},
        {CONSTRAINT_DT, 3, 0.0, GA_ERR_CALLBACK_RETRY,
         "constraint_dt callback returned 3 (recoverable)"},
        {CONSTRAINT_DT, 0, NAN, GA_ERR_NONFINITE, "constraint time derivative Phi_t[0]"},
        {CONSTRAINT_DT, 0, INFINITY, GA_ERR_NONFINITE, "constraint time derivative Phi_t[0]"},
        /* Phi_q at the start of the step (the direction of the position correction) and at
         * the perturbed point of the curvature block */
        {JACOBIAN, -7, 0.0, GA_ERR_CALLBACK, "jacobian callback returned -7"},
        {JACOBIAN, 0, NAN, GA_ERR_NONFINITE, "constraint Jacobian Phi_q(0,0)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        faulty model = {{1.0, 1.0, 9.81}, NONE, 0, 0.0, 0, 0, 0, NULL, GA_OK, 0};
        ga_solver *s = NULL;
        double q[2], v[2], before[STATE_MAX], after[STATE_MAX];
        pendulum_state(&model.p, 1.0, 0.5, q, v);
        assert_int_equal(ga_create(2, 1, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, f_mass, f_force, f_constraint, f_jacobian, &model),
                         GA_OK);
        assert_int_equal(ga_set_constraint_dt(s, f_constraint_dt), GA_OK);
        assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
        assert_int_equal(ga_step(s, 0.01), GA_OK);
        snapshot(s, before);
        model.site = cases[k].site;
        model.rc = cases[k].rc;
        model.value = cases[k].value;
        assert_int_equal(ga_step(s, 0.01), cases[k].expected);
        expect_message(s, cases[k].part);
        snapshot(s, after);
        assert_true(ckpt_same_state(before, after));
        model.site = NONE; /* and the run goes on */
        assert_int_equal(ga_step(s, 0.01), GA_OK);
        ga_free(s);
    }
}

static void singular_iteration_matrix(void **state)
{
    fixture *x = *state;
    x->model.zero_jacobian = 1; /* Phi_q = 0: the saddle-point matrix is singular */
    failing_step(x, GA_ERR_SINGULAR, "iteration matrix S_t (scaled, eq. 10) is singular");
}

/* Singular only at an iterate Newton moved to (full Newton rebuilds the matrix at every
 * iteration; Phi_q vanishes from the step's second Jacobian call on): the message says where,
 * and what may be behind it. */
static void singular_iteration_matrix_at_a_later_iterate(void **state)
{
    fixture *x = *state;
    assert_int_equal(ga_set_jacobian_reuse(x->s, GA_REUSE_NEVER), GA_OK);
    x->model.jacobian_calls = 0;
    x->model.zero_jacobian_from = 2;
    double before[STATE_MAX], after[STATE_MAX];
    const size_t len = snapshot(x->s, before);
    assert_int_equal(ga_step(x->s, 0.01), GA_ERR_SINGULAR);
    expect_message(x->s, "is singular (rcond = 0) in Newton iteration 2");
    expect_message(x->s, "at an iterate the iteration moved to");
    expect_message(x->s, "a smaller h may help");
    snapshot(x->s, after);
    assert_true(ckpt_same_state(before, after));
    /* recovery, with the default modified Newton the reference solver uses */
    x->model.zero_jacobian_from = 0;
    assert_int_equal(ga_set_jacobian_reuse(x->s, GA_REUSE_AUTO), GA_OK);
    continues_undisturbed(x, before, len);
}

static void newton_not_converged_in_max_iter(void **state)
{
    fixture *x = *state;
    assert_int_equal(ga_set_newton(x->s, 1e-10, 1), GA_OK);
    double before[STATE_MAX], after[STATE_MAX];
    snapshot(x->s, before);
    assert_int_equal(ga_step(x->s, 0.01), GA_ERR_NEWTON);
    expect_message(x->s, "did not converge in 1 iterations");
    snapshot(x->s, after);
    assert_true(ckpt_same_state(before, after));
    assert_int_equal(ga_set_newton(x->s, 1e-10, 20), GA_OK);
    assert_int_equal(ga_step(x->s, 0.01), GA_OK);
}

/* A wrong tangent (as from a sign error in user code) makes Newton diverge: reported, not
 * accepted, and the state is kept. */
static int wrong_stiffness(double t, const double *q, const double *v, const double *qdd,
                           const double *lambda, double *K, void *u)
{
    (void)t, (void)q, (void)v, (void)qdd, (void)lambda, (void)u;
    K[0] = K[3] = -1.95e4; /* cancels most of beta' M at h = 0.01: a wildly wrong slope */
    K[1] = K[2] = 0.0;
    return 0;
}

static void newton_diverges_with_wrong_tangent(void **state)
{
    fixture *x = *state;
    assert_int_equal(ga_set_tangents(x->s, wrong_stiffness, NULL), GA_OK);
    double before[STATE_MAX], after[STATE_MAX];
    snapshot(x->s, before);
    const ga_status st = ga_step(x->s, 0.01);
    assert_true(st == GA_ERR_NEWTON || st == GA_ERR_NONFINITE);
    snapshot(x->s, after);
    assert_true(ckpt_same_state(before, after));
}

/* ---- re-entrancy ------------------------------------------------------------------------ */

static void callback_calling_its_own_solver_is_refused(void **state)
{
    fixture *x = *state;
    x->model.self = x->s;
    x->model.reentry_status = GA_OK;
    assert_int_equal(ga_step(x->s, 0.01), GA_OK); /* the outer step is not disturbed */
    assert_true(x->model.reentry_calls > 0);
    assert_int_equal(x->model.reentry_status, GA_ERR_STATE);
    /* after the outer call, its own (empty: success) message again */
    assert_string_equal(ga_last_error(x->s), "");
    x->model.self = NULL;
}

/* ---- initial values ---------------------------------------------------------------------- */

/* Callback failures inside ga_init (projection of q0 and v0, consistent accelerations): the
 * status and the callback are reported, the solver stays uninitialized, and a ga_init after
 * the fault is gone succeeds. q0 off the constraint and v0 off the velocity constraint, so
 * that the projections call every callback. */
static void callback_failures_in_ga_init(void **state)
{
    (void)state;
    const fault_site sites[] = {MASS, FORCE, CONSTRAINT, JACOBIAN, CONSTRAINT_DT};
    const char *names[] = {"mass callback returned", "force callback returned",
                           "constraint callback returned", "jacobian callback returned",
                           "constraint_dt callback returned"};
    for (int i = 0; i < 5; ++i)
        for (int rc = -7; rc <= 7; rc += 14) {
            faulty model = {.p = {1.0, 1.0, 9.81}, .site = sites[i], .rc = rc};
            double q[2] = {0.3, -1.0}, v[2] = {0.2, 0.4}, t;
            ga_solver *s = NULL;
            assert_int_equal(ga_create(2, 1, &s), GA_OK);
            assert_int_equal(ga_set_callbacks(s, f_mass, f_force, f_constraint, f_jacobian,
                                              &model),
                             GA_OK);
            assert_int_equal(ga_set_constraint_dt(s, f_constraint_dt), GA_OK);
            assert_int_equal(ga_init(s, 0.0, q, v),
                             rc < 0 ? GA_ERR_CALLBACK : GA_ERR_CALLBACK_RETRY);
            expect_message(s, names[i]);
            assert_int_equal(ga_get_t(s, &t), GA_ERR_STATE);
            assert_int_equal(ga_step(s, 0.01), GA_ERR_STATE);
            model.site = NONE;
            assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
            assert_int_equal(ga_step(s, 0.01), GA_OK);
            ga_free(s);
        }
}

/* Projections with a rank-deficient Phi_q (the pendulum's constraint twice): position and
 * velocity projection report a singular matrix instead of dividing by zero. */
static void rank_deficient_projections_at_init(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL;
    double q[2] = {0.3, -1.0}, v[2] = {0.0, 0.0};
    assert_int_equal(ga_create(2, 2, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_twice_constraint,
                                      pendulum_twice_jacobian, &p),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_SINGULAR);
    expect_message(s, "cannot project q0: Phi_q is rank deficient");
    q[0] = 0.0; /* on the circle, moving off it */
    v[1] = 0.2;
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_SINGULAR);
    expect_message(s, "cannot project v0: Phi_q is rank deficient");
    ga_free(s);
}

static void inconsistent_start_refused_when_asked(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL;
    double q[2] = {0.3, -1.0}, v[2] = {0.0, 0.0};
    assert_non_null(s = pendulum_new_solver(&p, 0));
    assert_int_equal(ga_set_init_mode(s, GA_INIT_REFUSE, 1e-10), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_INCONSISTENT);
    expect_message(s, "q0 violates the constraints");
    q[0] = 0.0; /* consistent position, inconsistent velocity */
    v[1] = 0.2;
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_INCONSISTENT);
    expect_message(s, "v0 violates the velocity constraints");
    ga_free(s);
}

/* x^2 + y^2 = L^2 with L^2 < 0 has no solution: the projection must give up, not loop. */
static int impossible_constraint(double t, const double *q, double *phi, void *u)
{
    (void)t, (void)u;
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] + 1.0);
    return 0;
}

static void projection_that_cannot_converge(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL;
    double q[2] = {0.3, -1.0}, v[2] = {0.0, 0.0};
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, impossible_constraint,
                                      pendulum_jacobian, &p),
                     GA_OK);
    const ga_status st = ga_init(s, 0.0, q, v);
    assert_true(st == GA_ERR_INCONSISTENT || st == GA_ERR_SINGULAR);
    printf("  impossible constraint: %s: %s\n", ga_strerror(st), ga_last_error(s));
    ga_free(s);
}

static int massless(double t, const double *q, double *M, void *u)
{
    (void)t, (void)q, (void)u;
    M[0] = M[1] = M[2] = M[3] = 0.0;
    return 0;
}

/* ga_init of a pendulum at rest at 0.4 rad with the given callbacks: refused as singular, with
 * the message part given, by every dense LU kernel. */
static void singular_at_init(ga_mass_fn mass, int m, ga_constraint_fn constraint,
                             ga_jacobian_fn jacobian, const char *part)
{
    const int kernels[] = {GA_LINEAR_DENSE, GA_LINEAR_DENSE_UNBLOCKED, GA_LINEAR_DENSE_EIGEN,
                           GA_LINEAR_DENSE_LAPACK};
    for (size_t k = 0; k < sizeof kernels / sizeof kernels[0]; ++k) {
        pendulum p = {1.0, 1.0, 9.81};
        ga_solver *s = NULL;
        double q[2], v[2];
        pendulum_state(&p, 0.4, 0.0, q, v);
        assert_int_equal(ga_create(2, m, &s), GA_OK);
        assert_int_equal(ga_set_callbacks(s, mass, pendulum_force, constraint, jacobian, &p),
                         GA_OK);
        assert_int_equal(ga_set_linear_solver(s, kernels[k]), GA_OK);
        assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_SINGULAR);
        expect_message(s, "saddle-point matrix [M Phi_q^T; Phi_q 0] is singular");
        expect_message(s, part);
        ga_free(s);
    }
}

static void singular_saddle_point_matrix_at_init(void **state)
{
    (void)state;
    /* the two rows of Phi_q are equal: rank 1, and the second depends on the first */
    singular_at_init(pendulum_mass, 2, pendulum_twice_constraint, pendulum_twice_jacobian,
                     "Phi_q has rank 1 < m = 2, redundant constraints (GA_REDUNDANT_DROP drops "
                     "them); these depend on the ones before them: 1");
}

/* A pendulum bob without mass: Phi_q has full rank, M is zero on its null space. */
static void massless_coordinate_at_init(void **state)
{
    (void)state;
    singular_at_init(massless, 1, pendulum_constraint, pendulum_jacobian,
                     "Phi_q has full rank 1, so M is singular on the null space of Phi_q");
}

static void nan_in_initial_values(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL;
    double q[2] = {0.0, -1.0}, v[2] = {NAN, 0.0};
    assert_non_null(s = pendulum_new_solver(&p, 0));
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_ARG);
    assert_int_equal(ga_init(s, NAN, q, q), GA_ERR_ARG);
    ga_free(s);
}

/* ---- memory ------------------------------------------------------------------------------ */

static int overcommit_always(void)
{
    FILE *f = fopen("/proc/sys/vm/overcommit_memory", "r");
    int mode = 0;
    if (f) {
        if (fscanf(f, "%d", &mode) != 1)
            mode = 0;
        fclose(f);
    }
    return mode == 1;
}

static void out_of_memory_is_reported(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    ga_solver *s = NULL;
    /* Dense workspace for n = 400 000: 1.28e12 bytes per n x n matrix, beyond any RAM here
     * (and beyond ASan's allocation limit): malloc fails, and so must ga_init, cleanly. */
    if (overcommit_always()) {
        printf("  skipped: vm.overcommit_memory = 1 would let the allocation succeed lazily\n");
        skip();
    }
    assert_int_equal(ga_create(400000, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, NULL, NULL, NULL, &p), GA_OK);
    double x = 0.0;
    assert_int_equal(ga_init(s, 0.0, &x, &x), GA_ERR_NOMEM);
    expect_message(s, "out of memory");
    ga_free(s);
}

static void strerror_names_every_status(void **state)
{
    (void)state;
    for (int st = GA_OK; st >= GA_ERR_STEP_SIZE; --st)
        assert_string_not_equal(ga_strerror(st), "unknown status");
    assert_string_equal(ga_strerror(-99), "unknown status");
    assert_string_equal(ga_strerror(GA_ERR_NEWTON), "Newton iteration did not converge");
    assert_string_equal(ga_strerror(GA_ERR_STEP_SIZE), "step size below its minimum");
}

#define T(f) cmocka_unit_test_setup_teardown(f, setup, teardown)
int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(create_rejects_bad_sizes),
        T(null_pointers_are_refused),
        T(bad_step_sizes_are_refused),
        cmocka_unit_test(calls_out_of_order_are_refused),
        T(bad_options_are_refused),
        cmocka_unit_test(bad_patterns_are_refused),
        T(bad_adaptive_calls_are_refused),
        T(bad_checkpoints_are_refused),
        T(fatal_callback_failure),
        T(recoverable_callback_failure),
        T(nan_and_inf_in_callback_outputs),
        T(overflow_in_the_newton_increment),
        T(overflow_in_the_residual),
        cmocka_unit_test(failure_in_the_corrected_start),
        T(singular_iteration_matrix),
        T(singular_iteration_matrix_at_a_later_iterate),
        T(newton_not_converged_in_max_iter),
        T(newton_diverges_with_wrong_tangent),
        T(callback_calling_its_own_solver_is_refused),
        cmocka_unit_test(inconsistent_start_refused_when_asked),
        cmocka_unit_test(callback_failures_in_ga_init),
        cmocka_unit_test(rank_deficient_projections_at_init),
        cmocka_unit_test(projection_that_cannot_converge),
        cmocka_unit_test(singular_saddle_point_matrix_at_init),
        cmocka_unit_test(massless_coordinate_at_init),
        cmocka_unit_test(nan_in_initial_values),
        cmocka_unit_test(callback_failures_in_index2_steps),
        cmocka_unit_test(overflow_of_the_iterate),
        cmocka_unit_test(out_of_memory_is_reported),
        cmocka_unit_test(strerror_names_every_status),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
