/* The rotation maps of the C API (ga_so3_*), against what defines each one, written out here:
 * the exponential's closed form, Rodrigues' formula for the matrix, the logarithm as the
 * exponential's inverse, the product's rotation as the matrices' product, the tangent operator's
 * closed form about an axis and as the derivative of exp (central differences in the group),
 * its inverse as the inverse matrix; then every refusal, with nothing written. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <limits.h>
#include <math.h>
#include <string.h>

#include <galpha.h>

static const double kPi = 3.14159265358979323846;

static double norm3(const double *v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

/* Rodrigues: R = I + sin t K + (1 - cos t) K^2, K the cross-product matrix of psi / t
 * (column-major) */
static void rodrigues(const double *psi, double *R)
{
    const double t = norm3(psi);
    double K[9] = {0}, K2[9] = {0};
    if (t > 0.0) {
        const double x = psi[0] / t, y = psi[1] / t, z = psi[2] / t;
        const double k[9] = {0, z, -y, -z, 0, x, y, -x, 0}; /* column-major [0 -z y; z 0 -x; ...] */
        memcpy(K, k, sizeof k);
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int l = 0; l < 3; ++l)
                K2[i + 3 * j] += K[i + 3 * l] * K[l + 3 * j];
    for (int e = 0; e < 9; ++e)
        R[e] = (e % 4 == 0 ? 1.0 : 0.0) + sin(t) * K[e] + (1.0 - cos(t)) * K2[e];
}

static void product(const double *A, const double *B, double *C)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double c = 0.0;
            for (int l = 0; l < 3; ++l)
                c += A[i + 3 * l] * B[l + 3 * j];
            C[i + 3 * j] = c;
        }
}

static double max_diff(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int i = 0; i < n; ++i)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

#define COUNT 6
static const double kPsi[COUNT][3] = {{0.0, 0.0, 0.0},  {1e-9, -2e-9, 3e-9}, {0.3, -0.2, 0.1},
                                      {0.0, 0.0, 1.5},  {-1.0, 2.0, 0.5},    {0.0, 3.0, 0.0}};

static void exponential_is_the_closed_form(void **state)
{
    (void)state;
    double q[COUNT][4];
    assert_int_equal(ga_so3_exp(COUNT, &kPsi[0][0], &q[0][0]), GA_OK);
    for (int k = 0; k < COUNT; ++k) {
        const double t = norm3(kPsi[k]);
        const double s = t > 0.0 ? sin(0.5 * t) / t : 0.5;
        const double want[4] = {cos(0.5 * t), s * kPsi[k][0], s * kPsi[k][1], s * kPsi[k][2]};
        assert_true(max_diff(q[k], want, 4) < 1e-15);
    }
}

static void matrix_is_rodrigues(void **state)
{
    (void)state;
    double q[COUNT][4], R[COUNT][9], want[9];
    assert_int_equal(ga_so3_exp(COUNT, &kPsi[0][0], &q[0][0]), GA_OK);
    assert_int_equal(ga_so3_matrix(COUNT, &q[0][0], &R[0][0]), GA_OK);
    for (int k = 0; k < COUNT; ++k) {
        rodrigues(kPsi[k], want);
        assert_true(max_diff(R[k], want, 9) < 1e-15);
    }
    /* a quarter turn about z takes the body's x axis to space y: R e_x = e_y, column-major */
    const double quarter[3] = {0.0, 0.0, 0.5 * kPi};
    double qz[4], Rz[9];
    assert_int_equal(ga_so3_exp(1, quarter, qz), GA_OK);
    assert_int_equal(ga_so3_matrix(1, qz, Rz), GA_OK);
    assert_true(fabs(Rz[0]) < 1e-15 && fabs(Rz[1] - 1.0) < 1e-15 && fabs(Rz[2]) < 1e-15);
}

