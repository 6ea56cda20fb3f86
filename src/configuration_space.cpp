// The group blocks of ga::ConfigurationSpace (docs/algorithms.md sec. 13, 14): rotations stored
// as unit quaternions or as column-major rotation matrices, and rigid poses of SE(3) (a
// position and a quaternion), moved by right increments, q o exp(xi), with xi in the body
// frame; vector blocks as in R^n. Each group block of width w (3 or 6) goes through the same
// four maps: exp onto its storage, the log between two storages, T(xi) and the transport
// Ad_{exp(-xi)} (w x w, row-major).
#include "configuration_space.hpp"

#include <limits>

#include "lie/se3.hpp"

namespace ga {

namespace {

using so3::Mat3;
using so3::Quat;
using so3::Vec3;
using Kind = ConfigurationSpace::Kind;
using Alg = std::array<double, 6>;  // an element of a block's algebra (3 or 6 used)
using Op = std::array<double, 36>;  // a w x w operator, row-major

Vec3 vec3(const double *p) { return {p[0], p[1], p[2]}; }
Quat quat(const double *p) { return {p[0], p[1], p[2], p[3]}; }

// A rotation matrix (row-major) as a unit quaternion with w >= 0 (Shepperd: from the largest
// of the four squared components, so that no division is by a small number)
Quat from_matrix(const Mat3 &R)
{
    const double tr = R[0] + R[4] + R[8];
    const double c[4] = {1 + tr, 1 + R[0] - R[4] - R[8], 1 - R[0] + R[4] - R[8],
                         1 - R[0] - R[4] + R[8]};
    int k = 0;
    for (int i = 1; i < 4; ++i)
        if (c[i] > c[k])
            k = i;
    const double r = std::sqrt(c[k]), f = 0.5 / r;
    Quat q{};
    switch (k) {
    case 0: q = {0.5 * r, (R[7] - R[5]) * f, (R[2] - R[6]) * f, (R[3] - R[1]) * f}; break;
    case 1: q = {(R[7] - R[5]) * f, 0.5 * r, (R[1] + R[3]) * f, (R[2] + R[6]) * f}; break;
    case 2: q = {(R[2] - R[6]) * f, (R[1] + R[3]) * f, 0.5 * r, (R[5] + R[7]) * f}; break;
    default: q = {(R[3] - R[1]) * f, (R[2] + R[6]) * f, (R[5] + R[7]) * f, 0.5 * r}; break;
    }
    if (q[0] < 0.0)
        for (double &x : q)
            x = -x;
    return q;
}

// The stored matrix (column-major) as row-major, and back
Mat3 load_matrix(const double *p) { return {p[0], p[3], p[6], p[1], p[4], p[7], p[2], p[5], p[8]}; }
void store_matrix(const Mat3 &R, double *p)
{
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            p[i + 3 * j] = R[3 * i + j];
}
using se3::detail::mul;
using se3::detail::transpose;

// out = q o exp(xi) on one group block (out may be q)
void compose_exp(Kind kind, const double *q, const double *xi, double *out)
{
    if (kind == Kind::Quaternion) {
        const Quat r = so3::compose(quat(q), so3::exp(vec3(xi)));
        std::copy(r.begin(), r.end(), out);
    } else if (kind == Kind::Matrix) {
        store_matrix(mul(load_matrix(q), so3::matrix(so3::exp(vec3(xi)))), out);
    } else {  // (x, R) o exp(u, w) = (x + R V(w) u, R exp(w))
        const Quat r = quat(q + 3);
        const Vec3 dx = so3::rotate(r, se3::exp_translation(vec3(xi), vec3(xi + 3)));
        const Quat r1 = so3::compose(r, so3::exp(vec3(xi + 3)));
        for (int k = 0; k < 3; ++k)
            out[k] = q[k] + dx[static_cast<std::size_t>(k)];
        std::copy(r1.begin(), r1.end(), out + 3);
    }
}

// log(q0^-1 q1) on one group block
Alg relative_log(Kind kind, const double *q0, const double *q1)
{
    Alg a{};
    if (kind == Kind::Pose) {
        const Quat r0 = quat(q0 + 3);
        const Vec3 dx = so3::rotate(so3::inverse(r0), {q1[0] - q0[0], q1[1] - q0[1],
                                                      q1[2] - q0[2]});
        return se3::log(dx, so3::compose(so3::inverse(r0), quat(q1 + 3)));
    }
    const Vec3 w = kind == Kind::Quaternion
                       ? so3::log(so3::compose(so3::inverse(quat(q0)), quat(q1)))
                       : so3::log(from_matrix(mul(transpose(load_matrix(q0)), load_matrix(q1))));
    std::copy(w.begin(), w.end(), a.begin());
    return a;
}

// w x w blocks of a 3 x 3 (rotations) or a 6 x 6 (poses)
Op widen(const Mat3 &A)
{
    Op o{};
    std::copy(A.begin(), A.end(), o.begin());
    return o;
}
Op tangent(Kind kind, const double *xi)
{
    return kind == Kind::Pose ? se3::tangent({xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]})
                              : widen(so3::tangent(vec3(xi)));
}
Op tangent_inverse(Kind kind, const double *xi)
{
    return kind == Kind::Pose ? se3::tangent_inverse({xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]})
                              : widen(so3::tangent_inverse(vec3(xi)));
}
// Ad_{exp(-xi)}: R(exp(xi))^T on a rotation
Op transport(Kind kind, const double *xi)
{
    return kind == Kind::Pose ? se3::transport({xi[0], xi[1], xi[2], xi[3], xi[4], xi[5]})
                              : widen(transpose(so3::matrix(so3::exp(vec3(xi)))));
}
// ad_v: v~ on a rotation
Op ad(Kind kind, const double *v)
{
    return kind == Kind::Pose ? se3::ad({v[0], v[1], v[2], v[3], v[4], v[5]})
                              : widen(se3::detail::hat(vec3(v)));
}

}  // namespace

