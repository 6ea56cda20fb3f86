/* Checkpoint and restart: taking a checkpoint changes nothing (the same run, the same work),
 * and a run restored from it (in a new solver, or in the same one rewound) repeats the run it
 * came from bit for bit, with fixed or adaptive steps, from a checkpoint taken before the
 * first step too; on the sparse path as well, in both formulations. The checkpoint carries
 * what rebuilds the kept iteration matrix and the LU's pivots. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdlib.h>
#include <string.h>

#include <galpha.h>

#include "helpers.h"
#include "chain_solver.h"

enum { LEN = CKPT_PENDULUM };
static pendulum P = {1.0, 1.0, 9.81};

static ga_solver *make(void)
{
    ga_solver *s = pendulum_new_solver(&P, 0);
    assert_non_null(s);
    assert_int_equal(ga_set_rho_inf(s, 0.7), GA_OK);
    return s;
}

/* k fixed steps of 3e-3, or (adaptive) k adaptive steps at rtol = atol = 1e-6 */
static void steps(ga_solver *s, int k)
{
    for (int i = 0; i < k; ++i)
        assert_int_equal(ga_step(s, 3e-3), GA_OK);
}
static void adaptive_steps(ga_solver *s, int k)
{
    for (int i = 0; i < k; ++i)
        assert_int_equal(ga_step_adaptive(s, 100.0), GA_OK);
}

/* Checkpoint after `before` steps (0: right after ga_init, where the first step still owes
 * the corrected start), 150 more steps in the solver and in a new one restored from it. */
static void restart_in_new_solver(int before, int adaptive)
{
    double q[2], v[2], ckpt[LEN], a[LEN], b[LEN];
    size_t len = 0;
    void (*advance)(ga_solver *, int) = adaptive ? adaptive_steps : steps;
    pendulum_state(&P, 1.2, 0.8, q, v); /* moving: at rest the start correction vanishes */
    ga_solver *s = make();
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    assert_int_equal(len, LEN);
    advance(s, before);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    double h_before = -1.0;
    assert_int_equal(ga_get_h_last(s, &h_before), GA_OK);
    advance(s, 150);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);

    ga_solver *r = make(); /* never initialized: set_state makes it ready */
    assert_int_equal(ga_set_tolerances(r, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_set_state(r, ckpt, LEN), GA_OK);
    double h_last = -1.0;
    assert_int_equal(ga_get_h_last(r, &h_last), GA_OK);
    assert_true(h_last == h_before && (before > 0) == (h_last > 0.0));
    advance(r, 150);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_memory_equal(a, b, sizeof a);
    ga_free(s);
    ga_free(r);
}

static void restart_in_new_solver_is_bit_identical(void **state)
{
    (void)state;
    for (int adaptive = 0; adaptive < 2; ++adaptive) {
        restart_in_new_solver(100, adaptive);
        restart_in_new_solver(0, adaptive);
    }
}

static void rewind_same_solver_is_bit_identical(void **state)
{
    (void)state;
    double q[2], v[2], ckpt[LEN], a[LEN], b[LEN];
    pendulum_state(&P, -0.7, 2.0, q, v);
    ga_solver *s = make();
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    steps(s, 40);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    steps(s, 60);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);
    assert_int_equal(ga_set_state(s, ckpt, LEN), GA_OK);
    steps(s, 60);
    assert_int_equal(ga_get_state(s, b, LEN), GA_OK);
    assert_memory_equal(a, b, sizeof a);
    ga_free(s);
}

/* A 30-link chain on the sparse path (KLU), exact tangents, index 3 or stabilized index 2,
 * fixed or adaptive steps: checkpoint after 5 steps, 30 more in the solver, in a new one
 * restored from the checkpoint, and in the first one rewound to it: the same states, and the
 * same work (the restored solvers reuse the rebuilt matrix as the first one reuses its own).
 * Without the pivots in the checkpoint, the new solver would refactorize with pivots chosen
 * from another matrix, and the runs would part at round-off. */
