// The group maps in the C API (ga_so3_*, ga_se3_*): src/lie/so3.hpp and se3.hpp over arrays
// of items, with the checks of the header's contract; matrices leave column-major.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>

#include "galpha.h"
#include "lie/se3.hpp"
#include "lie/so3.hpp"

namespace {

namespace so3 = ga::so3;
namespace se3 = ga::se3;

// count items of `width` doubles each: count >= 0, the arrays' lengths representable, and an
// array given whenever there is an item
bool valid(long count, std::size_t width, std::initializer_list<const void *> arrays)
{
    if (count < 0 || static_cast<unsigned long>(count) > PTRDIFF_MAX / (width * sizeof(double)))
        return false;
    if (count == 0)
        return true;
    for (const void *a : arrays)
        if (!a)
            return false;
    return true;
}

bool finite(const double *x, std::size_t n)
{
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(x[i]))
            return false;
    return true;
}

// Every input item checked before the first output is written: a failed call writes nothing.
template <std::size_t In, class Check> bool all_items(long count, const double *x, Check &&check)
{
    for (long i = 0; i < count; ++i) {
        const double *xi = x + static_cast<std::size_t>(i) * In;
        if (!finite(xi, In) || !check(xi))
            return false;
    }
    return true;
}

double length(const double *q)
{
    return std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
}
// a quaternion within 1e-6 of unit norm, as a unit one
bool near_unit(const double *q) { return std::fabs(length(q) - 1.0) <= 1e-6; }
so3::Quat unit(const double *q)
{
    const double n = length(q);
    return {q[0] / n, q[1] / n, q[2] / n, q[3] / n};
}

so3::Vec3 vec3(const double *x) { return {x[0], x[1], x[2]}; }

void put(const so3::Mat3 &A, double *out)  // row-major in, column-major out
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            out[i + 3 * j] = A[3 * i + j];
}

void put(const se3::Mat6 &A, double *out)
{
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            out[i + 6 * j] = A[6 * i + j];
}

template <std::size_t N> void put(const std::array<double, N> &x, double *out)
{
    for (std::size_t i = 0; i < N; ++i)
        out[i] = x[i];
}

const auto any = [](const double *) { return true; };

constexpr double kTwoPi = 6.283185307179586;
se3::Twist twist(const double *x) { return {x[0], x[1], x[2], x[3], x[4], x[5]}; }
// a pose (x, quaternion) whose quaternion is within 1e-6 of unit norm
bool near_unit_pose(const double *p) { return near_unit(p + 3); }
std::array<double, 7> pose(const so3::Vec3 &x, const so3::Quat &q)
{
    return {x[0], x[1], x[2], q[0], q[1], q[2], q[3]};
}

// out_i = f(in_i) for count items of In doubles in and Out out, each input accepted by `check`
// before the first output is written
template <std::size_t N> bool finite_result(const std::array<double, N> &x)
{
    return finite(x.data(), N);
}
// ... and whose image is finite: a finite input too large for the map (|psi| = 1e200, whose
// square overflows) is refused, not answered with NaN
template <std::size_t In, std::size_t Out, class Check, class Map>
ga_status map_items(long count, const double *in, double *out, Check &&check, Map &&f)
{
    const auto maps = [&](const double *x) { return check(x) && finite_result(f(x)); };
    if (!valid(count, std::max(In, Out), {in, out}) || !all_items<In>(count, in, maps))
        return GA_ERR_ARG;
    for (long i = 0; i < count; ++i)
        put(f(in + In * i), out + Out * i);
    return GA_OK;
}

}  // namespace

GA_API ga_status ga_so3_exp(long count, const double *psi, double *q)
{
    return map_items<3, 4>(count, psi, q, any, [](const double *p) { return so3::exp(vec3(p)); });
}

GA_API ga_status ga_so3_log(long count, const double *q, double *psi)
{
    return map_items<4, 3>(count, q, psi, near_unit,
                           [](const double *x) { return so3::log(unit(x)); });
}