ConfigurationSpace::ConfigurationSpace(const std::vector<Block> &blocks) : nq_(0), nv_(0)
{
    for (const Block &b : blocks) {
        parts_.push_back({b.kind, nq_, nv_, b.nv});
        nq_ += stored(b);
        nv_ += b.nv;
        if (b.kind != Kind::Vector) {
            rotation_part_.push_back(static_cast<int>(parts_.size()) - 1);
            ++rotations_;
        }
    }
    if (rotations_ == 0) {  // R^n: the Euclidean bodies, bit for bit those of ga_create
        parts_.clear();
        return;
    }
    part_of_.resize(static_cast<std::size_t>(nv_));
    for (std::size_t p = 0; p < parts_.size(); ++p)
        for (Eigen::Index i = 0; i < parts_[p].nv; ++i)
            part_of_[static_cast<std::size_t>(parts_[p].v0 + i)] = static_cast<int>(p);
}

void ConfigurationSpace::group_retract(const Vec &q, double e, const Vec &w, Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            out.segment(p.q0, p.nv) = q.segment(p.q0, p.nv) + e * w.segment(p.v0, p.nv);
            continue;
        }
        Alg d{};
        for (Eigen::Index k = 0; k < p.nv; ++k)
            d[static_cast<std::size_t>(k)] = e * w[p.v0 + k];
        compose_exp(p.kind, q.data() + p.q0, d.data(), out.data() + p.q0);
    }
}

void ConfigurationSpace::step_to(const Vec &q_n, const Vec &xi, Vec &q) const
{
    group_retract(q_n, 1.0, xi, q);
}

void ConfigurationSpace::group_taylor(const Vec &q, const Vec &v, const Vec &qdd, double h,
                                      Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            out.segment(p.q0, p.nv) = q.segment(p.q0, p.nv) + h * v.segment(p.v0, p.nv) +
                                      (0.5 * h * h) * qdd.segment(p.v0, p.nv);
            continue;
        }
        Alg psi{};
        for (Eigen::Index k = 0; k < p.nv; ++k)
            psi[static_cast<std::size_t>(k)] = h * v[p.v0 + k] + 0.5 * h * h * qdd[p.v0 + k];
        compose_exp(p.kind, q.data() + p.q0, psi.data(), out.data() + p.q0);
    }
}

void ConfigurationSpace::group_shift(Vec &q_pert, const Vec &q, Eigen::Index j, double e) const
{
    const Part &p = part_of(j);
    const Eigen::Index k = j - p.v0;
    if (p.kind == Kind::Vector) {
        q_pert[p.q0 + k] = q[p.q0 + k] + e;
        return;
    }
    Alg psi{};
    psi[static_cast<std::size_t>(k)] = e;
    compose_exp(p.kind, q.data() + p.q0, psi.data(), q_pert.data() + p.q0);
}

void ConfigurationSpace::group_restore(Vec &q_pert, const Vec &q, Eigen::Index j) const
{
    const Part &p = part_of(j);
    if (p.kind == Kind::Vector)
        q_pert[p.q0 + j - p.v0] = q[p.q0 + j - p.v0];
    else
        q_pert.segment(p.q0, stored(p.kind, p.nv)) = q.segment(p.q0, stored(p.kind, p.nv));
}

