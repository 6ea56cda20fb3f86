/* The pose maps of the C API (ga_se3_*), against what defines each one, written out here with
 * 4 x 4 homogeneous matrices H = [R x; 0 1]: the exponential as the matrix exponential of the
 * twist's matrix [w~ u; 0 0] (a Taylor series with scaling and squaring), the logarithm as its
 * inverse, the composition as the matrices' product, the tangent operator as the derivative of
 * exp (central differences, H(xi)^-1 dH/dxi_j = hat(T e_j)), its inverse as the inverse
 * matrix; then every refusal, with nothing written. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <limits.h>
#include <math.h>
#include <string.h>

#include <galpha.h>

typedef double Mat4[16]; /* column-major */

static void mul4(const double *A, const double *B, double *C)
{
    double c[16];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0.0;
            for (int l = 0; l < 4; ++l)
                s += A[i + 4 * l] * B[l + 4 * j];
            c[i + 4 * j] = s;
        }
    memcpy(C, c, sizeof c);
}

/* [w~ u; 0 0], the twist's matrix */
static void hat(const double *xi, double *X)
{
    const double *u = xi, *w = xi + 3;
    const double x[16] = {0,    w[2],  -w[1], 0, -w[2], 0,    w[0], 0,
                          w[1], -w[0], 0,     0, u[0],  u[1], u[2], 0};
    memcpy(X, x, sizeof x);
}

/* exp of the twist's matrix: Taylor series of exp(X / 2^s), then s squarings */
static void expm(const double *xi, double *H)
{
    double X[16], term[16], sum[16];
    hat(xi, X);
    double big = 0.0;
    for (int e = 0; e < 16; ++e)
        big = fmax(big, fabs(X[e]));
    int s = 0;
    while (big > 0.25) {
        big /= 2.0;
        ++s;
    }
    for (int e = 0; e < 16; ++e) {
        X[e] = ldexp(X[e], -s);
        sum[e] = term[e] = (e % 5 == 0) ? 1.0 : 0.0;
    }
    for (int k = 1; k <= 25; ++k) {
        mul4(term, X, term);
        for (int e = 0; e < 16; ++e) {
            term[e] /= k;
            sum[e] += term[e];
        }
    }
    for (int i = 0; i < s; ++i)
        mul4(sum, sum, sum);
    memcpy(H, sum, sizeof sum);
}

/* the pose (x, q) as H, by ga_so3_matrix for R (checked against Rodrigues in test_rotations) */
static void homogeneous(const double *p, double *H)
{
    double R[9];
    assert_int_equal(ga_so3_matrix(1, p + 3, R), GA_OK);
    memset(H, 0, 16 * sizeof(double));
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            H[i + 4 * j] = R[i + 3 * j];
        H[i + 12] = p[i];
    }
    H[15] = 1.0;
}

/* H^-1 = [R^T -R^T x; 0 1] */
static void inverse4(const double *H, double *G)
{
    memset(G, 0, 16 * sizeof(double));
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
            G[i + 4 * j] = H[j + 4 * i];
        for (int l = 0; l < 3; ++l)
            G[i + 12] -= H[l + 4 * i] * H[l + 12];
    }
    G[15] = 1.0;
}

static double max_diff(const double *a, const double *b, int n)
{
    double d = 0.0;
    for (int i = 0; i < n; ++i)
        d = fmax(d, fabs(a[i] - b[i]));
    return d;
}

#define COUNT 6
static const double kXi[COUNT][6] = {
    {0.0, 0.0, 0.0, 0.0, 0.0, 0.0},   {1.0, -2.0, 0.5, 1e-9, -2e-9, 3e-9},
    {0.3, -0.2, 0.1, 0.4, 0.1, -0.3}, {-2.0, 1.0, 3.0, 0.0, 0.0, 1.5},
    {0.5, 0.5, -1.0, 1.2, -2.1, 0.7}, {0.0, 1.0, 0.0, 2.9, 0.3, -0.4},
};

static void exponential_is_the_matrix_exponential(void **state)
{
    (void)state;
    double p[COUNT][7];
    assert_int_equal(ga_se3_exp(COUNT, &kXi[0][0], &p[0][0]), GA_OK);
    for (int k = 0; k < COUNT; ++k) {
        Mat4 H, E;
        homogeneous(p[k], H);
        expm(kXi[k], E);
        assert_true(max_diff(H, E, 16) < 1e-13);
    }
}

static void logarithm_inverts_the_exponential(void **state)
{
    (void)state;
    double p[COUNT][7], xi[COUNT][6];
    assert_int_equal(ga_se3_exp(COUNT, &kXi[0][0], &p[0][0]), GA_OK);
    assert_int_equal(ga_se3_log(COUNT, &p[0][0], &xi[0][0]), GA_OK);
    assert_true(max_diff(&xi[0][0], &kXi[0][0], 6 * COUNT) < 1e-12);
    /* in place: the twists packed at the front of the poses' array */
    assert_int_equal(ga_se3_log(COUNT, &p[0][0], &p[0][0]), GA_OK);
    assert_true(max_diff(&p[0][0], &kXi[0][0], 6 * COUNT) < 1e-12);
}