static void sparse_restart(int formulation, int adaptive, int sliver_first)
{
    chain c = chain_make(30);
    const int n = 3 * c.links;
    double q[3 * 30], v[3 * 30];
    chain_initial(&c, q, v);
    ga_solver *s[2];
    for (int i = 0; i < 2; ++i) {
        s[i] = chain_solver(&c, 1);
        assert_int_equal(ga_set_linear_solver(s[i], GA_LINEAR_SPARSE), GA_OK);
        assert_int_equal(ga_set_formulation(s[i], formulation), GA_OK);
        assert_int_equal(ga_set_tolerances(s[i], 1e-5, 1e-7), GA_OK);
    }
    void (*advance)(ga_solver *, int) = adaptive ? adaptive_steps : steps;
    assert_int_equal(ga_init(s[0], 0.0, q, v), GA_OK);
    assert_true(strstr(ga_linear_solver_name(s[0]), "sparse KLU") != NULL);
    advance(s[0], 5);
    size_t len = 0;
    assert_int_equal(ga_state_size(s[0], &len), GA_OK);
    /* 21 + 11n + 2m, and pivot blocks of 4 + 2N for N = n + m (three) and 2n + 2m */
    assert_int_equal(len, 37 + 21 * (size_t)n + 13 * 2 * (size_t)c.links);
    double *ckpt = malloc(3 * len * sizeof(double)), *a = ckpt + len, *b = a + len;
    assert_non_null(ckpt);
    assert_int_equal(ga_get_state(s[0], ckpt, len), GA_OK);
    long long work[2][3];
    assert_int_equal(ga_reset_counters(s[0]), GA_OK);
    if (sliver_first)
        assert_int_equal(ga_step(s[0], 1e-12), GA_OK);
    advance(s[0], 30);
    assert_int_equal(ga_get_state(s[0], a, len), GA_OK);

    assert_int_equal(ga_set_state(s[1], ckpt, len), GA_OK); /* a new solver */
    assert_int_equal(ga_reset_counters(s[1]), GA_OK);
    if (sliver_first)
        assert_int_equal(ga_step(s[1], 1e-12), GA_OK);
    advance(s[1], 30);
    assert_int_equal(ga_get_state(s[1], b, len), GA_OK);
    assert_memory_equal(a, b, len * sizeof(double));
    for (int i = 0; i < 2; ++i) {
        ga_get_counter(s[i], GA_COUNT_FACTORIZATIONS, &work[i][0]);
        ga_get_counter(s[i], GA_COUNT_NEWTON_ITERS, &work[i][1]);
        ga_get_counter(s[i], GA_COUNT_RESIDUALS, &work[i][2]);
    }
    assert_memory_equal(work[0], work[1], sizeof work[0]);

    assert_int_equal(ga_set_state(s[0], ckpt, len), GA_OK); /* the first one, rewound */
    if (sliver_first)
        assert_int_equal(ga_step(s[0], 1e-12), GA_OK);
    advance(s[0], 30);
    assert_int_equal(ga_get_state(s[0], b, len), GA_OK);
    assert_memory_equal(a, b, len * sizeof(double));
    free(ckpt);
    ga_free(s[0]);
    ga_free(s[1]);
}

static void sparse_restart_is_bit_identical(void **state)
{
    (void)state;
    for (int adaptive = 0; adaptive < 2; ++adaptive) {
        sparse_restart(GA_INDEX3, adaptive, 0);
        sparse_restart(GA_INDEX2_STABILIZED, adaptive, 0);
    }
    /* a sliver first (a Taylor step whose accelerations come from a KKT factorization: that
     * one too picks its pivots afresh in both solvers) */
    sparse_restart(GA_INDEX3, 0, 1);
    sparse_restart(GA_INDEX2_STABILIZED, 0, 1);
}

/* The auxiliary vector a is part of the state: restarting with a = qdd instead (what a host
 * that saved only q, v, qdd would do) does not continue the same trajectory. This is why the
 * checkpoint carries a. */
static void checkpoint_without_a_would_not_restart_exactly(void **state)
{
    (void)state;
    double q[2], v[2], ckpt[LEN], a[LEN], b[LEN];
    pendulum_state(&P, 1.2, 0.0, q, v);
    ga_solver *s = make();
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    steps(s, 50);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    steps(s, 10);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);
    memcpy(ckpt + CKPT_HEADER + 3 * 2 + 1, ckpt + CKPT_HEADER + 2 * 2, 2 * sizeof(double)); /* a := qdd */
    assert_int_equal(ga_set_state(s, ckpt, LEN), GA_OK);
    steps(s, 10);
    assert_int_equal(ga_get_state(s, b, LEN), GA_OK);
    assert_true(max_abs_diff(a + CKPT_HEADER, b + CKPT_HEADER, 2) > 0.0);
    ga_free(s);
}

/* A checkpoint between slivers (steps over 100 times shorter than the one before) carries how
 * much time they spanned: restored, the same next short step is a Taylor step or a step of
 * Algorithm 1 as in the run it came from. Read as layout 2 (that span dropped), the restored
 * run takes one more Taylor step and parts from the run. */
