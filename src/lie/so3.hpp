// The rotation group SO(3) stored as unit quaternions (S^3, its double cover), with the maps
// the Lie-group generalized-alpha method needs (docs/algorithms.md sec. 13): right increments
// and body-frame velocities, q_{n+1} = q_n o exp(psi), the exponential and logarithm, the
// tangent operator T(psi) of the increment and its inverse.
//
// Conventions, once: a quaternion is (w, x, y, z), w the scalar part; R(q) x = q x q^-1 maps
// body to space; exp(psi) turns by |psi| about psi / |psi| in the body frame; T(psi) is the
// right-trivialized derivative of exp, exp(psi + d) = exp(psi) o exp(T(psi) d + O(|d|^2)).
// Near psi = 0 (below 1e-4 rad) the coefficients use their Taylor series, whose first omitted
// terms are below 1e-17 there; above, the closed forms' cancellation costs no more than a few
// ulps of the matrices' entries.
#pragma once

#include <array>
#include <cmath>

namespace ga::so3 {

using Vec3 = std::array<double, 3>;
using Quat = std::array<double, 4>;   // (w, x, y, z)
using Mat3 = std::array<double, 9>;   // row-major

inline Quat compose(const Quat &a, const Quat &b)
{
    return {a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0]};
}

inline Quat inverse(const Quat &q) { return {q[0], -q[1], -q[2], -q[3]}; }  // (unit q)

// R(q) x
inline Vec3 rotate(const Quat &q, const Vec3 &x)
{
    const Quat p = compose(compose(q, {0.0, x[0], x[1], x[2]}), inverse(q));
    return {p[1], p[2], p[3]};
}

inline Mat3 matrix(const Quat &q)
{
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
            2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

inline double norm(const Vec3 &v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

// exp(psi) = (cos(theta/2), sin(theta/2) psi / theta), theta = |psi|
inline Quat exp(const Vec3 &psi)
{
    const double th = norm(psi), h = 0.5 * th;
    // sin(h) / th = (1/2) sinc(h)
    const double s = th < 1e-4 ? 0.5 * (1.0 - h * h / 6.0) : std::sin(h) / th;
    return {std::cos(h), s * psi[0], s * psi[1], s * psi[2]};
}

// The psi with exp(psi) = +-q and |psi| <= pi (q and -q are the same rotation)
inline Vec3 log(const Quat &q)
{
    const double sgn = q[0] < 0.0 ? -1.0 : 1.0;
    const double w = sgn * q[0];
    const Vec3 u{sgn * q[1], sgn * q[2], sgn * q[3]};
    const double s = norm(u);              // sin(theta/2)
    const double h = std::atan2(s, w);     // theta/2, in [0, pi/2]
    // theta / s = 2 atan(s / w) / s = (2 / w) (1 - s^2 / (3 w^2) + ...)
    const double f = s < 1e-4 ? (2.0 / w) * (1.0 - s * s / (3.0 * w * w)) : 2.0 * h / s;
    return {f * u[0], f * u[1], f * u[2]};
}

// a~ b = a x b
inline Vec3 cross(const Vec3 &a, const Vec3 &b)
{
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

namespace detail {
// I + c1 psi~ + c2 psi~^2 as a matrix
inline Mat3 one_plus(const Vec3 &p, double c1, double c2)
{
    const double x = p[0], y = p[1], z = p[2];
    const double xx = x * x, yy = y * y, zz = z * z;
    // psi~ = [0 -z y; z 0 -x; -y x 0], psi~^2 = psi psi^T - |psi|^2 I
    return {1 + c2 * (-yy - zz), -c1 * z + c2 * x * y,  c1 * y + c2 * x * z,
            c1 * z + c2 * x * y, 1 + c2 * (-xx - zz),   -c1 * x + c2 * y * z,
            -c1 * y + c2 * x * z, c1 * x + c2 * y * z,  1 + c2 * (-xx - yy)};
}
}  // namespace detail

// T(psi) = I + ((cos theta - 1) / theta^2) psi~ + ((theta - sin theta) / theta^3) psi~^2
inline Mat3 tangent(const Vec3 &psi)
{
    const double th = norm(psi), t2 = th * th, h = 0.5 * th;
    // cos theta - 1 = -2 sin^2(theta/2): c1 without cancellation (it multiplies psi~, of size
    // theta, so the closed form's eps / theta^2 would show as eps / theta)
    const double sinc_h = th < 1e-4 ? 1.0 - h * h / 6.0 : std::sin(h) / h;
    const double c1 = -0.5 * sinc_h * sinc_h;
    // (the closed form's eps / theta^2 is multiplied by psi~^2, of size theta^2)
    const double c2 = th < 1e-4 ? 1.0 / 6.0 - t2 / 120.0 : (th - std::sin(th)) / (t2 * th);
    return detail::one_plus(psi, c1, c2);
}

// T(psi)^-1 = I + (1/2) psi~ + (1 / theta^2 - cot(theta/2) / (2 theta)) psi~^2 (for
// theta < 2 pi; the increments of a step are far below). cot(theta/2), not
// (1 + cos theta) / sin theta: the same value, without 0/0 at theta = pi.
inline Mat3 tangent_inverse(const Vec3 &psi)
{
    const double th = norm(psi), t2 = th * th, h = 0.5 * th;
    const double c2 = th < 1e-4 ? 1.0 / 12.0 + t2 / 720.0
                                : 1.0 / t2 - std::cos(h) / (2.0 * th * std::sin(h));
    return detail::one_plus(psi, 0.5, c2);
}

}  // namespace ga::so3