void ConfigurationSpace::group_hermite(const Vec &q_a, const Vec &v_a, const Vec &q_b,
                                       const Vec &v_b, double h, double h00, double h10, double h01,
                                       double h11, Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            out.segment(p.q0, p.nv) =
                h00 * q_a.segment(p.q0, p.nv) + (h10 * h) * v_a.segment(p.v0, p.nv) +
                h01 * q_b.segment(p.q0, p.nv) + (h11 * h) * v_b.segment(p.v0, p.nv);
            continue;
        }
        const Alg xi = relative_log(p.kind, q_a.data() + p.q0, q_b.data() + p.q0);
        const Op Ti = tangent_inverse(p.kind, xi.data());
        const double *va = v_a.data() + p.v0, *vb = v_b.data() + p.v0;
        const Eigen::Index w = p.nv;
        Alg psi{};
        for (Eigen::Index k = 0; k < w; ++k) {
            double end = 0.0;
            for (Eigen::Index l = 0; l < w; ++l)
                end += Ti[static_cast<std::size_t>(w * k + l)] * vb[l];
            psi[static_cast<std::size_t>(k)] =
                (h10 * h) * va[k] + h01 * xi[static_cast<std::size_t>(k)] + (h11 * h) * end;
        }
        compose_exp(p.kind, q_a.data() + p.q0, psi.data(), out.data() + p.q0);
    }
}

// A pose's translation coordinates scale with its position (the radian of its rotation's)
double ConfigurationSpace::group_magnitude(const Vec &q, Eigen::Index i) const
{
    const Part &p = part_of(i);
    if (p.kind == Kind::Vector)
        return std::fabs(q[p.q0 + i - p.v0]);
    if (p.kind == Kind::Pose && i - p.v0 < 3)
        return std::sqrt(q[p.q0] * q[p.q0] + q[p.q0 + 1] * q[p.q0 + 1] +
                         q[p.q0 + 2] * q[p.q0 + 2]);
    return 1.0;
}

double ConfigurationSpace::group_distance(const Vec &q1, const Vec &q0, Eigen::Index i) const
{
    const Part &p = part_of(i);
    if (p.kind == Kind::Vector)
        return std::fabs(q1[p.q0 + i - p.v0] - q0[p.q0 + i - p.v0]);
    return std::fabs(relative_log(p.kind, q0.data() + p.q0,
                                  q1.data() + p.q0)[static_cast<std::size_t>(i - p.v0)]);
}

// A tangent vector s at q_n (q_n o exp(e s)) seen at q_n1 = q_n o exp(xi): q_n o exp(e s) o
// exp(xi) = q_n1 o exp(e Ad_{exp(-xi)} s); an increment d of xi moves q_n1 by T(xi) d (sec.
// 14, 16).
void ConfigurationSpace::group_newmark_derivative(const Vec &q_n, const Vec &q_n1, const Vec &s_q,
                                                  const Vec &s_v, const Vec &s_a, const Vec &s_a1,
                                                  double h, double beta, Vec &out) const
{
    for (const Part &p : parts_) {
        const Eigen::Index v0 = p.v0, w = p.nv;
        if (p.kind == Kind::Vector) {
            out.segment(v0, w) =
                s_q.segment(v0, w) + h * s_v.segment(v0, w) +
                (h * h) * ((0.5 - beta) * s_a.segment(v0, w) + beta * s_a1.segment(v0, w));
            continue;
        }
        const Alg xi = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        const Op A = transport(p.kind, xi.data()), T = tangent(p.kind, xi.data());
        Alg d{};
        for (Eigen::Index k = 0; k < w; ++k)
            d[static_cast<std::size_t>(k)] =
                h * s_v[v0 + k] + (h * h) * ((0.5 - beta) * s_a[v0 + k] + beta * s_a1[v0 + k]);
        for (Eigen::Index i = 0; i < w; ++i) {
            double r = 0.0;
            for (Eigen::Index k = 0; k < w; ++k)
                r += A[static_cast<std::size_t>(w * i + k)] * s_q[v0 + k] +
                     T[static_cast<std::size_t>(w * i + k)] * d[static_cast<std::size_t>(k)];
            out[v0 + i] = r;
        }
    }
}

