// The small motions about a moving state (t, q, v) (docs/algorithms.md sec. 15, "About a
// moving state"): in the chart q(z) = q0 + N z + R h(z) of the constraint manifold at q0
// (N, R orthonormal bases of Phi_q's null space and of its rows' span; h keeps Phi = 0) with
// v(z, w) = N w + R k(z, w) (k keeps Phi_q v + Phi_t = 0), z' = N^T v = w exactly, so
// x = (z, w) obeys x' = F(x) with F = (w, N^T qdd(q(z), v(z, w))), qdd the consistent
// acceleration. A = dF/dx at (0, N^T v0), by central differences of qdd: it holds the
// centripetal and Coriolis terms that the tangent system at rest does not.
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/LU>
#include <Eigen/QR>

#include "at_rest.hpp"
#include "operating_point.hpp"

namespace ga {

namespace {

class Chart {
public:
    Chart(Stepper &kernel, double t)
        : model_(kernel.model), diag_(kernel.diag), t_(t), n_(kernel.nv()), m_(kernel.m()),
          f_(kernel.nv())
    {
        M_.copy_layout(kernel.matrix(GA_MATRIX_MASS));
        J_.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
    }
    Mat N, R;
    ga_status jacobian(const Vec &q, Mat &J)
    {
        if (m_ == 0) {
            J.resize(0, n_);
            return GA_OK;
        }
        if (auto st = model_.jacobian(t_, q, J_))
            return st;
        J_.to_dense(J);
        return GA_OK;
    }
    ga_status constraint(double t, const Vec &q, Vec &phi)
    {
        phi.resize(m_);
        return m_ > 0 ? model_.constraint(t, q, phi) : GA_OK;
    }
    // Phi_t: the callback, or a central difference in t (exactly 0 without t in Phi)
    ga_status phi_t(double t, const Vec &q, Vec &out)
    {
        out.setZero(m_);
        if (m_ == 0)
            return GA_OK;
        if (model_.cb.constraint_dt)
            return model_.constraint_dt(t, q, out);
        const double e = 6.06e-6 * std::max(1.0, std::fabs(t));
        Vec p(m_), mi(m_);
        if (auto st = constraint(t + e, q, p))
            return st;
        if (auto st = constraint(t - e, q, mi))
            return st;
        out = (p - mi) / (2.0 * e);
        return GA_OK;
    }
    // Phi_qq(v, v) + 2 Phi_qt v + Phi_tt: the callback, or the central difference of
    // Phi_q v + Phi_t along (q + s v, t + s)
    ga_status accel_term(const Vec &q, const Vec &v, Vec &out)
    {
        out.setZero(m_);
        if (m_ == 0)
            return GA_OK;
        if (model_.cb.constraint_accel)
            return model_.constraint_accel(t_, q, v, out);
        const double s = std::cbrt(std::numeric_limits<double>::epsilon()) *
                         std::max(rest::max_abs(q), 1.0) / std::max(rest::max_abs(v), 1.0);
        Vec g[2], pt(m_), qs(n_);
        Mat J;
        for (int side = 0; side < 2; ++side) {
            const double sig = side == 0 ? s : -s;
            model_.space.shifted(q, sig, v, qs);
            if (auto st = jacobian(qs, J))
                return st;
            if (auto st = phi_t(t_ + sig, qs, pt))
                return st;
            g[side] = J * v + pt;
        }
        out = (g[0] - g[1]) / (2.0 * s);
        return GA_OK;
    }
    // the consistent acceleration at (q, v): [M, J^T; J, 0] [a; lambda] = [f; -accel]
    ga_status acceleration(const Vec &q, const Vec &v, Vec &a)
    {
        if (auto st = model_.mass(t_, q, M_))
            return st;
        if (auto st = model_.force(t_, q, v, f_))
            return st;
        Mat M, J;
        M_.to_dense(M);
        if (auto st = jacobian(q, J))
            return st;
        Vec c;
        if (auto st = accel_term(q, v, c))
            return st;
        Mat S = Mat::Zero(n_ + m_, n_ + m_);
        S.topLeftCorner(n_, n_) = M;
        S.bottomLeftCorner(m_, n_) = J;
        S.topRightCorner(n_, m_) = J.transpose();
        Vec rhs(n_ + m_);
        rhs.head(n_) = f_;
        rhs.tail(m_) = -c;
        const Eigen::FullPivLU<Mat> lu(S);
        if (!lu.isInvertible())
            return diag_.fail(GA_ERR_SINGULAR, "ga_state_space_motion: [M, Phi_q^T; Phi_q, 0] "
                                               "is singular near q (a free direction without "
                                               "mass, or redundant constraints)");
        a = lu.solve(rhs).head(n_);
        if (!all_finite(a))
            return diag_.fail(GA_ERR_NONFINITE,
                              "ga_state_space_motion: the acceleration is not finite near q");
        return GA_OK;
    }
    // (q, v) at chart point (z, w): Newton on Phi(q0 + N z + R h) = 0 in h, then k
    ga_status point(const Vec &q0, const Vec &z, const Vec &w, Vec &q, Vec &v)
    {
        const Vec dz = N * z;
        model_.space.shifted(q0, 1.0, dz, q);
        Mat J;
        Vec phi, pt;
        const double scale = std::max(1.0, rest::max_abs(q0));
        for (int it = 0; it < 30 && m_ > 0; ++it) {
            if (auto st = constraint(t_, q, phi))
                return st;
            if (rest::max_abs(phi) <= 1e-15 * scale)
                break;
            if (auto st = jacobian(q, J))
                return st;
            const Mat JR = J * R;
            const Vec dh = R * JR.completeOrthogonalDecomposition().solve(-phi), qk = q;
            model_.space.shifted(qk, 1.0, dh, q);
            // a correction at q's round-off ends it too: Phi = x^2 + y^2 - L^2 in mm units
            // keeps a residual of eps L^2, far above 1e-15 |q|
            if (rest::max_abs(dh) <= 8.0 * std::numeric_limits<double>::epsilon() * scale)
                break;
            if (it == 29)
                return diag_.fail(GA_ERR_NEWTON, "ga_state_space_motion: the chart's projection "
                                                 "onto the constraints did not converge near q");
        }
        v = N * w;
        if (m_ > 0) {
            if (auto st = jacobian(q, J))
                return st;
            if (auto st = phi_t(t_, q, pt))
                return st;
            const Mat JR = J * R;
            v.noalias() += R * JR.completeOrthogonalDecomposition().solve(-(J * v + pt));
        }
        return GA_OK;
    }

private:
    Model &model_;
    Diagnostics &diag_;
    double t_;
    int n_, m_;
    Vec f_;
    ModelMatrix M_, J_;
};

}  // namespace

ga_status motion_state_space(Stepper &kernel, double t, const double *q_in, const double *v_in,
                             const double *y_in, StateSpace &out)
{
    const char *name = "ga_state_space_motion";
    Diagnostics &diag = kernel.diag;
    const int n = kernel.nv(), m = kernel.m(), nr = kernel.r();
    const Vec q0 = Eigen::Map<const Vec>(q_in, n), v0 = Eigen::Map<const Vec>(v_in, n);
    Vec y = nr > 0 ? Vec(Eigen::Map<const Vec>(y_in, nr)) : Vec(0);
    if (!all_finite(q0) || !all_finite(v0) || !all_finite(y))
        return diag.fail(GA_ERR_ARG, "%s: q, v or y is not finite", name);
    // the force sees y (first-order states, docs/algorithms.md sec. 9)
    const Restore<const Vec *> keep(kernel.model.y_now);
    kernel.model.y_now = &y;
    Chart chart(kernel, t);
    Mat J;
    Vec phi, pt;
    if (auto st = chart.constraint(t, q0, phi))
        return st;
    if (auto st = chart.jacobian(q0, J))
        return st;
    if (auto st = chart.phi_t(t, q0, pt))
        return st;
    const double qs = std::max(1.0, rest::max_abs(q0)), vs = std::max(1.0, rest::max_abs(v0));
    if (m > 0 && rest::max_abs(phi) > 1e-8 * qs)
        return diag.fail(GA_ERR_INCONSISTENT, "%s: q is off the constraints (|Phi| = %.3g)", name,
                         rest::max_abs(phi));
    if (m > 0 && rest::max_abs(J * v0 + pt) > 1e-8 * vs)
        return diag.fail(GA_ERR_INCONSISTENT,
                         "%s: v violates the velocity constraint (|Phi_q v + Phi_t| = %.3g)", name,
                         rest::max_abs(J * v0 + pt));
    const rest::NullSpace ns(J);
    chart.N = ns.N;
    if (m > 0) {
        Eigen::ColPivHouseholderQR<Mat> qr(J.transpose());
        const Mat Q = qr.householderQ();
        chart.R = Q.leftCols(ns.rank);
    } else {
        chart.R.resize(n, 0);
    }
    const int d = static_cast<int>(chart.N.cols());
    const Vec w0 = chart.N.transpose() * v0;
    out.dof = d;
    out.dim = 2 * d + nr;
    out.A.setZero(out.dim, out.dim);
    out.A.block(0, d, d, d).setIdentity();
    // central differences of (N^T qdd, g) in z_j, w_j and y_j (steps as for K_t and C_t)
    enum Kind { Z, W, Y };
    Vec q, v, ap, am, gp(nr), gm(nr), z = Vec::Zero(d), w = w0;
    const auto column = [&](Kind kind, int j, double e) -> ga_status {
        Vec &x = kind == Z ? z : kind == W ? w : y;
        const double x0 = x[j];
        for (int side = 0; side < 2; ++side) {
            x[j] = x0 + (side == 0 ? e : -e);
            ga_status st = chart.point(q0, z, w, q, v);
            if (!st)
                st = chart.acceleration(q, v, side == 0 ? ap : am);
            if (!st && nr > 0)
                st = kernel.model.rate(t, q, v, y, side == 0 ? gp : gm);
            if (st) {
                x[j] = x0;
                return st;
            }
        }
        x[j] = x0;
        const int col = kind == Z ? j : kind == W ? d + j : 2 * d + j;
        out.A.block(d, col, d, 1) = chart.N.transpose() * (ap - am) / (2.0 * e);
        if (nr > 0)
            out.A.block(2 * d, col, nr, 1) = (gp - gm) / (2.0 * e);
        return GA_OK;
    };
    for (int j = 0; j < d; ++j)
        for (const Kind kind : {Z, W})
            if (auto st = column(kind, j, rest::step_for(kind == Z ? qs : vs)))
                return st;
    for (int j = 0; j < nr; ++j)
        if (auto st = column(Y, j, rest::step_for(y[j])))
            return st;
    out.N = chart.N;
    return GA_OK;
}

}  // namespace ga
