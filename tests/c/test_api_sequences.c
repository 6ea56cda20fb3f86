/* Random sequences of C API calls, as a careless or hurried host program makes them: options
 * set before and after ga_init, out-of-range and non-finite arguments, steps of every size,
 * checkpoints restored with a corrupted entry or the wrong length, and callbacks that fail at a
 * random call (returning > 0 or < 0, writing a NaN, an Inf or 1e300 into their output, or
 * calling ga_step on their own solver). test_errors.c pins each failure's status and message;
 * test_fault_sweep.c sweeps failures over the calls of one step; this suite checks what must hold
 * whatever the order of calls (and runs under ASan, UBSan and valgrind with the others):
 *   - every call returns GA_OK or one of the ga_status codes;
 *   - every failed call that may change the solver leaves a message (ga_last_error);
 *   - a failed ga_step or ga_step_adaptive leaves t, q, v, qdd, a and lambda bit-identical;
 *   - a callback's call of ga_step on its own solver is refused with GA_ERR_STATE;
 *   - a checkpoint restored in the solver it came from repeats the steps taken after it, bit
 *     for bit (the restart twin).
 * Models: planar chains of 1 to 3 links in Cartesian coordinates (n = 2, 4 or 6; a constraint
 * per link), the same with the first constraint stated twice (one redundant), and free
 * particles (none); each of them also with a free rotor on a group block (ga_create_space: a
 * quaternion, a rotation matrix or an SE(3) pose);
 * a third of the runs declare sparsity patterns and take the sparse path, and pattern
 * declarations (valid ones, and invalid ones that must be refused) come at random too.
 * Every function of the header is called (events and events on y, first-order states and
 * their coupling, sensitivities with their starts and derivative callbacks, the adjoint with
 * running and terminal costs and checkpointing, the step hook, the resolution check), and
 * every callback kind can fail. ga_advance runs over short intervals with h_min raised to a
 * 256th of them (the limits drawn here could make it take millions of steps); a failed one
 * keeps the steps it accepted, so t must lie between where it was and t_out.
 * (The harness grew in issue 34: the committed fuzzer findings are replayed as inputs of the
 * present harness; the defects they once found each have a test of their own.) */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>

#define SEQ_FAIL(...) fail_msg(__VA_ARGS__)
#define SEQ_REQUIRE(cond) assert_true(cond)
#include "api_sequence.h"

enum { SEQUENCES = 20000, ROTOR_SEQUENCES = 6000 };

static void random_call_sequences_keep_the_contract(void **state)
{
    (void)state;
    seq_stats stats = {0};
    for (int seq = 0; seq < SEQUENCES; ++seq)
        run_sequence(seq, NULL, 0, &stats, 0);
    const long long steps_ok = stats.steps_ok, sparse_ok = stats.sparse_ok;
    printf("  %d sequences, %lld calls, %lld accepted steps (%lld on the sparse path, %lld with "
           "sensitivities), %lld steps repeated from a restored checkpoint, %lld stops at "
           "events, %lld adjoint sweeps, %lld step hook calls, %lld stops by it, %lld "
           "ga_advance calls that reached t_out, %lld operating-point calls with GA_OK\n",
           SEQUENCES, stats.calls, steps_ok, sparse_ok, stats.sensitivity_steps_ok,
           stats.twin_steps_ok, stats.events, stats.adjoint_ok, stats.hook_calls, stats.hook_stops,
           stats.advance_ok, stats.operating_points_ok);
    /* the sequences must reach the stepping code, dense and sparse, not only the checks of
     * arguments and of the call order */
    assert_true(steps_ok > SEQUENCES / 2);
    assert_true(sparse_ok > SEQUENCES / 100);
    assert_true(stats.twin_steps_ok > SEQUENCES / 100);
    assert_true(stats.events > SEQUENCES / 400); /* few sequences step far; some must stop */
    assert_true(stats.sensitivity_steps_ok > SEQUENCES / 100);
    assert_true(stats.adjoint_ok > SEQUENCES / 400);
    assert_true(stats.hook_calls > SEQUENCES / 10 && stats.hook_stops > SEQUENCES / 400);
    assert_true(stats.advance_ok > SEQUENCES / 100);
    assert_true(stats.operating_points_ok > SEQUENCES / 100);
}

/* The same contract with a rotor on a group block beside the chain (a quaternion, a rotation
 * matrix or an SE(3) pose): the group's step, its sparse path, checkpoints, events,
 * sensitivities and the adjoint under the same careless calls. */