void ConfigurationSpace::group_tangent(const Vec &q_n, const Vec &q_n1, const Vec &d, Vec &out,
                                       bool transposed) const
{
    for (const Part &p : parts_) {
        const Eigen::Index w = p.nv;
        if (p.kind == Kind::Vector) {
            if (!transposed)
                out.segment(p.v0, w) += d.segment(p.v0, w);
            else if (&out != &d)
                out.segment(p.v0, w) = d.segment(p.v0, w);
            continue;
        }
        const Alg xi = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        const Op T = tangent(p.kind, xi.data());
        Alg x{};
        for (Eigen::Index k = 0; k < w; ++k)
            x[static_cast<std::size_t>(k)] = d[p.v0 + k];
        for (Eigen::Index i = 0; i < w; ++i) {
            double r = 0.0;
            for (Eigen::Index k = 0; k < w; ++k)
                r += T[static_cast<std::size_t>(transposed ? w * k + i : w * i + k)] *
                     x[static_cast<std::size_t>(k)];
            if (transposed)
                out[p.v0 + i] = r;
            else
                out[p.v0 + i] += r;
        }
    }
}

void ConfigurationSpace::group_transport_transpose(const Vec &q_n, const Vec &q_n1, Vec &m) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index w = p.nv;
        const Alg xi = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        const Op A = transport(p.kind, xi.data());
        Alg x{};
        for (Eigen::Index k = 0; k < w; ++k)
            x[static_cast<std::size_t>(k)] = m[p.v0 + k];
        for (Eigen::Index i = 0; i < w; ++i) {
            double r = 0.0;
            for (Eigen::Index k = 0; k < w; ++k)
                r += A[static_cast<std::size_t>(w * k + i)] * x[static_cast<std::size_t>(k)];
            m[p.v0 + i] = r;
        }
    }
}

// out += c (-ad_u^T g): u x g on a rotation
void ConfigurationSpace::add_cross(double c, const Vec &u, const Vec &g, Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index w = p.nv;
        const Op A = ad(p.kind, u.data() + p.v0);
        for (Eigen::Index i = 0; i < w; ++i) {
            double r = 0.0;
            for (Eigen::Index k = 0; k < w; ++k)
                r += A[static_cast<std::size_t>(w * k + i)] * g[p.v0 + k];
            out[p.v0 + i] -= c * r;
        }
    }
}

void ConfigurationSpace::increment_between(const Vec &q_n, const Vec &q_n1, Vec &xi) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            xi.segment(p.v0, p.nv) = q_n1.segment(p.q0, p.nv) - q_n.segment(p.q0, p.nv);
            continue;
        }
        const Alg x = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        for (Eigen::Index k = 0; k < p.nv; ++k)
            xi[p.v0 + k] = x[static_cast<std::size_t>(k)];
    }
}

void ConfigurationSpace::right_multiply_tangent(const Vec &xi, double *A, Eigen::Index rows,
                                                Eigen::Index ld) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index w = p.nv;
        const Op T = tangent(p.kind, xi.data() + p.v0);
        double *c = A + p.v0 * ld;
        for (Eigen::Index r = 0; r < rows; ++r) {
            Alg a{};
            for (Eigen::Index k = 0; k < w; ++k)
                a[static_cast<std::size_t>(k)] = c[r + k * ld];
            for (Eigen::Index j = 0; j < w; ++j) {
                double s = 0.0;
                for (Eigen::Index k = 0; k < w; ++k)
                    s += a[static_cast<std::size_t>(k)] * T[static_cast<std::size_t>(w * k + j)];
                c[r + j * ld] = s;
            }
        }
    }
}

int ConfigurationSpace::rotation_of(Eigen::Index j, int *local) const
{
    if (euclidean())
        return -1;
    const int p = part_of_[static_cast<std::size_t>(j)];
    if (parts_[p].kind == Kind::Vector)
        return -1;
    *local = static_cast<int>(j - parts_[p].v0);
    return static_cast<int>(std::lower_bound(rotation_part_.begin(), rotation_part_.end(), p) -
                            rotation_part_.begin());
}

void ConfigurationSpace::rotation_tangents(const Vec &xi, double *T) const
{
    for (const int pi : rotation_part_) {
        const Part &p = parts_[pi];
        const Op t = tangent(p.kind, xi.data() + p.v0);
        std::copy(t.begin(), t.begin() + p.nv * p.nv, T);
        T += p.nv * p.nv;
    }
}

