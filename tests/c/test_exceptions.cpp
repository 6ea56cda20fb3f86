// No C++ exception crosses the C ABI: a callback written in C++ that throws makes the call
// fail with a status (GA_ERR_INTERNAL, or GA_ERR_NOMEM for std::bad_alloc and
// std::length_error), the message
// carries what(), the state is kept, and the solver stays usable.
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}
#include <cstdio>
#include <cstring>
#include <new>
#include <stdexcept>

#include <galpha.h>

#include "scenes/pendulum.h"

namespace {

// 0: none, 1: std::runtime_error, 2: int, 3: std::bad_alloc, 4: std::length_error (what a
// vector beyond max_size() throws: memory, not a bug)
int throw_kind = 0;

int throwing_force(double t, const double *q, const double *v, double *f, void *user)
{
    switch (throw_kind) {
    case 1: throw std::runtime_error("model exploded");
    case 2: throw 42;
    case 3: throw std::bad_alloc();
    case 4: throw std::length_error("cannot create std::vector larger than max_size()");
    default: return pendulum_force(t, q, v, f, user);
    }
}

void exceptions_become_statuses(void **)
{
    pendulum p{1.0, 1.0, 9.81};
    double q[2], v[2];
    ga_solver *s = nullptr;
    pendulum_state(&p, 0.5, 0.0, q, v);
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, throwing_force, pendulum_constraint,
                                      pendulum_jacobian, &p),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double before[128], after[128];
    assert_true(len <= 128);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    // the state proper: header entries 0-9 (t, the step-size control), then from entry 19
    // q, v, qdd, lambda, a, a_prev (a failed step drops the kept matrix on purpose)
    const size_t state = 5 * 2 + 1;

    const ga_status expected[] = {GA_ERR_INTERNAL, GA_ERR_INTERNAL, GA_ERR_NOMEM, GA_ERR_NOMEM};
    const char *message[] = {"model exploded", "unknown type", "out of memory",
                             "out of memory: cannot create std::vector larger"};
    for (int k = 1; k <= 4; ++k) {
        throw_kind = k;
        assert_int_equal(ga_step(s, 0.01), expected[k - 1]);
        assert_non_null(std::strstr(ga_last_error(s), message[k - 1]));
        assert_int_equal(ga_get_state(s, after, len), GA_OK);
        assert_memory_equal(before, after, 10 * sizeof(double));
        assert_memory_equal(before + 19, after + 19, state * sizeof(double));
    }
    // an exception during ga_init is caught as well, and the solver is still usable after
    throw_kind = 1;
    assert_int_equal(ga_init(s, 0.0, q, v), GA_ERR_INTERNAL);
    throw_kind = 0;
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    ga_free(s);
}

int throwing_hook(const ga_solver *, double, const double *, const double *, const double *,
                  void *)
{
    switch (throw_kind) {
    case 1: throw std::runtime_error("hook exploded");
    case 2: throw 42;
    case 3: throw std::bad_alloc();
    case 4: throw std::length_error("cannot create std::vector larger than max_size()");
    default: return 0;
    }
}

