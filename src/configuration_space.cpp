// The group blocks of ga::ConfigurationSpace (docs/algorithms.md sec. 14): rotations stored
// as unit quaternions or as column-major rotation matrices, moved by right increments,
// q o exp(psi), with psi in the body frame; vector blocks as in R^n.
#include "configuration_space.hpp"

#include "lie/so3.hpp"

namespace ga {

namespace {

using so3::Mat3;
using so3::Quat;
using so3::Vec3;

Vec3 vec3(const double *p) { return {p[0], p[1], p[2]}; }

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
Mat3 multiply(const Mat3 &A, const Mat3 &B)
{
    Mat3 C{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
    return C;
}
Mat3 transpose(const Mat3 &A) { return {A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8]}; }

// out = q o exp(psi) on one rotation block (out may be q)
void compose_exp(ConfigurationSpace::Kind kind, const double *q, const Vec3 &psi, double *out)
{
    if (kind == ConfigurationSpace::Kind::Quaternion) {
        const Quat r = so3::compose({q[0], q[1], q[2], q[3]}, so3::exp(psi));
        for (int k = 0; k < 4; ++k)
            out[k] = r[k];
    } else {
        store_matrix(multiply(load_matrix(q), so3::matrix(so3::exp(psi))), out);
    }
}

// log(q0^-1 q1) on one rotation block
Vec3 relative_log(ConfigurationSpace::Kind kind, const double *q0, const double *q1)
{
    if (kind == ConfigurationSpace::Kind::Quaternion)
        return so3::log(
            so3::compose(so3::inverse({q0[0], q0[1], q0[2], q0[3]}), {q1[0], q1[1], q1[2], q1[3]}));
    return so3::log(from_matrix(multiply(transpose(load_matrix(q0)), load_matrix(q1))));
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
        const double *d = w.data() + p.v0;
        compose_exp(p.kind, q.data() + p.q0, {e * d[0], e * d[1], e * d[2]}, out.data() + p.q0);
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
        Vec3 psi{};
        for (int k = 0; k < 3; ++k)
            psi[k] = h * v[p.v0 + k] + 0.5 * h * h * qdd[p.v0 + k];
        compose_exp(p.kind, q.data() + p.q0, psi, out.data() + p.q0);
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
    Vec3 psi{};
    psi[static_cast<std::size_t>(k)] = e;
    compose_exp(p.kind, q.data() + p.q0, psi, q_pert.data() + p.q0);
}

void ConfigurationSpace::group_restore(Vec &q_pert, const Vec &q, Eigen::Index j) const
{
    const Part &p = part_of(j);
    if (p.kind == Kind::Vector)
        q_pert[p.q0 + j - p.v0] = q[p.q0 + j - p.v0];
    else
        q_pert.segment(p.q0, p.kind == Kind::Quaternion ? 4 : 9) =
            q.segment(p.q0, p.kind == Kind::Quaternion ? 4 : 9);
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
        const Vec3 xi = relative_log(p.kind, q_a.data() + p.q0, q_b.data() + p.q0);
        const Mat3 Ti = so3::tangent_inverse(xi);
        const double *va = v_a.data() + p.v0, *vb = v_b.data() + p.v0;
        Vec3 psi{};
        for (int k = 0; k < 3; ++k) {
            const double end = Ti[3 * k] * vb[0] + Ti[3 * k + 1] * vb[1] + Ti[3 * k + 2] * vb[2];
            psi[k] = (h10 * h) * va[k] + h01 * xi[k] + (h11 * h) * end;
        }
        compose_exp(p.kind, q_a.data() + p.q0, psi, out.data() + p.q0);
    }
}

double ConfigurationSpace::group_magnitude(const Vec &q, Eigen::Index i) const
{
    const Part &p = part_of(i);
    return p.kind == Kind::Vector ? std::fabs(q[p.q0 + i - p.v0]) : 1.0;
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
// exp(xi) = q_n1 o exp(e Ad_{exp(-xi)} s), Ad_{exp(-xi)} = R(exp(xi))^T on SO(3); an increment
// d of xi moves q_n1 by T(xi) d (sec. 14, 16).
void ConfigurationSpace::group_newmark_derivative(const Vec &q_n, const Vec &q_n1, const Vec &s_q,
                                                  const Vec &s_v, const Vec &s_a, const Vec &s_a1,
                                                  double h, double beta, Vec &out) const
{
    for (const Part &p : parts_) {
        const Eigen::Index v0 = p.v0, nv = p.nv;
        if (p.kind == Kind::Vector) {
            out.segment(v0, nv) =
                s_q.segment(v0, nv) + h * s_v.segment(v0, nv) +
                (h * h) * ((0.5 - beta) * s_a.segment(v0, nv) + beta * s_a1.segment(v0, nv));
            continue;
        }
        const Vec3 xi = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        const Mat3 E = so3::matrix(so3::exp(xi)), T = so3::tangent(xi);
        double d[3];
        for (int k = 0; k < 3; ++k)
            d[k] = h * s_v[v0 + k] + (h * h) * ((0.5 - beta) * s_a[v0 + k] + beta * s_a1[v0 + k]);
        for (int i = 0; i < 3; ++i) {
            double r = 0.0;
            for (int k = 0; k < 3; ++k)
                r += E[3 * k + i] * s_q[v0 + k] + T[3 * i + k] * d[k];
            out[v0 + i] = r;
        }
    }
}

void ConfigurationSpace::group_tangent(const Vec &q_n, const Vec &q_n1, const Vec &d, Vec &out,
                                       bool transposed) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            if (!transposed)
                out.segment(p.v0, p.nv) += d.segment(p.v0, p.nv);
            else if (&out != &d)
                out.segment(p.v0, p.nv) = d.segment(p.v0, p.nv);
            continue;
        }
        const Mat3 T = so3::tangent(relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0));
        const double x[3] = {d[p.v0], d[p.v0 + 1], d[p.v0 + 2]};
        for (int i = 0; i < 3; ++i) {
            double r = 0.0;
            for (int k = 0; k < 3; ++k)
                r += (transposed ? T[3 * k + i] : T[3 * i + k]) * x[k];
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
        // (Ad_{exp(-xi)})^T = R(exp(xi))
        const Mat3 E =
            so3::matrix(so3::exp(relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0)));
        const double x[3] = {m[p.v0], m[p.v0 + 1], m[p.v0 + 2]};
        for (int i = 0; i < 3; ++i)
            m[p.v0 + i] = E[3 * i] * x[0] + E[3 * i + 1] * x[1] + E[3 * i + 2] * x[2];
    }
}