static void restart_between_slivers_is_bit_identical(void **state)
{
    (void)state;
    double q[2], v[2], ckpt[LEN], old[LEN], a[LEN], b[LEN];
    pendulum_state(&P, 1.2, 0.8, q, v);
    ga_solver *s = make();
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    steps(s, 20);
    for (int k = 0; k < 10; ++k) /* 10 slivers of 3e-6 span 3e-5, 1/100 of 3e-3 */
        assert_int_equal(ga_step(s, 3e-6), GA_OK);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    assert_true(ckpt[9] > 2.9e-5);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(s, 3e-6), GA_OK);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);

    ga_solver *r = make();
    assert_int_equal(ga_set_state(r, ckpt, LEN), GA_OK);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(r, 3e-6), GA_OK);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_memory_equal(a, b, sizeof a);

    assert_int_equal(ga_set_state(r, old, ckpt_as_layout2(ckpt, old)), GA_OK);
    for (int k = 0; k < 100; ++k)
        assert_int_equal(ga_step(r, 3e-6), GA_OK);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_true(max_abs_diff(a + CKPT_HEADER, b + CKPT_HEADER, 2) > 0.0);
    ga_free(s);
    ga_free(r);
}

/* Taking a checkpoint only reads: runs with and without one after every step are the same
 * run with the same work, dense and sparse, both formulations, exact and finite-difference
 * tangents, fixed and adaptive steps. (Taking one dropped the kept matrix and the pivots:
 * on a 1 000-link chain 15 % more time per 10-step interval, and the trajectory moved.) And a
 * new solver restored from the checkpoint of step 20 repeats steps 21-40 with the same work. */
static void taking_checkpoints_changes_nothing(void **state)
{
    (void)state;
    chain c = chain_make(20);
    double q[3 * 20], v[3 * 20];
    chain_initial(&c, q, v);
    for (int config = 0; config < 16; ++config) {
        const int sparse = config & 1, formulation = config & 2 ? GA_INDEX2_STABILIZED : GA_INDEX3;
        const int adaptive = (config & 4) != 0, exact = (config & 8) == 0;
        ga_solver *s[3];
        size_t len = 0;
        for (int i = 0; i < 3; ++i) {
            s[i] = chain_solver(&c, exact);
            assert_int_equal(ga_set_linear_solver(s[i], sparse ? GA_LINEAR_SPARSE
                                                               : GA_LINEAR_DENSE),
                             GA_OK);
            assert_int_equal(ga_set_formulation(s[i], formulation), GA_OK);
            assert_int_equal(ga_set_tolerances(s[i], 1e-5, 1e-7), GA_OK);
            if (i < 2)
                assert_int_equal(ga_init(s[i], 0.0, q, v), GA_OK);
        }
        assert_int_equal(ga_state_size(s[0], &len), GA_OK);
        double *buf = malloc(3 * len * sizeof(double)), *a = buf + len, *b = a + len;
        assert_non_null(buf);
        long long at_20[GA_COUNTER_COUNT];
        for (int k = 0; k < 40; ++k) {
            for (int i = 0; i < 2; ++i)
                assert_int_equal(adaptive ? ga_step_adaptive(s[i], 100.0) : ga_step(s[i], 3e-3),
                                 GA_OK);
            assert_int_equal(ga_get_state(s[1], buf, len), GA_OK);
            if (k == 19) {
                assert_int_equal(ga_set_state(s[2], buf, len), GA_OK);
                assert_int_equal(ga_reset_counters(s[2]), GA_OK);
                for (int key = 0; key < GA_COUNTER_COUNT; ++key)
                    ga_get_counter(s[1], key, &at_20[key]);
            } else if (k >= 20) {
                assert_int_equal(adaptive ? ga_step_adaptive(s[2], 100.0) : ga_step(s[2], 3e-3),
                                 GA_OK);
            }
        }
        assert_int_equal(ga_get_state(s[0], a, len), GA_OK);
        assert_int_equal(ga_get_state(s[1], b, len), GA_OK);
        assert_memory_equal(a, b, len * sizeof(double));
        assert_int_equal(ga_get_state(s[2], b, len), GA_OK);
        assert_memory_equal(a, b, len * sizeof(double));
        for (int key = 0; key < GA_COUNTER_COUNT; ++key) {
            long long x, y, z;
            ga_get_counter(s[0], key, &x);
            ga_get_counter(s[1], key, &y);
            ga_get_counter(s[2], key, &z);
            assert_int_equal(x, y);
            assert_int_equal(z, y - at_20[key]);
        }
        free(buf);
        for (int i = 0; i < 3; ++i)
            ga_free(s[i]);
    }
}

