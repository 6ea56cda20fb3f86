// SO(3) as unit quaternions (src/lie/so3.hpp), checked against what defines each map rather
// than against itself: the logarithm inverts the exponential; the rotation is Rodrigues'
// formula, written out here independently; the tangent operator is the derivative of the
// exponential, measured by central differences in the group; its inverse inverts it; and the
// Taylor branches near psi = 0 meet the closed forms.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "lie/so3.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

using namespace ga::so3;

Vec3 scaled(const Vec3 &v, double s) { return {s * v[0], s * v[1], s * v[2]}; }

// a direction of random orientation, length theta
Vec3 of_length(double theta, std::mt19937 &rng)
{
    std::normal_distribution<double> n(0.0, 1.0);
    const Vec3 u{n(rng), n(rng), n(rng)};
    return scaled(u, theta / norm(u));
}

const double kLengths[] = {0.0, 1e-12, 1e-8, 0.99e-4, 1.01e-4, 1e-3, 0.1, 0.5, 1.0, 2.0, 3.0};

void exp_and_log_invert(void **)
{
    std::mt19937 rng(1);
    double worst = 0.0;
    for (double th : kLengths)
        for (int trial = 0; trial < 20; ++trial) {
            const Vec3 psi = of_length(th, rng);
            const Quat q = exp(psi);
            const double unit = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
            assert_true(std::fabs(unit - 1.0) < 1e-15);
            const Vec3 back = log(q);
            for (int i = 0; i < 3; ++i)
                worst = std::max(worst, std::fabs(back[i] - psi[i]) / std::max(th, 1e-300));
            // -q is the same rotation: the same logarithm
            const Vec3 minus = log({-q[0], -q[1], -q[2], -q[3]});
            for (int i = 0; i < 3; ++i)
                assert_true(std::fabs(minus[i] - back[i]) <= 4e-16 * std::max(th, 1.0));
        }
    std::printf("  log(exp(psi)) relative to |psi|: worst %.2e\n", worst);
    assert_true(worst < 1e-14);
}

void rotation_is_rodrigues(void **)
{
    std::mt19937 rng(2);
    double worst = 0.0;
    for (double th : kLengths) {
        if (th < 1e-3)
            continue;  // (Rodrigues' closed form loses digits below)
        for (int trial = 0; trial < 20; ++trial) {
            const Vec3 psi = of_length(th, rng), x = of_length(1.0, rng);
            // R = I + (sin th / th) psi~ + ((1 - cos th) / th^2) psi~^2, applied to x
            const Vec3 px = cross(psi, x), ppx = cross(psi, px);
            const double a = std::sin(th) / th, b = (1.0 - std::cos(th)) / (th * th);
            const Vec3 ref{x[0] + a * px[0] + b * ppx[0], x[1] + a * px[1] + b * ppx[1],
                           x[2] + a * px[2] + b * ppx[2]};
            const Quat q = exp(psi);
            const Vec3 y = rotate(q, x);
            const Mat3 R = matrix(q);
            for (int i = 0; i < 3; ++i) {
                const double z = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
                worst = std::max({worst, std::fabs(y[i] - ref[i]), std::fabs(z - ref[i])});
            }
        }
    }
    std::printf("  rotation against Rodrigues: worst %.2e\n", worst);
    assert_true(worst < 1e-14);
}

void tangent_is_the_derivative_of_exp(void **)
{
    std::mt19937 rng(3);
    double worst = 0.0;
    const double s = 1e-5;
    for (double th : kLengths)
        for (int trial = 0; trial < 10; ++trial) {
            const Vec3 psi = of_length(th, rng);
            const Quat q_inv = inverse(exp(psi));
            const Mat3 T = tangent(psi);
            for (int k = 0; k < 3; ++k) {
                Vec3 plus = psi, minus = psi;
                plus[k] += s;
                minus[k] -= s;
                // exp(psi)^-1 o exp(psi +- s e_k) = exp(+-s T e_k + O(s^2))
                const Vec3 lp = log(compose(q_inv, exp(plus)));
                const Vec3 lm = log(compose(q_inv, exp(minus)));
                for (int i = 0; i < 3; ++i)
                    worst = std::max(worst, std::fabs((lp[i] - lm[i]) / (2.0 * s) - T[3 * i + k]));
            }
        }
    std::printf("  T(psi) against central differences of exp: worst %.2e\n", worst);
    assert_true(worst < 1e-9);  // (s^2 truncation ~1e-11, round-off eps / s ~ 1e-11)
}