static void logarithm_inverts_the_exponential(void **state)
{
    (void)state;
    double q[COUNT][4], psi[COUNT][3];
    assert_int_equal(ga_so3_exp(COUNT, &kPsi[0][0], &q[0][0]), GA_OK);
    assert_int_equal(ga_so3_log(COUNT, &q[0][0], &psi[0][0]), GA_OK);
    for (int k = 0; k < COUNT; ++k)
        assert_true(max_diff(psi[k], kPsi[k], 3) < 1e-15 * fmax(1.0, norm3(kPsi[k])) * 4);
    /* -q is the same rotation; a norm off by 1e-7 is normalized first */
    double minus[4], off[4], back[3];
    for (int i = 0; i < 4; ++i) {
        minus[i] = -q[4][i];
        off[i] = (1.0 + 1e-7) * q[4][i];
    }
    assert_int_equal(ga_so3_log(1, minus, back), GA_OK);
    assert_true(max_diff(back, kPsi[4], 3) < 1e-14);
    assert_int_equal(ga_so3_log(1, off, back), GA_OK);
    assert_true(max_diff(back, kPsi[4], 3) < 1e-14);
    /* beyond pi the logarithm is the shorter way round: |psi| <= pi */
    const double long_way[3] = {0.0, 0.0, 1.5 * kPi};
    double ql[4], pl[3];
    assert_int_equal(ga_so3_exp(1, long_way, ql), GA_OK);
    assert_int_equal(ga_so3_log(1, ql, pl), GA_OK);
    assert_true(fabs(pl[2] + 0.5 * kPi) < 1e-14 && fabs(pl[0]) < 1e-15 && fabs(pl[1]) < 1e-15);
}

static void composition_is_the_matrices_product(void **state)
{
    (void)state;
    double a[4], b[4], ab[4], Ra[9], Rb[9], Rab[9], want[9];
    assert_int_equal(ga_so3_exp(1, kPsi[2], a), GA_OK);
    assert_int_equal(ga_so3_exp(1, kPsi[4], b), GA_OK);
    assert_int_equal(ga_so3_compose(1, a, b, ab), GA_OK);
    assert_int_equal(ga_so3_matrix(1, a, Ra), GA_OK);
    assert_int_equal(ga_so3_matrix(1, b, Rb), GA_OK);
    assert_int_equal(ga_so3_matrix(1, ab, Rab), GA_OK);
    product(Ra, Rb, want);
    assert_true(max_diff(Rab, want, 9) < 1e-15 * 8);
    /* in place: the output may be the first input */
    assert_int_equal(ga_so3_compose(1, a, b, a), GA_OK);
    assert_true(max_diff(a, ab, 4) == 0.0);
    /* turns about one axis add up */
    const double s[3] = {0.0, 0.4, 0.0}, t[3] = {0.0, 0.7, 0.0}, st[3] = {0.0, 1.1, 0.0};
    double qs[4], qt[4], qst[4], sum[4];
    assert_int_equal(ga_so3_exp(1, s, qs), GA_OK);
    assert_int_equal(ga_so3_exp(1, t, qt), GA_OK);
    assert_int_equal(ga_so3_exp(1, st, qst), GA_OK);
    assert_int_equal(ga_so3_compose(1, qs, qt, sum), GA_OK);
    assert_true(max_diff(sum, qst, 4) < 1e-15 * 4);
}

/* T(t e_z) = [sin t / t, (1 - cos t) / t, 0; -(1 - cos t) / t, sin t / t, 0; 0, 0, 1] */
static void tangent_about_an_axis_is_the_closed_form(void **state)
{
    (void)state;
    for (int k = 0; k < 4; ++k) {
        const double th = (double[]){1e-6, 0.3, 1.5, 3.0}[k];
        const double psi[3] = {0.0, 0.0, th};
        /* 1 - cos t as 2 sin^2(t/2): without its cancellation at t = 1e-6 */
        const double s = sin(th) / th, c = 2.0 * sin(0.5 * th) * sin(0.5 * th) / th;
        const double want[9] = {s, -c, 0.0, c, s, 0.0, 0.0, 0.0, 1.0}; /* column-major */
        double T[9];
        assert_int_equal(ga_so3_tangent(1, psi, T), GA_OK);
        assert_true(max_diff(T, want, 9) < 1e-15 * 4);
    }
}

/* exp(psi + e d) = exp(psi) o exp(T(psi) e d + O(e^2)): T d by central differences of
 * log(exp(psi)^-1 o exp(psi +- e d)) */
static void tangent_is_the_derivative_of_exp(void **state)
{
    (void)state;
    const double e = 1e-5;
    double worst = 0.0;
    for (int k = 0; k < COUNT; ++k) {
        double T[9], q[4], inv[4];
        assert_int_equal(ga_so3_tangent(1, kPsi[k], T), GA_OK);
        assert_int_equal(ga_so3_exp(1, kPsi[k], q), GA_OK);
        inv[0] = q[0];
        for (int i = 1; i < 4; ++i)
            inv[i] = -q[i];
        for (int j = 0; j < 3; ++j) {
            double fd[3], side[2][3];
            for (int sgn = 0; sgn < 2; ++sgn) {
                double p[3] = {kPsi[k][0], kPsi[k][1], kPsi[k][2]}, qp[4], rel[4];
                p[j] += sgn == 0 ? e : -e;
                assert_int_equal(ga_so3_exp(1, p, qp), GA_OK);
                assert_int_equal(ga_so3_compose(1, inv, qp, rel), GA_OK);
                assert_int_equal(ga_so3_log(1, rel, side[sgn]), GA_OK);
            }
            for (int i = 0; i < 3; ++i) {
                fd[i] = (side[0][i] - side[1][i]) / (2.0 * e);
                worst = fmax(worst, fabs(fd[i] - T[i + 3 * j]));
            }
        }
    }
    assert_true(worst < 1e-9);
}