/* A mass callback that fails while `fail` is set. */
static int fail_mass;
static int failing_mass(double t, const double *q, double *M, void *user)
{
    return fail_mass ? 1 : pendulum_mass(t, q, M, user);
}

/* Restoring rebuilds the kept matrix from the callbacks. Should one fail there, ga_set_state
 * still succeeds, keeps no matrix, and the run goes on as one restored as a restart (the
 * layout-2 form of the same checkpoint) does, bit for bit. */
static void failed_rebuild_restores_as_a_restart(void **state)
{
    (void)state;
    double q[2], v[2], ckpt[LEN], c2[LEN], a[LEN], b[LEN];
    pendulum_state(&P, 1.2, 0.8, q, v);
    ga_solver *s = make();
    assert_int_equal(ga_set_callbacks(s, failing_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &P),
                     GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    steps(s, 30);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    assert_true(ckpt[10] == 1.0); /* modified Newton keeps a matrix after 30 steps */
    const size_t len2 = ckpt_as_layout2(ckpt, c2);

    ga_solver *r = make();
    assert_int_equal(ga_set_callbacks(r, failing_mass, pendulum_force, pendulum_constraint,
                                      pendulum_jacobian, &P),
                     GA_OK);
    fail_mass = 1;
    assert_int_equal(ga_set_state(r, ckpt, LEN), GA_OK);
    fail_mass = 0;
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_true(b[10] == 0.0);
    assert_true(ckpt_same_state(ckpt, b));
    steps(r, 50);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);

    assert_int_equal(ga_set_state(s, c2, len2), GA_OK);
    steps(s, 50);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);
    assert_memory_equal(a, b, sizeof a);
    ga_free(s);
    ga_free(r);
}

/* A step that factorizes and then fails (Newton's iteration limit) keeps no matrix, and its
 * checkpoint holds nothing of the failed attempt's recipe: the same state, the same
 * checkpoint, as the one a solver restored from it gives back. */
static void failed_step_leaves_no_recipe_in_the_checkpoint(void **state)
{
    (void)state;
    double q[2], v[2], a[LEN], b[LEN];
    pendulum_state(&P, 1.2, 0.8, q, v);
    ga_solver *s = make();
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    steps(s, 30);
    assert_int_equal(ga_set_jacobian_reuse(s, GA_REUSE_NEVER), GA_OK);
    assert_int_equal(ga_set_newton(s, 1e-14, 1), GA_OK);
    assert_int_equal(ga_step(s, 0.2), GA_ERR_NEWTON);
    assert_int_equal(ga_get_state(s, a, LEN), GA_OK);
    assert_true(a[10] == 0.0); /* no kept matrix */
    for (int i = 11; i < 15; ++i)
        assert_true(a[i] == 0.0); /* and no recipe time, step or tangents */
    ga_solver *r = make();
    assert_int_equal(ga_set_jacobian_reuse(r, GA_REUSE_NEVER), GA_OK);
    assert_int_equal(ga_set_newton(r, 1e-14, 1), GA_OK);
    assert_int_equal(ga_set_state(r, a, LEN), GA_OK);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_memory_equal(a, b, sizeof a);
    ga_free(s);
    ga_free(r);
}

/* The restart after a jump (an impact law, a switched force): ga_init on a running solver, at
 * a new state, continues exactly as a new solver with the same options started there does,
 * dense and sparse, index 3 and 2, fixed and adaptive steps (nothing of the run before is
 * kept: not the step-size history, the kept matrix, nor the sparse pivots). */
