/* Misuse: one solver called from two threads at once. Each call is let in or refused with
 * GA_ERR_STATE by an atomic guard (not under helgrind, which does not see the order an atomic
 * makes and would report the solver's state as raced on). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"

/* Two threads stepping one solver: every call steps or is refused, never both at once (the
 * guard was a plain bool, and 2 of 6 such runs corrupted the heap; issue 17). */
typedef struct shared {
    ga_solver *s;
    long ok, refused, other, silent;
} shared;
static void *hammer(void *arg)
{
    shared *sh = arg;
    for (int i = 0; i < 20000; ++i) {
        const ga_status st = ga_step(sh->s, 1e-5);
        if (st == GA_OK)
            ++sh->ok;
        else if (st == GA_ERR_STATE) {
            ++sh->refused;
            /* the message is the other call's: this thread is told why it was refused */
            if (!strstr(ga_last_error(sh->s), "call refused: another call holds this solver"))
                ++sh->silent;
        }
        else
            ++sh->other;
    }
    return NULL;
}
static void one_solver_in_two_threads_is_refused_not_shared(void **state)
{
    (void)state;
    pendulum p = {1.0, 1.0, 9.81};
    double q[2], v[2];
    pendulum_state(&p, 1.0, 0.5, q, v);
    ga_solver *s = pendulum_new_solver(&p, 0);
    assert_non_null(s);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    shared sh[2] = {{s, 0, 0, 0, 0}, {s, 0, 0, 0, 0}};
    pthread_t th[2];
    for (int i = 0; i < 2; ++i)
        assert_int_equal(pthread_create(&th[i], NULL, hammer, &sh[i]), 0);
    for (int i = 0; i < 2; ++i)
        assert_int_equal(pthread_join(th[i], NULL), 0);
    long long steps;
    assert_int_equal(ga_get_counter(s, GA_COUNT_STEPS, &steps), GA_OK);
    printf("  %ld and %ld steps taken, %ld and %ld refused\n", sh[0].ok, sh[1].ok, sh[0].refused,
           sh[1].refused);
    assert_int_equal(sh[0].other + sh[1].other, 0);
    assert_int_equal(sh[0].silent + sh[1].silent, 0);
    assert_true(sh[0].refused + sh[1].refused > 0);
    /* the owner's messages are its own again */
    assert_int_equal(ga_step(s, -1.0), GA_ERR_ARG);
    assert_non_null(strstr(ga_last_error(s), "step size"));
    assert_true(steps == sh[0].ok + sh[1].ok);
    assert_int_equal(ga_get_q(s, q), GA_OK);
    assert_true(isfinite(q[0]) && isfinite(q[1]));
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_solver_in_two_threads_is_refused_not_shared),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