void ConfigurationSpace::add_cross(double c, const Vec &u, const Vec &g, Vec &out) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Vec3 x = so3::cross(vec3(u.data() + p.v0), vec3(g.data() + p.v0));
        for (int k = 0; k < 3; ++k)
            out[p.v0 + k] += c * x[static_cast<std::size_t>(k)];
    }
}

void ConfigurationSpace::increment_between(const Vec &q_n, const Vec &q_n1, Vec &xi) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector) {
            xi.segment(p.v0, p.nv) = q_n1.segment(p.q0, p.nv) - q_n.segment(p.q0, p.nv);
            continue;
        }
        const Vec3 x = relative_log(p.kind, q_n.data() + p.q0, q_n1.data() + p.q0);
        for (int k = 0; k < 3; ++k)
            xi[p.v0 + k] = x[static_cast<std::size_t>(k)];
    }
}

void ConfigurationSpace::right_multiply_tangent(const Vec &xi, double *A, Eigen::Index rows,
                                                Eigen::Index ld) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        const Mat3 T = so3::tangent(vec3(xi.data() + p.v0));
        double *c0 = A + p.v0 * ld, *c1 = c0 + ld, *c2 = c1 + ld;
        for (Eigen::Index r = 0; r < rows; ++r) {
            const double a0 = c0[r], a1 = c1[r], a2 = c2[r];
            c0[r] = a0 * T[0] + a1 * T[3] + a2 * T[6];
            c1[r] = a0 * T[1] + a1 * T[4] + a2 * T[7];
            c2[r] = a0 * T[2] + a1 * T[5] + a2 * T[8];
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
    for (std::size_t r = 0; r < rotation_part_.size(); ++r) {
        const Mat3 t = so3::tangent(vec3(xi.data() + parts_[rotation_part_[r]].v0));
        std::copy(t.begin(), t.end(), T + 9 * r);
    }
}

void ConfigurationSpace::add_bracket(const Vec &v, const double *J, Eigen::Index rows,
                                     double *Z) const
{
    for (const Part &p : parts_) {
        if (p.kind == Kind::Vector)
            continue;
        // w x v = -v~ w: column k of J (-v~) is -sum_l J_l (v~)_{lk}
        const double *w = v.data() + p.v0;
        const Mat3 vh{0.0, -w[2], w[1], w[2], 0.0, -w[0], -w[1], w[0], 0.0};
        for (int k = 0; k < 3; ++k) {
            double *z = Z + (p.v0 + k) * rows;
            for (int l = 0; l < 3; ++l) {
                const double c = vh[3 * l + k];
                if (c == 0.0)
                    continue;
                const double *jl = J + (p.v0 + l) * rows;
                for (Eigen::Index r = 0; r < rows; ++r)
                    z[r] -= c * jl[r];
            }
        }
    }
}

Eigen::Index ConfigurationSpace::invalid_rotation(const double *q) const
{
    constexpr double kTol = 1e-6;
    for (const Part &p : parts_) {
        const double *b = q + p.q0;
        if (p.kind == Kind::Quaternion) {
            const double n = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] + b[3] * b[3]);
            if (!(std::fabs(n - 1.0) <= kTol))
                return p.q0;
        } else if (p.kind == Kind::Matrix) {
            const Mat3 R = load_matrix(b), RtR = multiply(transpose(R), R);
            double off = 0.0;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    off = std::max(off, std::fabs(RtR[3 * i + j] - (i == j ? 1.0 : 0.0)));
            const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) -
                               R[1] * (R[3] * R[8] - R[5] * R[6]) +
                               R[2] * (R[3] * R[7] - R[4] * R[6]);
            if (!(off <= kTol) || !(det > 0.0))
                return p.q0;
        }
    }
    return -1;
}

}  // namespace ga