static void tangent_inverse_inverts_it(void **state)
{
    (void)state;
    const double cases[][3] = {{1e-7, 0.0, 0.0}, {0.3, -0.2, 0.1}, {0.0, kPi, 0.0},
                               {-1.0, 2.0, 0.5}, {0.0, 0.0, 6.0}};
    for (int k = 0; k < 5; ++k) {
        double T[9], Ti[9], I[9];
        assert_int_equal(ga_so3_tangent(1, cases[k], T), GA_OK);
        assert_int_equal(ga_so3_tangent_inverse(1, cases[k], Ti), GA_OK);
        product(T, Ti, I);
        for (int e = 0; e < 9; ++e)
            assert_true(fabs(I[e] - (e % 4 == 0 ? 1.0 : 0.0)) < 1e-13);
    }
}

static void refusals_write_nothing(void **state)
{
    (void)state;
    const double psi[2][3] = {{0.1, 0.2, 0.3}, {0.0, NAN, 0.0}};
    const double q_bad[4] = {1.0, 1e-3, 0.0, 0.0}; /* norm off by 5e-7 ... */
    const double q_far[4] = {1.1, 0.0, 0.0, 0.0};  /* ... and by 0.1 */
    double out[2][9];
    memset(out, 0, sizeof out);
    assert_int_equal(ga_so3_exp(-1, psi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_exp(1, NULL, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_exp(1, psi[0], NULL), GA_ERR_ARG);
    assert_int_equal(ga_so3_exp(LONG_MAX, psi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_exp(0, NULL, NULL), GA_OK); /* nothing to map */
    assert_int_equal(ga_so3_exp(2, psi[0], out[0]), GA_ERR_ARG); /* the second is NaN */
    assert_int_equal(ga_so3_tangent(2, psi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_tangent_inverse(2, psi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_log(1, q_far, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_matrix(1, q_far, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_compose(1, q_far, NULL, out[0]), GA_ERR_ARG);
    const double q_nan[4] = {1.0, 0.0, NAN, 0.0};
    assert_int_equal(ga_so3_compose(1, q_far, q_nan, out[0]), GA_ERR_ARG);
    const double full_turn[3] = {0.0, 2.0 * kPi, 0.0};
    assert_int_equal(ga_so3_tangent_inverse(1, full_turn, out[0]), GA_ERR_ARG);
    /* D6: finite inputs whose images are not (|psi|^2 overflows): GA_OK with NaN before */
    const double huge[3] = {1e200, 0.0, 0.0}, q_huge[4] = {1e200, 1e200, 0.0, 0.0};
    assert_int_equal(ga_so3_exp(1, huge, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_tangent(1, huge, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_so3_compose(1, q_huge, q_huge, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_exp(1, (const double[6]){0, 0, 0, 1e200, 0, 0}, out[0]),
                     GA_ERR_ARG);
    /* D4: ga_se3_tangent's series at |w| = 25 was 0.33 off with GA_OK; beyond 4 pi refused */
    double T[36] = {0};
    assert_int_equal(ga_se3_tangent(1, (const double[6]){1, 0, 0, 0, 25.0, 0}, T), GA_ERR_ARG);
    for (int j = 0; j < 36; ++j)
        assert_true(T[j] == 0.0);
    assert_int_equal(ga_se3_tangent(1, (const double[6]){1, 0, 0, 0, 12.0, 0}, T), GA_OK);
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 9; ++j)
            assert_true(out[i][j] == 0.0); /* no refusal wrote anything */
    /* within 1e-6 of unit norm is accepted */
    assert_int_equal(ga_so3_log(1, q_bad, out[0]), GA_OK);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exponential_is_the_closed_form),
        cmocka_unit_test(matrix_is_rodrigues),
        cmocka_unit_test(logarithm_inverts_the_exponential),
        cmocka_unit_test(composition_is_the_matrices_product),
        cmocka_unit_test(tangent_about_an_axis_is_the_closed_form),
        cmocka_unit_test(tangent_is_the_derivative_of_exp),
        cmocka_unit_test(tangent_inverse_inverts_it),
        cmocka_unit_test(refusals_write_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