static void composition_is_the_matrices_product(void **state)
{
    (void)state;
    double a[7], b[7], ab[7];
    assert_int_equal(ga_se3_exp(1, kXi[2], a), GA_OK);
    assert_int_equal(ga_se3_exp(1, kXi[4], b), GA_OK);
    assert_int_equal(ga_se3_compose(1, a, b, ab), GA_OK);
    Mat4 Ha, Hb, Hab, P;
    homogeneous(a, Ha);
    homogeneous(b, Hb);
    homogeneous(ab, Hab);
    mul4(Ha, Hb, P);
    assert_true(max_diff(Hab, P, 16) < 1e-14);
    /* exp(xi) o exp(xi) = exp(2 xi): one subgroup */
    double two[6], p2[7], pp[7];
    for (int i = 0; i < 6; ++i)
        two[i] = 2.0 * kXi[4][i];
    assert_int_equal(ga_se3_exp(1, two, p2), GA_OK);
    assert_int_equal(ga_se3_compose(1, b, b, pp), GA_OK);
    assert_true(max_diff(p2, pp, 7) < 1e-14);
}

static void tangent_is_the_derivative_of_exp(void **state)
{
    (void)state;
    const double e = 1e-5;
    for (int k = 0; k < COUNT; ++k) {
        double T[36];
        assert_int_equal(ga_se3_tangent(1, kXi[k], T), GA_OK);
        Mat4 H, G;
        expm(kXi[k], H);
        inverse4(H, G);
        for (int j = 0; j < 6; ++j) {
            double xp[6], xm[6];
            memcpy(xp, kXi[k], sizeof xp);
            memcpy(xm, kXi[k], sizeof xm);
            xp[j] += e;
            xm[j] -= e;
            Mat4 Hp, Hm, D, GD, want;
            expm(xp, Hp);
            expm(xm, Hm);
            for (int l = 0; l < 16; ++l)
                D[l] = (Hp[l] - Hm[l]) / (2.0 * e);
            mul4(G, D, GD);
            hat(T + 6 * j, want); /* column j of T, as a twist's matrix */
            assert_true(max_diff(GD, want, 16) < 1e-8);
        }
    }
}

static void tangent_inverse_inverts_it(void **state)
{
    (void)state;
    for (int k = 0; k < COUNT; ++k) {
        double T[36], Ti[36];
        assert_int_equal(ga_se3_tangent(1, kXi[k], T), GA_OK);
        assert_int_equal(ga_se3_tangent_inverse(1, kXi[k], Ti), GA_OK);
        for (int i = 0; i < 6; ++i)
            for (int j = 0; j < 6; ++j) {
                double s = 0.0;
                for (int l = 0; l < 6; ++l)
                    s += T[i + 6 * l] * Ti[l + 6 * j];
                assert_true(fabs(s - (i == j ? 1.0 : 0.0)) < 1e-13);
            }
    }
}

static void refusals_write_nothing(void **state)
{
    (void)state;
    const double xi[2][6] = {{0.1, 0.2, 0.3, 0.1, 0.0, 0.0}, {0.0, 0.0, 0.0, 0.0, NAN, 0.0}};
    const double p_far[7] = {0.0, 0.0, 0.0, 1.1, 0.0, 0.0, 0.0}; /* norm off by 0.1 */
    const double p_ok[7] = {1.0, 2.0, 3.0, 1.0, 0.0, 0.0, 0.0};
    const double p_nan[7] = {NAN, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0};
    const double full_turn[6] = {0.0, 0.0, 0.0, 0.0, 2.0 * 3.14159265358979323846, 0.0};
    double out[2][36];
    memset(out, 0, sizeof out);
    assert_int_equal(ga_se3_exp(-1, xi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_exp(1, NULL, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_exp(1, xi[0], NULL), GA_ERR_ARG);
    assert_int_equal(ga_se3_exp(LONG_MAX, xi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_exp(0, NULL, NULL), GA_OK);         /* nothing to map */
    assert_int_equal(ga_se3_exp(2, xi[0], out[0]), GA_ERR_ARG); /* the second is NaN */
    assert_int_equal(ga_se3_tangent(2, xi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_tangent(LONG_MAX / 8, xi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_tangent_inverse(2, xi[0], out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_tangent_inverse(1, full_turn, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_log(1, p_far, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_log(1, p_nan, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_compose(1, p_ok, p_far, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_compose(1, p_far, p_ok, out[0]), GA_ERR_ARG);
    assert_int_equal(ga_se3_compose(1, p_ok, NULL, out[0]), GA_ERR_ARG);
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 36; ++j)
            assert_true(out[i][j] == 0.0); /* no refusal wrote anything */
    assert_int_equal(ga_se3_compose(1, p_ok, p_ok, out[0]), GA_OK);
    assert_true(out[0][0] == 2.0 && out[0][2] == 6.0 && out[0][3] == 1.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exponential_is_the_matrix_exponential),
        cmocka_unit_test(logarithm_inverts_the_exponential),
        cmocka_unit_test(composition_is_the_matrices_product),
        cmocka_unit_test(tangent_is_the_derivative_of_exp),
        cmocka_unit_test(tangent_inverse_inverts_it),
        cmocka_unit_test(refusals_write_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