static void random_call_sequences_with_a_rotor_keep_the_contract(void **state)
{
    (void)state;
    seq_stats stats = {0};
    for (int seq = 0; seq < ROTOR_SEQUENCES; ++seq)
        run_sequence(SEQUENCES + seq, NULL, 0, &stats, 1);
    printf("  %d sequences with a rotor, %lld calls, %lld accepted steps (%lld on the sparse "
           "path, %lld with sensitivities), %lld steps repeated from a restored checkpoint, "
           "%lld stops at events, %lld adjoint sweeps\n",
           ROTOR_SEQUENCES, stats.calls, stats.steps_ok, stats.sparse_ok,
           stats.sensitivity_steps_ok, stats.twin_steps_ok, stats.events, stats.adjoint_ok);
    assert_true(stats.steps_ok > ROTOR_SEQUENCES / 2);
    assert_true(stats.sparse_ok > ROTOR_SEQUENCES / 100);
    assert_true(stats.twin_steps_ok > ROTOR_SEQUENCES / 100);
    assert_true(stats.events > ROTOR_SEQUENCES / 400);
    assert_true(stats.sensitivity_steps_ok > ROTOR_SEQUENCES / 100);
    assert_true(stats.adjoint_ok > ROTOR_SEQUENCES / 400);
}

/* The sequences' model is exact: for every chain length, with and without the redundant
 * constraint, dense and in its patterns, Phi_q, K_t = d(Phi_q^T lambda)/dq and Phi_qq(v, v)
 * agree with central differences of Phi and of Phi_q. */
static void model_derivatives_agree_with_differences(void **state)
{
    (void)state;
    const double eps = 1e-6;
    for (int links = 1; links <= MAX_LINKS; ++links)
        for (int redundant = 0; redundant < 2; ++redundant)
            for (int sparse = 0; sparse < 2; ++sparse) {
                model md = {0};
                model_shape(&md, links, links + redundant);
                md.sparse_J = md.sparse_K = sparse;
                const int n = md.n, m = md.m;
                double q[NMAX], v[NMAX], lambda[MMAX], J[MMAX * NMAX], K[NMAX * NMAX];
                double Jd[MMAX * NMAX] = {0}, Kd[NMAX * NMAX] = {0}, out[MMAX];
                for (int i = 0; i < n; ++i)
                    q[i] = 0.3 * i + 0.1 * (i % 2), v[i] = 0.7 - 0.2 * i;
                for (int k = 0; k < m; ++k)
                    lambda[k] = 1.0 + k;
                assert_int_equal(jacobian(0.0, q, J, &md), 0);
                assert_int_equal(stiffness(0.0, q, v, v, lambda, K, &md), 0);
                if (sparse) { /* scatter the values into dense matrices */
                    for (int e = 0; e < md.j_nnz; ++e)
                        Jd[md.j_rows[e] + md.j_cols[e] * m] = J[e];
                    for (int e = 0; e < md.k_nnz; ++e)
                        Kd[md.k_rows[e] + md.k_cols[e] * n] = K[e];
                } else {
                    memcpy(Jd, J, sizeof(double) * (size_t)(m * n));
                    memcpy(Kd, K, sizeof(double) * (size_t)(n * n));
                }
                md.sparse_J = 0; /* differences of the dense Phi_q */
                for (int j = 0; j < n; ++j) {
                    double qp[NMAX], qm[NMAX], pp[MMAX], pm[MMAX];
                    double Jp[MMAX * NMAX], Jm[MMAX * NMAX];
                    memcpy(qp, q, sizeof qp);
                    memcpy(qm, q, sizeof qm);
                    qp[j] += eps;
                    qm[j] -= eps;
                    constraint(0.0, qp, pp, &md);
                    constraint(0.0, qm, pm, &md);
                    jacobian(0.0, qp, Jp, &md);
                    jacobian(0.0, qm, Jm, &md);
                    for (int k = 0; k < m; ++k)
                        assert_true(fabs((pp[k] - pm[k]) / (2 * eps) - Jd[k + j * m]) < 1e-8);
                    for (int i = 0; i < n; ++i) { /* column j of d(J^T lambda)/dq, row i */
                        double d = 0.0;
                        for (int k = 0; k < m; ++k)
                            d += (Jp[k + i * m] - Jm[k + i * m]) / (2 * eps) * lambda[k];
                        assert_true(fabs(d - Kd[i + j * n]) < 1e-8);
                    }
                }
                /* Phi_qq(v, v) = d/ds (Phi_q(q + s v) v) at s = 0 */
                double qp[NMAX], qm[NMAX], Jp[MMAX * NMAX], Jm[MMAX * NMAX];
                for (int i = 0; i < n; ++i)
                    qp[i] = q[i] + eps * v[i], qm[i] = q[i] - eps * v[i];
                jacobian(0.0, qp, Jp, &md);
                jacobian(0.0, qm, Jm, &md);
                assert_int_equal(accel(0.0, q, v, out, &md), 0);
                for (int k = 0; k < m; ++k) {
                    double d = 0.0;
                    for (int i = 0; i < n; ++i)
                        d += (Jp[k + i * m] - Jm[k + i * m]) / (2 * eps) * v[i];
                    assert_true(fabs(d - out[k]) < 1e-8);
                }
            }
}

