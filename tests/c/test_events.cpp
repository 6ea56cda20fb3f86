// The event locator (src/events.hpp) on functions with known roots: the root found within its
// tolerance, 100 u (|t1| + |h|), behind the reported time; the earliest of several functions
// first, and the next from there; a root exactly at the end found once; directions obeyed;
// two functions with one root both reported; a steep and a flat function located in few
// evaluations; a failing evaluation returned as it is.
#include <cmath>
#include <cstdio>
#include <limits>

#include "events.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

const double kPi = 3.14159265358979323846;

// Event functions of t alone (the locator sees only values at times).
struct Functions {
    int count;
    double (*f[3])(double);
    int fail_after = -1;  // evaluations before a failure (-1: none)
    int calls = 0;
};

int evaluate(double t, double *g, void *context)
{
    auto *fs = static_cast<Functions *>(context);
    if (fs->fail_after >= 0 && fs->calls++ >= fs->fail_after)
        return -7;
    for (int k = 0; k < fs->count; ++k)
        g[k] = fs->f[k](t);
    return 0;
}

double tolerance(double t0, double t1)
{
    return 100.0 * std::numeric_limits<double>::epsilon() * (std::fabs(t1) + std::fabs(t1 - t0));
}

// locate on [t0, t1]; returns the locator's result
int run(ga::EventLocator &loc, Functions &fs, double t0, double t1, const int *direction,
        double *t_root, int *fired)
{
    double g0[3], g1[3];
    evaluate(t0, g0, &fs);
    evaluate(t1, g1, &fs);
    fs.calls = 0;
    return loc.locate(t0, g0, t1, g1, direction, evaluate, &fs, t_root, fired);
}

void one_root_is_located_behind_the_reported_time(void **)
{
    ga::EventLocator loc;
    loc.setup(1);
    Functions fs{1, {[](double t) { return std::sin(t) - 0.5; }}};
    const int both[] = {0};
    double t;
    int fired[1];
    assert_int_equal(run(loc, fs, 0.0, 1.0, both, &t, fired), 1);
    const double root = kPi / 6.0;
    std::printf("  sin t = 1/2: %.17g (root %.17g), %d evaluations\n", t, root,
                loc.last_evaluations());
    assert_true(t >= root && t - root <= tolerance(0.0, 1.0));
    assert_int_equal(fired[0], 1);
    assert_true(loc.last_evaluations() <= 12);
}

void the_earliest_first_then_the_next(void **)
{
    ga::EventLocator loc;
    loc.setup(2);
    Functions fs{2, {[](double t) { return 0.7 - t; }, [](double t) { return t * t - 0.09; }}};
    const int both[] = {0, 0};
    double t;
    int fired[2];
    assert_int_equal(run(loc, fs, 0.0, 1.0, both, &t, fired), 1);
    assert_true(t >= 0.3 && t - 0.3 <= tolerance(0.0, 1.0));
    assert_int_equal(fired[0], 0);
    assert_int_equal(fired[1], 1);
    /* the rest of the step, from the reported time */
    assert_int_equal(run(loc, fs, t, 1.0, both, &t, fired), 1);
    assert_true(t >= 0.7 && t - 0.7 <= tolerance(0.3, 1.0));
    assert_int_equal(fired[0], -1);
    assert_int_equal(fired[1], 0);
    assert_int_equal(run(loc, fs, t, 1.0, both, &t, fired), 0);
}

void directions_are_obeyed(void **)
{
    ga::EventLocator loc;
    loc.setup(1);
    Functions fs{1, {[](double t) { return std::cos(t); }}};  // falls through zero at pi/2
    double t;
    int fired[1];
    const int rising[] = {1}, falling[] = {-1};
    assert_int_equal(run(loc, fs, 0.0, 2.0, rising, &t, fired), 0);
    assert_int_equal(run(loc, fs, 0.0, 2.0, falling, &t, fired), 1);
    assert_true(t >= kPi / 2 && t - kPi / 2 <= tolerance(0.0, 2.0));
    assert_int_equal(fired[0], -1);
}

void a_root_at_the_end_is_found_once(void **)
{
    ga::EventLocator loc;
    loc.setup(1);
    Functions fs{1, {[](double t) { return t - 0.5; }}};
    const int both[] = {0};
    double t;
    int fired[1];
    assert_int_equal(run(loc, fs, 0.25, 0.5, both, &t, fired), 1);
    assert_true(t == 0.5);
    assert_int_equal(fired[0], 1);
    /* the next step starts where the function is zero: no new event */
    assert_int_equal(run(loc, fs, 0.5, 0.75, both, &t, fired), 0);
}

void one_root_of_two_functions_fires_both(void **)
{
    ga::EventLocator loc;
    loc.setup(3);
    Functions fs{3,
                 {[](double t) { return t - 0.4; }, [](double t) { return 2.0 * (0.4 - t); },
                  [](double t) { return t + 1.0; }}};
    const int both[] = {0, 0, 0};
    double t;
    int fired[3];
    assert_int_equal(run(loc, fs, 0.0, 1.0, both, &t, fired), 1);
    assert_true(t >= 0.4 && t - 0.4 <= tolerance(0.0, 1.0));
    assert_int_equal(fired[0], 1);
    assert_int_equal(fired[1], -1);
    assert_int_equal(fired[2], 0);
}

void steep_and_flat_functions_take_few_evaluations(void **)
{
    ga::EventLocator loc;
    loc.setup(1);
    const int both[] = {0};
    double t;
    int fired[1];
    // flat at the root (triple root of (t - 0.3)^3 + small slope): the plain secant crawls
    Functions flat{1, {[](double t) { return std::pow(t - 0.3, 3) + 1e-6 * (t - 0.3); }}};
    assert_int_equal(run(loc, flat, 0.0, 1.0, both, &t, fired), 1);
    std::printf("  flat: %d evaluations\n", loc.last_evaluations());
    assert_true(t >= 0.3 && t - 0.3 <= tolerance(0.0, 1.0));
    assert_true(loc.last_evaluations() <= 60);
    Functions steep{1, {[](double t) { return std::tanh(1e4 * (t - 0.61)); }}};
    assert_int_equal(run(loc, steep, 0.0, 1.0, both, &t, fired), 1);
    std::printf("  steep: %d evaluations\n", loc.last_evaluations());
    assert_true(std::fabs(t - 0.61) <= 2.0 * tolerance(0.0, 1.0));
    assert_true(loc.last_evaluations() <= 80);
}

void a_failing_evaluation_is_returned(void **)
{
    ga::EventLocator loc;
    loc.setup(1);
    Functions fs{1, {[](double t) { return t - 0.5; }}};
    fs.fail_after = 0;
    const int both[] = {0};
    double g0[1] = {-0.5}, g1[1] = {0.5}, t = -1.0;
    int fired[1] = {9};
    assert_int_equal(loc.locate(0.0, g0, 1.0, g1, both, evaluate, &fs, &t, fired), -7);
    assert_true(t == -1.0 && fired[0] == 9);  // nothing written
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_root_is_located_behind_the_reported_time),
        cmocka_unit_test(the_earliest_first_then_the_next),
        cmocka_unit_test(directions_are_obeyed),
        cmocka_unit_test(a_root_at_the_end_is_found_once),
        cmocka_unit_test(one_root_of_two_functions_fires_both),
        cmocka_unit_test(steep_and_flat_functions_take_few_evaluations),
        cmocka_unit_test(a_failing_evaluation_is_returned),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
