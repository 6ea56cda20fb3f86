// SE(3)'s maps (src/lie/se3.hpp) against their definitions, by differences of the group
// operations themselves: the tangent operator from exp(xi + e d) = exp(xi) o exp(e T d + ..),
// its inverse, the transport from exp(e s) o exp(xi) = exp(xi) o exp(e Ad s + ..), and log as
// the inverse of exp; the series of T's coupling block against a direct sum of (-ad)^k/(k+1)!.
#include <Eigen/Dense>
#include <cmath>

#include "lie/se3.hpp"

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

using namespace ga;
using Pose = std::pair<so3::Vec3, so3::Quat>;  // (x, r)
using M6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

Pose exp_pose(const se3::Twist &xi)
{
    return {se3::exp_translation({xi[0], xi[1], xi[2]}, {xi[3], xi[4], xi[5]}),
            so3::exp({xi[3], xi[4], xi[5]})};
}
Pose compose(const Pose &a, const Pose &b)
{
    const so3::Vec3 d = so3::rotate(a.second, b.first);
    return {{a.first[0] + d[0], a.first[1] + d[1], a.first[2] + d[2]},
            so3::compose(a.second, b.second)};
}
Pose inverse(const Pose &a)
{
    const so3::Quat ri = so3::inverse(a.second);
    const so3::Vec3 x = so3::rotate(ri, a.first);
    return {{-x[0], -x[1], -x[2]}, ri};
}
se3::Twist log_pose(const Pose &a) { return se3::log(a.first, a.second); }

M6 as_matrix(const se3::Mat6 &A) { return Eigen::Map<const M6>(A.data()); }

const se3::Twist kXi[] = {{0.3, -0.7, 0.2, 0.4, -0.1, 0.9},
                          {1.0, 2.0, -0.5, 1e-6, 2e-6, -1e-6},
                          {-0.2, 0.1, 0.4, 2.5, -1.0, 0.5}};

void test_log_inverts_exp(void **)
{
    for (const se3::Twist &xi : kXi) {
        const se3::Twist back = log_pose(exp_pose(xi));
        for (int k = 0; k < 6; ++k)
            assert_true(std::fabs(back[k] - xi[k]) < 1e-14);
    }
}

// column j of T: log(exp(xi)^-1 exp(xi + e e_j)) / e, central, e = 1e-6
void test_tangent_by_differences(void **)
{
    for (const se3::Twist &xi : kXi) {
        const M6 T = as_matrix(se3::tangent(xi));
        const Pose inv = inverse(exp_pose(xi));
        M6 D;
        const double e = 1e-6;
        for (int j = 0; j < 6; ++j) {
            se3::Twist p = xi, m = xi;
            p[j] += e;
            m[j] -= e;
            const se3::Twist a = log_pose(compose(inv, exp_pose(p)));
            const se3::Twist b = log_pose(compose(inv, exp_pose(m)));
            for (int i = 0; i < 6; ++i)
                D(i, j) = (a[i] - b[i]) / (2 * e);
        }
        const double diff = (T - D).cwiseAbs().maxCoeff();
        print_message("  T against differences: %.2e\n", diff);
        assert_true(diff < 1e-8);
        const M6 Ti = as_matrix(se3::tangent_inverse(xi));
        assert_true((Ti * T - M6::Identity()).cwiseAbs().maxCoeff() < 1e-13);
    }
}

// Ad_{exp(-xi)} s = log(exp(xi)^-1 exp(e s) exp(xi)) / e
void test_transport_by_differences(void **)
{
    for (const se3::Twist &xi : kXi) {
        const M6 A = as_matrix(se3::transport(xi));
        const Pose E = exp_pose(xi), Ei = inverse(E);
        const double e = 1e-6;
        M6 D;
        for (int j = 0; j < 6; ++j) {
            se3::Twist s{}, sm{};
            s[j] = e;
            sm[j] = -e;
            const se3::Twist a = log_pose(compose(compose(Ei, exp_pose(s)), E));
            const se3::Twist b = log_pose(compose(compose(Ei, exp_pose(sm)), E));
            for (int i = 0; i < 6; ++i)
                D(i, j) = (a[i] - b[i]) / (2 * e);
        }
        assert_true((A - D).cwiseAbs().maxCoeff() < 1e-8);
    }
}

// T = sum_k (-ad)^k / (k+1)! with Eigen's 6 x 6 powers
void test_tangent_is_the_series_of_ad(void **)
{
    for (const se3::Twist &xi : kXi) {
        const M6 ad = as_matrix(se3::ad(xi));
        M6 S = M6::Zero(), P = M6::Identity();
        double f = 1.0;
        for (int k = 0; k < 40; ++k) {
            f /= (k + 1);
            S += f * P;
            P = -ad * P;
        }
        assert_true((as_matrix(se3::tangent(xi)) - S).cwiseAbs().maxCoeff() < 1e-14);
    }
}

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_log_inverts_exp),
        cmocka_unit_test(test_tangent_by_differences),
        cmocka_unit_test(test_transport_by_differences),
        cmocka_unit_test(test_tangent_is_the_series_of_ad),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