/* The inputs on which the fuzzer (tests/fuzz/fuzz_api.c) once found a defect, replayed. */
static void fuzzer_findings_stay_fixed(void **state)
{
    (void)state;
    DIR *dir = opendir(GALPHA_FUZZ_REGRESSIONS);
    assert_non_null(dir);
    int replayed = 0;
    for (struct dirent *e; (e = readdir(dir)) != NULL;) {
        if (e->d_name[0] == '.')
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", GALPHA_FUZZ_REGRESSIONS, e->d_name);
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        static uint8_t data[1 << 16];
        const size_t size = fread(data, 1, sizeof data, f);
        fclose(f);
        seq_stats stats = {0};
        run_sequence(0, data, size, &stats, 0);
        run_sequence(0, data, size, &stats, 1);
        ++replayed;
    }
    closedir(dir);
    printf("  %d inputs replayed\n", replayed);
    assert_true(replayed > 0);
}

/* The first fuzzer finding of the checkpoint defect, as a plain sequence: a fixed step of h = 1
 * whose Newton iteration diverged before it converged, then an adaptive step whose first try
 * is a sliver (a Taylor step, no iteration). The sliver's error estimate read the diverged
 * verdict of that earlier iteration, which a checkpoint does not carry: restored, the same
 * adaptive step took another error and another h (9.5449e-4 instead of 9.5436e-4). */
static void a_sliver_after_a_diverged_step_repeats_from_its_checkpoint(void **state)
{
    (void)state;
    model md = {0};
    md.p[0] = 9.81;
    model_shape(&md, 3, 3);
    ga_solver *s = NULL;
    assert_int_equal(ga_create(md.n, md.m, &s), GA_OK);
    md.s = s;
    assert_int_equal(ga_set_output(s, GA_OUTPUT_STEP), GA_OK);
    assert_int_equal(ga_set_callbacks(s, mass, force, constraint, jacobian, &md), GA_OK);
    assert_int_equal(ga_set_tangents(s, stiffness, NULL), GA_OK);
    assert_int_equal(ga_set_initial_step(s, 0.7), GA_OK);
    const double q0[6] = {0.37706637854462755,  -0.22618623730394516, 1.3770663785446275,
                          -0.92618623730394511, 2.3770663785446278,   -0.92618623730394511};
    const double v0[6] = {0.0};
    assert_int_equal(ga_init(s, 0.0, q0, v0), GA_OK);
    /* (a step of h = 1 does not resolve this motion: let it be taken, as before the check) */
    assert_int_equal(ga_set_resolution_check(s, INFINITY), GA_OK);
    assert_int_equal(ga_step(s, 1.0), GA_OK);
    size_t len = 0;
    assert_int_equal(ga_state_size(s, &len), GA_OK);
    assert_true(len <= CKPT_MAX);
    double ckpt[CKPT_MAX], end[2][CKPT_MAX], h[2];
    assert_int_equal(ga_get_state(s, ckpt, len), GA_OK);
    for (int run = 0; run < 2; ++run) {
        if (run == 1)
            assert_int_equal(ga_set_state(s, ckpt, len), GA_OK);
        assert_int_equal(ga_step_adaptive(s, 1.005), GA_OK);
        assert_int_equal(ga_get_h_last(s, &h[run]), GA_OK);
        assert_int_equal(ga_get_state(s, end[run], len), GA_OK);
    }
    assert_true(h[0] < 1e-3); /* shrunk from the sliver of 5e-3 that it tried first */
    assert_memory_equal(&h[0], &h[1], sizeof h[0]);
    assert_memory_equal(end[0], end[1], sizeof(double) * len);
    ga_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(model_derivatives_agree_with_differences),
        cmocka_unit_test(random_call_sequences_keep_the_contract),
        cmocka_unit_test(random_call_sequences_with_a_rotor_keep_the_contract),
        cmocka_unit_test(fuzzer_findings_stay_fixed),
        cmocka_unit_test(a_sliver_after_a_diverged_step_repeats_from_its_checkpoint),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