void ConfigurationSpace::rotation_brackets(const Vec &v, const Vec *xi, double *G) const
{
    for (const int pi : rotation_part_) {
        const Part &p = parts_[pi];
        const Eigen::Index w = p.nv;
        const Op A = ad(p.kind, v.data() + p.v0);
        const Op T = xi ? tangent(p.kind, xi->data() + p.v0) : Op{};
        for (Eigen::Index l = 0; l < w; ++l)
            for (Eigen::Index c = 0; c < w; ++c) {
                double g = 0.0;
                if (xi)
                    for (Eigen::Index j = 0; j < w; ++j)
                        g -= A[static_cast<std::size_t>(w * l + j)] *
                             T[static_cast<std::size_t>(w * j + c)];
                else
                    g = -A[static_cast<std::size_t>(w * l + c)];
                G[w * l + c] = g;
            }
        G += w * w;
    }
}

// Z <- Z + J (-ad_v) on each group block's columns: Z w += J [w, v], [w, v] = -ad_v w
void ConfigurationSpace::add_bracket(const Vec &v, const double *J, Eigen::Index rows,
                                     double *Z) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index w = p.nv;
        const Op A = ad(p.kind, v.data() + p.v0);
        for (Eigen::Index k = 0; k < w; ++k) {
            double *z = Z + (p.v0 + k) * rows;
            for (Eigen::Index l = 0; l < w; ++l) {
                const double c = A[static_cast<std::size_t>(w * l + k)];
                if (c == 0.0)
                    continue;
                const double *jl = J + (p.v0 + l) * rows;
                for (Eigen::Index r = 0; r < rows; ++r)
                    z[r] -= c * jl[r];
            }
        }
    }
}

void ConfigurationSpace::bracket(const Vec &w, const Vec &v, Vec &u) const
{
    u.setZero();
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index n = p.nv;
        const Op A = ad(p.kind, v.data() + p.v0);
        for (Eigen::Index l = 0; l < n; ++l) {
            double s = 0.0;
            for (Eigen::Index k = 0; k < n; ++k)
                s += A[static_cast<std::size_t>(n * l + k)] * w[p.v0 + k];
            u[p.v0 + l] = -s;
        }
    }
}

void ConfigurationSpace::bracket_transpose_add(const Vec &v, const Vec &u, Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index n = p.nv;
        const Op A = ad(p.kind, v.data() + p.v0);
        for (Eigen::Index k = 0; k < n; ++k) {
            double s = 0.0;
            for (Eigen::Index l = 0; l < n; ++l)
                s += A[static_cast<std::size_t>(n * l + k)] * u[p.v0 + l];
            out[p.v0 + k] -= s;
        }
    }
}

namespace {
// How far a block's storage is from a rotation: |q| - 1 of a quaternion, the largest entry of
// R^T R - I of a matrix (infinite with det <= 0); NaN stays NaN
double rotation_error(Kind kind, const double *b)
{
    if (kind != Kind::Matrix) {
        const double n = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
        return std::fabs(n - 1.0);
    }
    const Mat3 R = load_matrix(b), RtR = mul(transpose(R), R);
    double off = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            off = std::max(off, std::fabs(RtR[3 * i + j] - (i == j ? 1.0 : 0.0)));
    const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                       R[2] * (R[3] * R[7] - R[4] * R[6]);
    return std::isnan(off) ? off : det > 0.0 ? off : std::numeric_limits<double>::infinity();
}
// where a group block's rotation starts in q (a pose's quaternion after its position)
Eigen::Index rotation_storage(Kind kind, Eigen::Index q0) { return kind == Kind::Pose ? q0 + 3 : q0; }
}  // namespace

Eigen::Index ConfigurationSpace::invalid_rotation(const double *q) const
{
    constexpr double kTol = 1e-6;
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Eigen::Index at = rotation_storage(p.kind, p.q0);
        if (!(rotation_error(p.kind, q + at) <= kTol))
            return at;
    }
    return -1;
}

void ConfigurationSpace::normalize_rotations(double *q, double exact) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        double *b = q + rotation_storage(p.kind, p.q0);
        if (!(rotation_error(p.kind, b) > exact))
            continue;
        if (p.kind != Kind::Matrix) {
            const double n = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
            for (int k = 0; k < 4; ++k)
                b[k] /= n;
            continue;
        }
        // the nearest rotation (polar factor) by Newton-Schulz, R <- R (3 I - R^T R) / 2: each
        // pass squares the error, 1e-6 -> 1e-12 -> round-off
        Mat3 R = load_matrix(b);
        for (int pass = 0; pass < 3; ++pass) {
            Mat3 E = mul(transpose(R), R);
            for (int i = 0; i < 9; ++i)
                E[static_cast<std::size_t>(i)] = 0.5 * ((i % 4 == 0 ? 3.0 : 0.0) -
                                                        E[static_cast<std::size_t>(i)]);
            R = mul(R, E);
        }
        store_matrix(R, b);
    }
}

}  // namespace ga
