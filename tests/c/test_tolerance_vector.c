/* Per-coordinate absolute tolerances (ga_set_tolerances_vector): two uncoupled oscillators,
 * a slow one of amplitude 1 (omega 1) and a fast one of amplitude 1e-8 (omega 10), and a
 * first-order state y' = -y, against their exact solutions. With one atol the fast one sits
 * far below it and its error is not controlled; with its own atol it is held as it is when
 * it dominates at amplitude 1 (the model is linear: a coordinate scaled by c with its atol
 * scaled by c has the same relative error). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

enum { N = 2, R = 1 };
static const double kOmega[N] = {1.0, 10.0};
static const double kSmall[N] = {1.0, 1e-8}; /* the fast one far below atol */
static const double kLarge[N] = {1e-8, 1.0}; /* the fast one alone at its own scale */
static const double *kAmp = kSmall;

static int mass(double t, const double *q, double *M, void *user)
{
    (void)t, (void)q, (void)user;
    M[0] = 1.0, M[1] = 0.0, M[2] = 0.0, M[3] = 1.0;
    return 0;
}

static int force(double t, const double *q, const double *v, const double *y, double *f,
                 void *user)
{
    (void)t, (void)v, (void)y, (void)user;
    for (int i = 0; i < N; ++i)
        f[i] = -kOmega[i] * kOmega[i] * q[i];
    return 0;
}

static int rate(double t, const double *q, const double *v, const double *y, double *ydot,
                void *user)
{
    (void)t, (void)q, (void)v, (void)user;
    ydot[0] = -y[0];
    return 0;
}

static ga_solver *make(void)
{
    ga_solver *s = NULL;
    assert_int_equal(ga_create(N, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, mass, NULL, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_first_order(s, R, force, rate), GA_OK);
    return s;
}

/* Largest relative error of each oscillator's q and of y over ten output times to t = 10;
 * the accepted steps. */
static void run(ga_solver *s, double err[N + 1], long long *steps)
{
    double q[N], v[N], y[R], yd[R];
    for (int i = 0; i < N; ++i)
        q[i] = kAmp[i], v[i] = 0.0;
    y[0] = 1.0;
    assert_int_equal(ga_init_y(s, 0.0, q, v, y), GA_OK);
    memset(err, 0, (N + 1) * sizeof(double));
    for (int k = 1; k <= 10; ++k) {
        const double t = k;
        assert_int_equal(ga_advance(s, t), GA_OK);
        assert_int_equal(ga_get_q(s, q), GA_OK);
        assert_int_equal(ga_get_y(s, y, yd), GA_OK);
        for (int i = 0; i < N; ++i)
            err[i] = fmax(err[i], fabs(q[i] - kAmp[i] * cos(kOmega[i] * t)) / kAmp[i]);
        err[N] = fmax(err[N], fabs(y[0] - exp(-t)) / exp(-t));
    }
    assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, steps), GA_OK);
}

