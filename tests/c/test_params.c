/* Method parameters: eq. (24) with eq. (20) from rho_inf, and every refusal of ga_set_params
 * with the condition it names. Expected values are worked out by hand from eq. (24). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <string.h>

#include <galpha.h>

static int setup(void **state)
{
    ga_solver *s = NULL;
    if (ga_create(2, 1, &s) != GA_OK)
        return -1;
    *state = s;
    return 0;
}

static int teardown(void **state)
{
    ga_free((ga_solver *)*state);
    return 0;
}

static void expect_params(ga_solver *s, double am, double af, double beta, double gamma)
{
    double a, b, c, d;
    assert_int_equal(ga_get_params(s, &a, &b, &c, &d), GA_OK);
    assert_true(fabs(a - am) < 1e-15);
    assert_true(fabs(b - af) < 1e-15);
    assert_true(fabs(c - beta) < 1e-15);
    assert_true(fabs(d - gamma) < 1e-15);
}

/* rho = 0: alpha_m = -1, alpha_f = 0, gamma = 3/2, beta = 1.
 * rho = 1/2: alpha_m = 0, alpha_f = 1/3, gamma = 5/6, beta = 4/9.
 * rho = 0.7: alpha_m = 4/17, alpha_f = 7/17, gamma = 23/34, beta = 100/289.
 * rho = 0.9: alpha_m = 8/19, alpha_f = 9/19, gamma = 21/38, beta = 100/361 (gena defaults).
 * rho = 1: alpha_m = alpha_f = 1/2, gamma = 1/2, beta = 1/4 (trapezoidal rule). */
static void rho_inf_gives_eq_24(void **state)
{
    ga_solver *s = *state;
    assert_int_equal(ga_set_rho_inf(s, 0.0), GA_OK);
    expect_params(s, -1.0, 0.0, 1.0, 1.5);
    assert_int_equal(ga_set_rho_inf(s, 0.5), GA_OK);
    expect_params(s, 0.0, 1.0 / 3.0, 4.0 / 9.0, 5.0 / 6.0);
    assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
    expect_params(s, 4.0 / 17.0, 7.0 / 17.0, 100.0 / 289.0, 23.0 / 34.0);
    assert_int_equal(ga_set_rho_inf(s, 0.9), GA_OK);
    expect_params(s, 8.0 / 19.0, 9.0 / 19.0, 100.0 / 361.0, 21.0 / 38.0);
    assert_int_equal(ga_set_rho_inf(s, 1.0), GA_OK);
    expect_params(s, 0.5, 0.5, 0.25, 0.5);
}

static void default_is_rho_09(void **state)
{
    expect_params(*state, 8.0 / 19.0, 9.0 / 19.0, 100.0 / 361.0, 21.0 / 38.0);
}

static void rho_inf_outside_unit_interval_is_refused(void **state)
{
    ga_solver *s = *state;
    assert_int_equal(ga_set_rho_inf(s, -0.01), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "outside [0, 1]"));
    assert_int_equal(ga_set_rho_inf(s, 1.01), GA_ERR_ARG);
    assert_int_equal(ga_set_rho_inf(s, NAN), GA_ERR_ARG);
    expect_params(s, 8.0 / 19.0, 9.0 / 19.0, 100.0 / 361.0, 21.0 / 38.0); /* unchanged */
}

static void explicit_params_satisfying_20_and_23_are_accepted(void **state)
{
    ga_solver *s = *state;
    /* HHT-like: alpha_m = 0, alpha_f = 0.1, gamma = 0.6, beta = 0.3025 > 0.25 + 0.05 */
    assert_int_equal(ga_set_params(s, 0.0, 0.1, 0.3025, 0.6), GA_OK);
    expect_params(s, 0.0, 0.1, 0.3025, 0.6);
}

static void refused(ga_solver *s, double am, double af, double beta, double gamma,
                    const char *why)
{
    assert_int_equal(ga_set_params(s, am, af, beta, gamma), GA_ERR_ARG);
    if (!strstr(ga_last_error(s), why))
        fail_msg("message '%s' does not name '%s'", ga_last_error(s), why);
    expect_params(s, 8.0 / 19.0, 9.0 / 19.0, 100.0 / 361.0, 21.0 / 38.0); /* unchanged */
}

static void each_broken_condition_is_named(void **state)
{
    ga_solver *s = *state;
    refused(s, 0.0, 0.1, 0.3025, 0.55, "order-2 condition (eq. 20)");
    refused(s, 0.6, 0.7, 0.5, 0.6, "alpha_m > 1/2 is not zero-stable");
    refused(s, 0.2, 0.1, 0.3, 0.4, "alpha_m >= alpha_f");
    refused(s, 0.0, 0.0, 0.25, 0.5, "alpha_m >= alpha_f"); /* Newmark trapezoidal */
    refused(s, 0.3, 0.5, 0.5, 0.7, "alpha_f >= 1/2");
    refused(s, 0.0, 0.1, 0.3, 0.6, "beta <= 1/4 + (alpha_f - alpha_m)/2");
    refused(s, NAN, 0.1, 0.3, 0.6, "finite");
    refused(s, 0.0, INFINITY, 0.3, 0.6, "finite");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(default_is_rho_09, setup, teardown),
        cmocka_unit_test_setup_teardown(rho_inf_gives_eq_24, setup, teardown),
        cmocka_unit_test_setup_teardown(rho_inf_outside_unit_interval_is_refused, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(explicit_params_satisfying_20_and_23_are_accepted, setup,
                                        teardown),
        cmocka_unit_test_setup_teardown(each_broken_condition_is_named, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