static void restart_after_a_jump_is_a_new_solver(void **state)
{
    (void)state;
    chain c = chain_make(20);
    enum { NQ = 3 * 20 };
    double q[NQ], v[NQ];
    chain_initial(&c, q, v);
    for (int config = 0; config < 8; ++config) {
        const int sparse = config & 1, formulation = config & 2 ? GA_INDEX2_STABILIZED : GA_INDEX3;
        const int adaptive = (config & 4) != 0;
        ga_solver *s[2];
        for (int i = 0; i < 2; ++i) {
            s[i] = chain_solver(&c, 1);
            assert_int_equal(ga_set_linear_solver(s[i], sparse ? GA_LINEAR_SPARSE
                                                               : GA_LINEAR_DENSE),
                             GA_OK);
            assert_int_equal(ga_set_formulation(s[i], formulation), GA_OK);
            assert_int_equal(ga_set_tolerances(s[i], 1e-5, 1e-7), GA_OK);
        }
        assert_int_equal(ga_init(s[0], 0.0, q, v), GA_OK);
        for (int k = 0; k < 20; ++k)
            assert_int_equal(adaptive ? ga_step_adaptive(s[0], 100.0) : ga_step(s[0], 3e-3),
                             GA_OK);
        /* the jump: velocities reversed and halved, one position nudged off the constraints */
        double t, qj[NQ], vj[NQ];
        assert_int_equal(ga_get_t(s[0], &t), GA_OK);
        assert_int_equal(ga_get_q(s[0], qj), GA_OK);
        assert_int_equal(ga_get_v(s[0], vj), GA_OK);
        for (int i = 0; i < NQ; ++i)
            vj[i] *= -0.5;
        qj[4] += 1e-3;
        for (int i = 0; i < 2; ++i)
            assert_int_equal(ga_init(s[i], t, qj, vj), GA_OK);
        for (int k = 0; k < 20; ++k)
            for (int i = 0; i < 2; ++i)
                assert_int_equal(adaptive ? ga_step_adaptive(s[i], 100.0) : ga_step(s[i], 3e-3),
                                 GA_OK);
        size_t len = 0;
        assert_int_equal(ga_state_size(s[0], &len), GA_OK);
        double *a = malloc(2 * len * sizeof(double)), *b = a + len;
        assert_non_null(a);
        assert_int_equal(ga_get_state(s[0], a, len), GA_OK);
        assert_int_equal(ga_get_state(s[1], b, len), GA_OK);
        assert_memory_equal(a, b, len * sizeof(double));
        free(a);
        for (int i = 0; i < 2; ++i)
            ga_free(s[i]);
    }
}

/* A layout-3 checkpoint (before the index-3 error estimate kept consistent accelerations) is
 * read as the same state with none of them: the estimate falls back to differences of a for
 * one step, knows one after it and two after the next, and the run ends where the run it came
 * from ends, within its tolerance. */
static void layout3_is_read_without_consistent_accelerations(void **state)
{
    (void)state;
    double q[2], v[2], ckpt[LEN], old[LEN], b[LEN], qa[2], qb[2], t;
    pendulum_state(&P, 1.2, 0.8, q, v);
    ga_solver *s = make(), *r = make();
    assert_int_equal(ga_set_tolerances(s, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_set_tolerances(r, 1e-6, 1e-6), GA_OK);
    assert_int_equal(ga_init(s, 0.0, q, v), GA_OK);
    adaptive_steps(s, 50);
    assert_int_equal(ga_get_state(s, ckpt, LEN), GA_OK);
    assert_true(ckpt[19] == 2.0 && ckpt[20] > 0.0);
    const size_t len3 = ckpt_as_layout3(ckpt, LEN, old);
    assert_int_equal(len3, LEN - 6);
    assert_int_equal(ga_set_state(r, old, len3 - 1), GA_ERR_ARG);
    assert_int_equal(ga_set_state(r, old, len3), GA_OK);
    assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
    assert_memory_equal(b, ckpt, 19 * sizeof(double));
    assert_true(b[19] == 0.0 && b[20] == 0.0);
    assert_memory_equal(b + CKPT_HEADER, ckpt + CKPT_HEADER, 11 * sizeof(double));
    for (int k = 1; k <= 2; ++k) {
        adaptive_steps(r, 1);
        assert_int_equal(ga_get_state(r, b, LEN), GA_OK);
        assert_true(b[19] == (double)k);
    }
    assert_int_equal(ga_get_t(s, &t), GA_OK);
    assert_int_equal(ga_advance(s, t + 1.0), GA_OK);
    assert_int_equal(ga_advance(r, t + 1.0), GA_OK);
    assert_int_equal(ga_get_q(s, qa), GA_OK);
    assert_int_equal(ga_get_q(r, qb), GA_OK);
    assert_true(max_abs_diff(qa, qb, 2) > 0.0 && max_abs_diff(qa, qb, 2) < 1e-5);
    ga_free(s);
    ga_free(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(restart_in_new_solver_is_bit_identical),
        cmocka_unit_test(rewind_same_solver_is_bit_identical),
        cmocka_unit_test(sparse_restart_is_bit_identical),
        cmocka_unit_test(checkpoint_without_a_would_not_restart_exactly),
        cmocka_unit_test(restart_between_slivers_is_bit_identical),
        cmocka_unit_test(taking_checkpoints_changes_nothing),
        cmocka_unit_test(failed_rebuild_restores_as_a_restart),
        cmocka_unit_test(failed_step_leaves_no_recipe_in_the_checkpoint),
        cmocka_unit_test(restart_after_a_jump_is_a_new_solver),
        cmocka_unit_test(layout3_is_read_without_consistent_accelerations),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
