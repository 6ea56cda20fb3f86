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

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(exceptions_become_statuses),
                                       cmocka_unit_test(throwing_step_hook)};
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