static void equal_entries_are_the_scalar_tolerance(void **state)
{
    (void)state;
    const double rtol = 1e-5, atol = 1e-7, each[2 * N + R] = {atol, atol, atol, atol, atol};
    double e1[N + 1], e2[N + 1];
    long long n1, n2;
    ga_solver *a = make(), *b = make();
    assert_int_equal(ga_set_tolerances(a, rtol, atol), GA_OK);
    assert_int_equal(ga_set_tolerances_vector(b, rtol, each), GA_OK);
    run(a, e1, &n1);
    run(b, e2, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(e1, e2, sizeof e1); /* bit for bit */
    ga_free(a);
    ga_free(b);
}

static void a_small_coordinate_is_held_to_its_own_tolerance(void **state)
{
    (void)state;
    const double rtol = 1e-6, atol = 1e-6;
    /* the fast oscillator's position and velocity at its own scale */
    const double each[2 * N + R] = {atol, atol * kSmall[1], atol, atol * kSmall[1], atol};
    double one[N + 1], own[N + 1], alone[N + 1];
    long long n_one, n_own, n_alone;
    ga_solver *a = make(), *b = make(), *c = make();
    assert_int_equal(ga_set_tolerances(a, rtol, atol), GA_OK);
    assert_int_equal(ga_set_tolerances_vector(b, rtol, each), GA_OK);
    assert_int_equal(ga_set_tolerances(c, rtol, atol), GA_OK);
    run(a, one, &n_one);
    run(b, own, &n_own);
    kAmp = kLarge;
    run(c, alone, &n_alone);
    kAmp = kSmall;
    printf("  one atol:     %lld steps, relative errors slow %.2e fast %.2e y %.2e\n", n_one,
           one[0], one[1], one[2]);
    printf("  own atol:     %lld steps, relative errors slow %.2e fast %.2e y %.2e\n", n_own,
           own[0], own[1], own[2]);
    printf("  fast at 1:    %lld steps, relative error fast %.2e\n", n_alone, alone[1]);
    /* One atol: the fast oscillator (1e-8 against atol 1e-6) weighs nothing in the error
     * norm, the steps follow the slow one and its phase error grows unchecked. With its own
     * atol it is held as at its own scale: the steps it takes there (the slow one, now at
     * 1e-8, weighs nothing), and its error, which decreases with h (a phase error). */
    assert_true(one[1] > 50.0 * alone[1]);
    assert_true(own[1] <= alone[1]);
    assert_true(n_own >= n_alone);
    assert_true(own[0] <= one[0]); /* the slow one rides along on the smaller steps */
    ga_free(a);
    ga_free(b);
    ga_free(c);
}

static void refusals_name_the_entry_and_change_nothing(void **state)
{
    (void)state;
    const double good[2 * N + R] = {1e-6, 1e-6, 1e-6, 1e-6, 1e-6};
    double bad[2 * N + R];
    ga_solver *s = make(), *twin = make();
    assert_int_equal(ga_set_tolerances(s, 1e-5, 1e-7), GA_OK);
    assert_int_equal(ga_set_tolerances(twin, 1e-5, 1e-7), GA_OK);
    assert_int_equal(ga_set_tolerances_vector(s, 1e-5, NULL), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "NULL"));
    assert_int_equal(ga_set_tolerances_vector(s, 0.0, good), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "rtol"));
    assert_int_equal(ga_set_tolerances_vector(s, NAN, good), GA_ERR_ARG);
    const double wrong[3] = {0.0, -1e-6, NAN};
    for (int k = 0; k < 3; ++k) {
        memcpy(bad, good, sizeof bad);
        bad[2 * N] = wrong[k]; /* the state's entry */
        assert_int_equal(ga_set_tolerances_vector(s, 1e-5, bad), GA_ERR_ARG);
        assert_non_null(strstr(ga_last_error(s), "atol[4]"));
        assert_non_null(strstr(ga_last_error(s), "state 0"));
    }
    bad[2 * N] = 1e-6, bad[N + 1] = INFINITY;
    assert_int_equal(ga_set_tolerances_vector(s, 1e-5, bad), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "velocity 1"));
    assert_int_equal(ga_set_tolerances_vector(NULL, 1e-5, good), GA_ERR_ARG);
    /* nothing changed: the same run as the twin's */
    double e1[N + 1], e2[N + 1];
    long long n1, n2;
    run(s, e1, &n1);
    run(twin, e2, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(e1, e2, sizeof e1);
    ga_free(s);
    ga_free(twin);
}

static void scalar_tolerances_undo_the_vector(void **state)
{
    (void)state;
    const double each[2 * N + R] = {1e-3, 1e-9, 1e-3, 1e-9, 1e-3};
    double e1[N + 1], e2[N + 1];
    long long n1, n2;
    ga_solver *a = make(), *b = make();
    assert_int_equal(ga_set_tolerances_vector(a, 1e-5, each), GA_OK);
    assert_int_equal(ga_set_tolerances(a, 1e-5, 1e-7), GA_OK);
    assert_int_equal(ga_set_tolerances(b, 1e-5, 1e-7), GA_OK);
    run(a, e1, &n1);
    run(b, e2, &n2);
    assert_int_equal(n1, n2);
    assert_memory_equal(e1, e2, sizeof e1);
    ga_free(a);
    ga_free(b);
}

static void states_are_declared_before_their_tolerances(void **state)
{
    (void)state;
    ga_solver *s = NULL;
    const double each[2 * N] = {1e-6, 1e-6, 1e-6, 1e-6};
    assert_int_equal(ga_create(N, 0, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, mass, NULL, NULL, NULL, NULL), GA_OK);
    assert_int_equal(ga_set_tolerances_vector(s, 1e-5, each), GA_OK); /* 2 n + 0 */
    assert_int_equal(ga_set_first_order(s, R, force, rate), GA_ERR_STATE);
    assert_non_null(strstr(ga_last_error(s), "ga_set_tolerances_vector"));
    assert_int_equal(ga_set_first_order(s, 0, NULL, NULL), GA_OK); /* the same r: accepted */
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(equal_entries_are_the_scalar_tolerance),
        cmocka_unit_test(a_small_coordinate_is_held_to_its_own_tolerance),
        cmocka_unit_test(refusals_name_the_entry_and_change_nothing),
        cmocka_unit_test(scalar_tolerances_undo_the_vector),
        cmocka_unit_test(states_are_declared_before_their_tolerances),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
