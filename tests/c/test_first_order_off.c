/* Zero first-order states declared are none, bit for bit (issue 19): runs of the shipped
 * scenes -- fixed steps in index 3 and 2, adaptive steps in index 2 -- with
 * ga_set_first_order(s, 0, ...) end in states whose FNV-1a hash over the bytes of (t, q, v,
 * qdd, lambda) and the work counters equals that of the same run without the call, made in
 * this process. (That the solver without them is the one before them was shown against hashes
 * recorded with galpha 912a78b, the last commit before first-order states, on the machine
 * that recorded them; such hashes are a compiler's and a CPU's bits, not a test for any
 * machine: scripts/golden.sh compares two commits on one.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "fnv.h"
#include "scene_catalog.h"

/* The counters galpha 912a78b had (the hash was first compared with that commit's). */
enum { kRuns = 3, kCountersBefore = 15 };


/* run 0: index 3, h = t_end / 200; run 1: index 2, the same h; run 2: index 2 adaptive,
 * rtol = atol = 1e-6 to t_end. */
static uint64_t run_hash(int scene, int run, int declare_zero)
{
    catalog_scene sc = catalog_make(scene);
    ga_solver *s = catalog_solver(&sc);
    assert_non_null(s);
    if (declare_zero)
        assert_int_equal(ga_set_first_order(s, 0, NULL, NULL), GA_OK);
    if (run > 0)
        assert_int_equal(ga_set_formulation(s, GA_INDEX2_STABILIZED), GA_OK);
    /* (its Phi_t would add to the constraint counters of 912a78b's index-3 runs) */
    assert_int_equal(ga_set_resolution_check(s, INFINITY), GA_OK);
    assert_int_equal(ga_init(s, 0.0, sc.q0, sc.v0), GA_OK);
    if (run < 2) {
        const double h = sc.t_end / 200;
        for (int k = 0; k < 200; ++k)
            assert_int_equal(ga_step(s, h), GA_OK);
    } else {
        assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
        assert_int_equal(ga_advance(s, sc.t_end), GA_OK);
    }
    const int n = sc.n, m = sc.m;
    double t, q[kCatalogMaxN], v[kCatalogMaxN], qdd[kCatalogMaxN], lambda[kCatalogMaxN];
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_int_equal(ga_get_q(s, q), GA_OK);
    assert_int_equal(ga_get_v(s, v), GA_OK);
    assert_int_equal(ga_get_qdd(s, qdd), GA_OK);
    assert_int_equal(ga_get_lambda(s, lambda), GA_OK);
    long long counters[kCountersBefore];
    for (int k = 0; k < kCountersBefore; ++k)
        assert_int_equal(ga_get_counter(s, k, &counters[k]), GA_OK);
    uint64_t hash = 14695981039346656037ull;
    hash = fnv(hash, &t, sizeof t);
    hash = fnv(hash, q, sizeof(double) * (size_t)n);
    hash = fnv(hash, v, sizeof(double) * (size_t)n);
    hash = fnv(hash, qdd, sizeof(double) * (size_t)n);
    hash = fnv(hash, lambda, sizeof(double) * (size_t)m);
    hash = fnv(hash, counters, sizeof counters);
    ga_free(s);
    return hash;
}

static void zero_states_are_none(void **state)
{
    (void)state;
    for (int sc = 0; sc < kCatalogScenes; ++sc)
        for (int run = 0; run < kRuns; ++run) {
            const uint64_t without = run_hash(sc, run, 0), declared = run_hash(sc, run, 1);
            if (without != declared)
                print_error("%s run %d: hash %016llx with zero states declared, %016llx without\n",
                            catalog_make(sc).name, run, (unsigned long long)declared,
                            (unsigned long long)without);
            assert_true(without == declared);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(zero_states_are_none)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