void tangent_inverse_inverts(void **)
{
    std::mt19937 rng(4);
    double worst = 0.0;
    for (double th : kLengths)
        for (int trial = 0; trial < 20; ++trial) {
            const Vec3 psi = of_length(th, rng);
            const Mat3 T = tangent(psi), Ti = tangent_inverse(psi);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                    double e = 0.0;
                    for (int k = 0; k < 3; ++k)
                        e += T[3 * i + k] * Ti[3 * k + j];
                    worst = std::max(worst, std::fabs(e - (i == j ? 1.0 : 0.0)));
                }
        }
    std::printf("  T T^-1 - I: worst %.2e\n", worst);
    assert_true(worst < 1e-14);
}

// The closed forms evaluated in extended precision (long double, 64-bit mantissa on x86-64): an
// independent evaluation, accurate to ~eps_ld / theta in the entries, against the double maps.
void entries_match_extended_precision(void **)
{
    // (valgrind computes long double in double precision: no oracle there)
    volatile long double one = 1.0L, tiny = 1e-18L;
    if (one + tiny == one) {
        std::printf("  long double is no wider than double here: no extended-precision oracle\n");
        skip();
    }
    std::mt19937 rng(6);
    double worst = 0.0;
    for (double th : kLengths) {
        if (th < 1e-4)
            continue;
        for (int trial = 0; trial < 20; ++trial) {
            const Vec3 psi = of_length(th, rng);
            const long double x = psi[0], y = psi[1], z = psi[2];
            const long double t = std::sqrt(x * x + y * y + z * z), t2 = t * t;
            const long double c1 = (std::cos(t) - 1.0L) / t2, c2 = (t - std::sin(t)) / (t2 * t);
            const long double d2 = 1.0L / t2 - (1.0L + std::cos(t)) / (2.0L * t * std::sin(t));
            const long double P[9] = {0, -z, y, z, 0, -x, -y, x, 0};
            const Mat3 T = tangent(psi), Ti = tangent_inverse(psi);
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) {
                    long double P2 = 0.0L;
                    for (int k = 0; k < 3; ++k)
                        P2 += P[3 * i + k] * P[3 * k + j];
                    const long double I = i == j ? 1.0L : 0.0L;
                    const long double e = I + c1 * P[3 * i + j] + c2 * P2;
                    const long double ei = I + 0.5L * P[3 * i + j] + d2 * P2;
                    worst = std::max({worst, static_cast<double>(std::fabs(T[3 * i + j] - e)),
                                      static_cast<double>(std::fabs(Ti[3 * i + j] - ei))});
                }
        }
    }
    std::printf("  T and T^-1 against long double: worst %.2e\n", worst);
    assert_true(worst < 1e-15);
}

void series_meet_closed_forms(void **)
{
    // along each axis (where |psi| is exact) at the switch, 1e-4, and at the double just below
    // it: psi moves by 1e-20, so what differs is the branch
    double worst = 0.0;
    const double hi = 1e-4, lo = std::nextafter(hi, 0.0);
    for (int axis = 0; axis < 3; ++axis)
        for (double sign : {1.0, -1.0}) {
            Vec3 a{0.0, 0.0, 0.0}, b{0.0, 0.0, 0.0};
            a[axis] = sign * lo;
            b[axis] = sign * hi;
            const Mat3 ta = tangent(a), tb = tangent(b), ia = tangent_inverse(a),
                       ib = tangent_inverse(b);
            for (int k = 0; k < 9; ++k)
                worst = std::max({worst, std::fabs(ta[k] - tb[k]), std::fabs(ia[k] - ib[k])});
            const Quat qa = exp(a), qb = exp(b);
            for (int k = 0; k < 4; ++k)
                worst = std::max(worst, std::fabs(qa[k] - qb[k]));
            const Vec3 la = log(qa), lb = log(qb);
            for (int k = 0; k < 3; ++k)
                worst = std::max(worst, std::fabs(la[k] - lb[k]));
        }
    std::printf("  across the series' switch: worst jump %.2e\n", worst);
    assert_true(worst < 1e-15);
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exp_and_log_invert),
        cmocka_unit_test(rotation_is_rodrigues),
        cmocka_unit_test(tangent_is_the_derivative_of_exp),
        cmocka_unit_test(tangent_inverse_inverts),
        cmocka_unit_test(entries_match_extended_precision),
        cmocka_unit_test(series_meet_closed_forms),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