// A step hook that throws fails the call and undoes the step it was called after.
void throwing_step_hook(void **)
{
    pendulum p{1.0, 1.0, 9.81};
    double q[2], v[2];
    ga_solver *s = nullptr;
    pendulum_state(&p, 0.5, 0.0, q, v);
    assert_int_equal(ga_create(2, 1, &s), GA_OK);
    assert_int_equal(ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &p),
                     GA_OK);
    assert_int_equal(ga_set_step_hook(s, throwing_hook, nullptr, 0), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    throw_kind = 0;
    assert_int_equal(ga_step(s, 0.01), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    double before[128], after[128];
    assert_true(len <= 128);
    assert_int_equal(ga_get_state(s, before, len), GA_OK);
    const size_t state = 5 * 2 + 1;
    const ga_status expected[] = {GA_ERR_INTERNAL, GA_ERR_INTERNAL, GA_ERR_NOMEM};
    const char *message[] = {"hook exploded", "unknown type", "out of memory"};
    for (int k = 1; k <= 3; ++k)
        for (int adaptive = 0; adaptive < 3; ++adaptive) {
            throw_kind = k;
            const ga_status st = adaptive == 0   ? ga_step(s, 0.01)
                                 : adaptive == 1 ? ga_step_adaptive(s, 1.0)
                                                 : ga_advance(s, 1.0);
            assert_int_equal(st, expected[k - 1]);
            assert_non_null(std::strstr(ga_last_error(s), message[k - 1]));
            assert_int_equal(ga_get_state(s, after, len), GA_OK);
            assert_memory_equal(before, after, 10 * sizeof(double));
            assert_memory_equal(before + 19, after + 19, state * sizeof(double));
        }
    throw_kind = 0;
    assert_int_equal(ga_advance(s, 0.5), GA_OK);
    ga_free(s);
}

// Throws at its countdown-th call (0: never).
int throw_at = 0;
int counting_force(double t, const double *q, const double *v, double *f, void *user)
{
    if (throw_at > 0 && --throw_at == 0)
        throw std::runtime_error("thrown in a fallback");
    return pendulum_force(t, q, v, f, user);
}

// An exception in the attempts a step falls back to (a fresh matrix, full Newton, the
// constant-a predictor, which change the iteration's options for their attempt) leaves the
// options as they were: the run that follows is that of a solver whose step failed without
// one (both drop the kept matrix).
void exception_in_a_fallback_changes_no_option(void **)
{
    pendulum p{1.0, 1.0, 9.81};
    double q[2], v[2];
    pendulum_state(&p, 0.5, 1.0, q, v);
    int calls = 0;
    for (int k = 1; calls == 0 || k <= calls; ++k) {
        ga_solver *s[2];
        for (auto &x : s) {
            assert_int_equal(ga_create(2, 1, &x), GA_OK);
            assert_int_equal(ga_set_callbacks(x, pendulum_mass, counting_force,
                                              pendulum_constraint, pendulum_jacobian, &p),
                             GA_OK);
            assert_int_equal(ga_init(x, 0.0, q, v), GA_OK);
            for (int i = 0; i < 5; ++i)
                assert_int_equal(ga_step(x, 0.01), GA_OK);
            // too few iterations for the tolerance: every attempt and fallback runs, and fails
            assert_int_equal(ga_set_newton(x, 1e-15, 1), GA_OK);
        }
        throw_at = 0;
        long long before = 0, after = 0;
        assert_int_equal(ga_get_counter(s[1], GA_COUNT_FORCE_EVALS, &before), GA_OK);
        assert_int_equal(ga_step(s[1], 0.01), GA_ERR_NEWTON);
        assert_int_equal(ga_get_counter(s[1], GA_COUNT_FORCE_EVALS, &after), GA_OK);
        calls = static_cast<int>(after - before);
        throw_at = k;
        assert_int_equal(ga_step(s[0], 0.01), GA_ERR_INTERNAL);
        throw_at = 0;
        double end[2][2];
        for (int i = 0; i < 2; ++i) {
            assert_int_equal(ga_set_newton(s[i], 1e-10, 20), GA_OK);
            for (int j = 0; j < 20; ++j)
                assert_int_equal(ga_step(s[i], 0.01), GA_OK);
            assert_int_equal(ga_get_q(s[i], end[i]), GA_OK);
            ga_free(s[i]);
        }
        if (std::memcmp(end[0], end[1], sizeof end[0]) != 0)
            fail_msg("thrown at force call %d of %d in the failing step: the run differs", k,
                     calls);
    }
    std::printf("  an exception at each of the %d force calls of a step's attempts and "
                "fallbacks: no option changed\n", calls);
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(exceptions_become_statuses),
                                       cmocka_unit_test(throwing_step_hook),
                                       cmocka_unit_test(exception_in_a_fallback_changes_no_option)};
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
