// The special Euclidean group SE(3), a pose (x, R) stored as its position and a unit quaternion,
// with the maps of the Lie-group method (docs/algorithms.md sec. 13, 14): right increments,
// body-frame twists xi = (u, w) (u the translation, w the rotation, in that order),
// (x, R) o exp(xi) = (x + R V(w) u, R exp(w)) with V(w) = T(w)^T the left Jacobian of SO(3).
// In that ordering ad_xi = [w~ u~; 0 w~]; the tangent operator is T(xi) = sum_k (-ad_xi)^k /
// (k+1)!, block upper triangular with SO(3)'s T(w) on the diagonal; its off-diagonal block is
// summed as a series (its closed form's cancellations near w = 0 are not worth the risk here).
#pragma once

#include <array>
#include <cmath>

#include "so3.hpp"

namespace ga::se3 {

using so3::Mat3;
using so3::Quat;
using so3::Vec3;
using Twist = std::array<double, 6>;  // (u, w)
using Mat6 = std::array<double, 36>;  // row-major

namespace detail {
inline Mat3 mul(const Mat3 &A, const Mat3 &B)
{
    Mat3 C{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    return C;
}
inline Mat3 transpose(const Mat3 &A) { return {A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8]}; }
inline Mat3 hat(const Vec3 &v) { return {0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0}; }
inline Vec3 apply(const Mat3 &A, const Vec3 &x)
{
    return {A[0] * x[0] + A[1] * x[1] + A[2] * x[2], A[3] * x[0] + A[4] * x[1] + A[5] * x[2],
            A[6] * x[0] + A[7] * x[1] + A[8] * x[2]};
}
// [A B; 0 D] as a 6 x 6
inline Mat6 blocks(const Mat3 &A, const Mat3 &B, const Mat3 &D)
{
    Mat6 M{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            M[6 * i + j] = A[3 * i + j];
            M[6 * i + 3 + j] = B[3 * i + j];
            M[6 * (3 + i) + 3 + j] = D[3 * i + j];
        }
    return M;
}
// The off-diagonal block of T(xi): sum_{k >= 1} (-1)^k / (k+1)! U_k, U_k that of ad^k,
// U_1 = u~, U_{k+1} = w~ U_k + u~ w~^k
inline Mat3 coupling(const Vec3 &u, const Vec3 &w)
{
    const Mat3 A = hat(w), B = hat(u);
    Mat3 U = B, P = A, C{};
    double coef = -0.5;
    const double angle = so3::norm(w);
    for (int k = 1; k <= 60; ++k) {
        double big = 0.0, sum = 0.0;
        for (int e = 0; e < 9; ++e) {
            C[e] += coef * U[e];
            big = std::fmax(big, std::fabs(coef * U[e]));
            sum = std::fmax(sum, std::fabs(C[e]));
        }
        if (k > 2 * angle + 2 && big <= 1e-18 * sum)
            break;
        const Mat3 AU = mul(A, U), BP = mul(B, P);
        for (int e = 0; e < 9; ++e)
            U[e] = AU[e] + BP[e];
        P = mul(A, P);
        coef = -coef / (k + 2);
    }
    return C;
}
}  // namespace detail

// The translation of exp(u, w): V(w) u = T(w)^T u
inline Vec3 exp_translation(const Vec3 &u, const Vec3 &w)
{
    return detail::apply(detail::transpose(so3::tangent(w)), u);
}

// log of the relative pose (dx, r) (dx in the first pose's frame): w = log(r), u = V(w)^-1 dx
inline Twist log(const Vec3 &dx, const Quat &r)
{
    const Vec3 w = so3::log(r);
    const Vec3 u = detail::apply(detail::transpose(so3::tangent_inverse(w)), dx);
    return {u[0], u[1], u[2], w[0], w[1], w[2]};
}

inline Mat6 tangent(const Twist &xi)
{
    const Vec3 u{xi[0], xi[1], xi[2]}, w{xi[3], xi[4], xi[5]};
    const Mat3 T = so3::tangent(w);
    return detail::blocks(T, detail::coupling(u, w), T);
}

// T^-1 = [T_w^-1, -T_w^-1 C T_w^-1; 0, T_w^-1]
inline Mat6 tangent_inverse(const Twist &xi)
{
    const Vec3 u{xi[0], xi[1], xi[2]}, w{xi[3], xi[4], xi[5]};
    const Mat3 Ti = so3::tangent_inverse(w);
    Mat3 B = detail::mul(detail::mul(Ti, detail::coupling(u, w)), Ti);
    for (double &b : B)
        b = -b;
    return detail::blocks(Ti, B, Ti);
}

// Ad of exp(-xi): a tangent vector s at a pose seen at that pose o exp(xi);
// exp(xi) = (p, E) gives [E^T, -E^T p~; 0, E^T]
inline Mat6 transport(const Twist &xi)
{
    const Vec3 u{xi[0], xi[1], xi[2]}, w{xi[3], xi[4], xi[5]};
    const Mat3 Et = detail::transpose(so3::matrix(so3::exp(w)));
    Mat3 B = detail::mul(Et, detail::hat(exp_translation(u, w)));
    for (double &b : B)
        b = -b;
    return detail::blocks(Et, B, Et);
}

// ad_xi = [w~ u~; 0 w~]
inline Mat6 ad(const Twist &xi)
{
    return detail::blocks(detail::hat({xi[3], xi[4], xi[5]}), detail::hat({xi[0], xi[1], xi[2]}),
                          detail::hat({xi[3], xi[4], xi[5]}));
}

}  // namespace ga::se3
