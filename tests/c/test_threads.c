/* Re-entrancy: no global mutable state. Solvers run in parallel threads give bit-identical
 * results to the same runs done one after the other. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <pthread.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"

enum { THREADS = 4, LEN = 9 + 5 * 2 + 1 };

typedef struct job {
    pendulum p;
    double theta0;
    double result[LEN];
    ga_status status;
} job;

static void *run(void *arg)
{
    job *j = arg;
    double q[2], v[2];
    ga_solver *s = NULL;
    j->status = ga_create(2, 1, &s);
    if (j->status)
        return NULL;
    pendulum_state(&j->p, j->theta0, 0.0, q, v);
    j->status = ga_set_callbacks(s, pendulum_mass, pendulum_force, pendulum_constraint,
                                 pendulum_jacobian, &j->p);
    if (!j->status)
        j->status = ga_set_tangent_mode(s, GA_TANGENT_FD);
    if (!j->status)
        j->status = ga_init(s, 0.0, q, v);
    for (int i = 0; i < 2000 && !j->status; ++i)
        j->status = ga_step(s, 5e-4);
    if (!j->status)
        j->status = ga_get_state(s, j->result, LEN);
    ga_free(s);
    return NULL;
}

static void parallel_runs_equal_serial_runs(void **state)
{
    (void)state;
    job serial[THREADS], parallel[THREADS];
    pthread_t th[THREADS];
    for (int i = 0; i < THREADS; ++i) {
        serial[i] = (job){{1.0 + i, 1.0 + 0.1 * i, 9.81}, 0.3 + 0.2 * i, {0}, GA_OK};
        parallel[i] = serial[i];
        run(&serial[i]);
        assert_int_equal(serial[i].status, GA_OK);
    }
    for (int i = 0; i < THREADS; ++i)
        assert_int_equal(pthread_create(&th[i], NULL, run, &parallel[i]), 0);
    for (int i = 0; i < THREADS; ++i)
        assert_int_equal(pthread_join(th[i], NULL), 0);
    for (int i = 0; i < THREADS; ++i) {
        assert_int_equal(parallel[i].status, GA_OK);
        assert_memory_equal(serial[i].result, parallel[i].result, sizeof serial[i].result);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(parallel_runs_equal_serial_runs)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
