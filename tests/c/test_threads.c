/* Re-entrancy: no global mutable state. Solvers run in parallel threads give bit-identical
 * results to the same runs done one after the other, on the dense path (pendulum) and on the
 * sparse one (chains, adaptive index-2 steps). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"
#include "chain_solver.h"

enum { THREADS = 4, LEN = CKPT_PENDULUM };

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

/* The sparse path in parallel: chains of different lengths, KLU, adaptive steps of the
 * stabilized index-2 formulation (its sparse system, the error projection, the controller). */
typedef struct chain_job {
    int links;
    double *result;
    size_t len;
    ga_status status;
} chain_job;

static void *run_chain(void *arg)
{
    chain_job *j = arg;
    chain c = chain_make(j->links);
    double *q = malloc(sizeof(double) * 3 * (size_t)c.links);
    double *v = malloc(sizeof(double) * 3 * (size_t)c.links);
    chain_initial(&c, q, v);
    ga_solver *s = NULL;
    j->status = ga_create(3 * c.links, 2 * c.links, &s);
    if (!j->status)
        j->status = chain_declare_patterns(&c, s);
    if (!j->status)
        j->status = ga_set_callbacks(s, chain_mass, chain_force, chain_constraint,
                                     chain_jacobian, &c);
    if (!j->status)
        j->status = ga_set_tangents(s, chain_stiffness, NULL);
    if (!j->status)
        j->status = ga_set_formulation(s, GA_INDEX2_STABILIZED);
    if (!j->status)
        j->status = ga_set_tolerances(s, 1e-5, 1e-5);
    if (!j->status)
        j->status = ga_init(s, 0.0, q, v);
    if (!j->status)
        j->status = ga_advance(s, 0.2);
    if (!j->status)
        j->status = ga_state_size(s, &j->len);
    if (!j->status) {
        j->result = malloc(sizeof(double) * j->len);
        j->status = ga_get_state(s, j->result, j->len);
    }
    ga_free(s);
    free(q);
    free(v);
    return NULL;
}

static void parallel_sparse_adaptive_runs_equal_serial_runs(void **state)
{
    (void)state;
    chain_job serial[THREADS], parallel[THREADS];
    pthread_t th[THREADS];
    for (int i = 0; i < THREADS; ++i) {
        serial[i] = (chain_job){40 + 15 * i, NULL, 0, GA_OK};
        parallel[i] = serial[i];
        run_chain(&serial[i]);
        assert_int_equal(serial[i].status, GA_OK);
    }
    for (int i = 0; i < THREADS; ++i)
        assert_int_equal(pthread_create(&th[i], NULL, run_chain, &parallel[i]), 0);
    for (int i = 0; i < THREADS; ++i)
        assert_int_equal(pthread_join(th[i], NULL), 0);
    for (int i = 0; i < THREADS; ++i) {
        assert_int_equal(parallel[i].status, GA_OK);
        assert_int_equal(parallel[i].len, serial[i].len);
        assert_memory_equal(serial[i].result, parallel[i].result,
                            sizeof(double) * serial[i].len);
        free(serial[i].result);
        free(parallel[i].result);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(parallel_runs_equal_serial_runs),
        cmocka_unit_test(parallel_sparse_adaptive_runs_equal_serial_runs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