GA_API ga_status ga_so3_compose(long count, const double *a, const double *b, double *ab)
{
    if (!valid(count, 4, {a, b, ab}) || !all_items<4>(count, a, any) ||
        !all_items<4>(count, b, any))
        return GA_ERR_ARG;
    for (long i = 0; i < count; ++i) {  // a finite product of finite factors, before writing
        const double *x = a + 4 * i, *y = b + 4 * i;
        if (!finite_result(so3::compose({x[0], x[1], x[2], x[3]}, {y[0], y[1], y[2], y[3]})))
            return GA_ERR_ARG;
    }
    for (long i = 0; i < count; ++i) {
        const double *x = a + 4 * i, *y = b + 4 * i;
        put(so3::compose({x[0], x[1], x[2], x[3]}, {y[0], y[1], y[2], y[3]}), ab + 4 * i);
    }
    return GA_OK;
}

GA_API ga_status ga_so3_matrix(long count, const double *q, double *R)
{
    return map_items<4, 9>(count, q, R, near_unit,
                           [](const double *x) { return so3::matrix(unit(x)); });
}

GA_API ga_status ga_so3_tangent(long count, const double *psi, double *T)
{
    return map_items<3, 9>(count, psi, T, any,
                           [](const double *p) { return so3::tangent(vec3(p)); });
}

GA_API ga_status ga_so3_tangent_inverse(long count, const double *psi, double *T)
{
    const auto invertible = [](const double *p) { return so3::norm(vec3(p)) < kTwoPi; };
    return map_items<3, 9>(count, psi, T, invertible,
                           [](const double *p) { return so3::tangent_inverse(vec3(p)); });
}

GA_API ga_status ga_se3_exp(long count, const double *xi, double *p)
{
    return map_items<6, 7>(count, xi, p, any, [](const double *x) {
        const so3::Vec3 u = vec3(x), w = vec3(x + 3);
        return pose(se3::exp_translation(u, w), so3::exp(w));
    });
}

GA_API ga_status ga_se3_log(long count, const double *p, double *xi)
{
    return map_items<7, 6>(count, p, xi, near_unit_pose,
                           [](const double *x) { return se3::log(vec3(x), unit(x + 3)); });
}

GA_API ga_status ga_se3_compose(long count, const double *a, const double *b, double *ab)
{
    if (!valid(count, 7, {a, b, ab}) || !all_items<7>(count, a, near_unit_pose) ||
        !all_items<7>(count, b, near_unit_pose))
        return GA_ERR_ARG;
    for (long i = 0; i < count; ++i) {
        const double *x = a + 7 * i, *y = b + 7 * i;
        const so3::Quat qa = unit(x + 3);
        const so3::Mat3 R = so3::matrix(qa);
        so3::Vec3 p = vec3(x);
        for (int r = 0; r < 3; ++r)
            p[r] += R[3 * r] * y[0] + R[3 * r + 1] * y[1] + R[3 * r + 2] * y[2];
        put(pose(p, so3::compose(qa, unit(y + 3))), ab + 7 * i);
    }
    return GA_OK;
}

GA_API ga_status ga_se3_tangent(long count, const double *xi, double *T)
{
    // The off-diagonal block is a series of alternating terms |w|^k / k!: beyond 4 pi its
    // round-off (eps e^|w|) left T wrong with GA_OK (0.33 off at |w| = 25). Refused there
    // until the closed form replaces the series.
    const auto in_reach = [](const double *x) { return so3::norm(vec3(x + 3)) <= 2.0 * kTwoPi; };
    return map_items<6, 36>(count, xi, T, in_reach,
                            [](const double *x) { return se3::tangent(twist(x)); });
}

GA_API ga_status ga_se3_tangent_inverse(long count, const double *xi, double *T)
{
    const auto invertible = [](const double *x) { return so3::norm(vec3(x + 3)) < kTwoPi; };
    return map_items<6, 36>(count, xi, T, invertible,
                            [](const double *x) { return se3::tangent_inverse(twist(x)); });
}
