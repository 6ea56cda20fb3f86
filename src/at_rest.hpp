// The model at rest (v = 0, qdd = 0), dense, for the operating points (operating_point.cpp,
// static_path.cpp): its pieces by the callbacks, K_t and C_t by them or by central
// differences, and the null space of Phi_q. Its own scratch: the solver's stays as it was.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>

#include "stepper.hpp"

namespace ga {
namespace rest {

inline Mat dense_of(const ModelMatrix &A)
{
    Mat D;
    A.to_dense(D);
    return D;
}

inline double max_abs(const Vec &x)
{
    return x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
}

// A mass factorization to divide by: no zero pivot and a condition well above round-off. Not
// by its determinant, which underflows for a well-conditioned mass of 40 masses of 1e-9 kg.
template <class LU> bool invertible(const LU &lu)
{
    const auto pivots = lu.matrixLU().diagonal().cwiseAbs();
    return (pivots.size() == 0 || pivots.minCoeff() > 0.0) && lu.rcond() > 1e-13;
}

// cbrt(eps) times the size of x: the central difference's truncation and round-off balance
inline double step_for(double x)
{
    return 6.06e-6 * std::max(std::fabs(x), 1.0);
}

// The model's pieces at rest (v = 0, qdd = 0), dense.
class AtRest {
public:
    AtRest(Stepper &kernel, double t)
        : k_(kernel), model_(kernel.model), t_(t), n_(kernel.nv()), m_(kernel.m()),
          r_(kernel.r()), zero_(Vec::Zero(kernel.nv())), f_(kernel.nv()),
          y_before_(kernel.model.y_now)
    {
        M_.copy_layout(kernel.matrix(GA_MATRIX_MASS));
        J_.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
        K_.copy_layout(kernel.matrix(GA_MATRIX_STIFFNESS));
        C_.copy_layout(kernel.matrix(GA_MATRIX_DAMPING));
    }
    ~AtRest() { model_.y_now = y_before_; }
    AtRest(const AtRest &) = delete;
    AtRest &operator=(const AtRest &) = delete;
    int n() const { return n_; }
    int m() const { return m_; }
    int r() const { return r_; }

    // First-order states (docs/algorithms.md sec. 9): the force sees y, which stays alive
    // while this is used; y' = g(q, 0, y).
    void states(const Vec &y) { model_.y_now = &y; }
    ga_status rate(const Vec &q, const Vec &y, Vec &g)
    {
        g.resize(r_);
        return model_.rate(t_, q, zero_, y, g);
    }
    // g_q, g_v, g_y and f_y at (q, 0, y): the coupling callback, or central differences
    ga_status coupling(const Vec &q, const Vec &y, CouplingBlocks &B)
    {
        B.allocate(n_, r_);
        const Restore<const Vec *> keep(model_.y_now);
        model_.y_now = &y;
        if (model_.cb.coupling) {
            Vec f, g;
            return model_.coupling(t_, q, zero_, y, f, g, B);
        }
        Vec qq = q, v = zero_, yy = y, gp(r_), gm(r_), fp(n_), fm(n_);
        const ConfigurationSpace &space = model_.space;
        for (int j = 0; j < n_; ++j) {
            const double e = step_for(q[j]);
            space.shift_coordinate(qq, q, j, e);
            if (auto st = model_.rate(t_, qq, zero_, y, gp))
                return st;
            space.shift_coordinate(qq, q, j, -e);
            if (auto st = model_.rate(t_, qq, zero_, y, gm))
                return st;
            space.restore_coordinate(qq, q, j);
            B.g_q.col(j) = (gp - gm) / (2.0 * e);
            const double ev = step_for(0.0);
            v[j] = ev;
            if (auto st = model_.rate(t_, q, v, y, gp))
                return st;
            v[j] = -ev;
            if (auto st = model_.rate(t_, q, v, y, gm))
                return st;
            v[j] = 0.0;
            B.g_v.col(j) = (gp - gm) / (2.0 * ev);
        }
        model_.y_now = &yy;
        for (int j = 0; j < r_; ++j) {
            const double e = step_for(y[j]);
            yy[j] = y[j] + e;
            if (auto st = model_.rate(t_, q, zero_, yy, gp))
                return st;
            if (auto st = model_.force(t_, q, zero_, fp))
                return st;
            yy[j] = y[j] - e;
            if (auto st = model_.rate(t_, q, zero_, yy, gm))
                return st;
            if (auto st = model_.force(t_, q, zero_, fm))
                return st;
            yy[j] = y[j];
            B.g_y.col(j) = (gp - gm) / (2.0 * e);
            B.f_y.col(j) = (fp - fm) / (2.0 * e);
        }
        return GA_OK;
    }

    ga_status force(const Vec &q, Vec &f) { return model_.force(t_, q, zero_, f); }
    ga_status constraint(const Vec &q, Vec &phi)
    {
        if (m_ == 0) {
            phi.resize(0);
            return GA_OK;
        }
        phi.resize(m_);
        return model_.constraint(t_, q, phi);
    }
    ga_status jacobian(const Vec &q, Mat &J)
    {
        if (m_ == 0) {
            J.resize(0, n_);
            return GA_OK;
        }
        if (auto st = model_.jacobian(t_, q, J_))
            return st;
        J = dense_of(J_);
        return GA_OK;
    }
    ga_status mass(const Vec &q, Mat &M)
    {
        if (auto st = model_.mass(t_, q, M_))
            return st;
        M = dense_of(M_);
        return GA_OK;
    }
    const Vec &last_force() const { return f_; }  // f of the last residual
    // r = -f(q, 0, t) + Phi_q^T lambda: the static part of r^q (eq. 1 at rest)
    ga_status residual(const Vec &q, const Vec &lambda, Vec &r, Mat *J = nullptr)
    {
        Mat Jl;
        Mat &Jq = J ? *J : Jl;
        if (auto st = force(q, f_))
            return st;
        if (auto st = jacobian(q, Jq))
            return st;
        r = -f_;
        if (m_ > 0)
            r.noalias() += Jq.transpose() * lambda;
        return GA_OK;
    }
    // K_t at rest: d(-f + Phi_q^T lambda)/dq, the callback or central differences of r
    ga_status stiffness(const Vec &q, const Vec &lambda, Mat &K)
    {
        if (model_.cb.stiffness) {
            if (K_.zero()) {
                K.setZero(n_, n_);
                return GA_OK;
            }
            const Restore<ga_tangent_mode> keep(model_.tangent_mode);
            model_.tangent_mode = GA_TANGENT_AUTO;
            Vec unused;
            if (auto st = model_.stiffness(t_, q, zero_, zero_, lambda, unused, M_, K_))
                return st;
            K = dense_of(K_);
            return GA_OK;
        }
        K.resize(n_, n_);
        Vec qq = q, rp, rm;
        const ConfigurationSpace &space = model_.space;
        for (int j = 0; j < n_; ++j) {
            const double e = step_for(q[j]);
            space.shift_coordinate(qq, q, j, e);
            if (auto st = residual(qq, lambda, rp))
                return st;
            space.shift_coordinate(qq, q, j, -e);
            if (auto st = residual(qq, lambda, rm))
                return st;
            space.restore_coordinate(qq, q, j);
            K.col(j) = (rp - rm) / (2.0 * e);
        }
        return GA_OK;
    }
    // C_t = -df/dv at rest: the callback or central differences in v
    ga_status damping(const Vec &q, Mat &C)
    {
        C.setZero(n_, n_);
        if (!model_.has_force() && !model_.cb.damping)
            return GA_OK;
        if (model_.cb.damping) {
            if (C_.zero())
                return GA_OK;
            const Restore<ga_tangent_mode> keep(model_.tangent_mode);
            model_.tangent_mode = GA_TANGENT_AUTO;
            Vec unused;
            if (auto st = model_.damping(t_, q, zero_, unused, C_))
                return st;
            C = dense_of(C_);
            return GA_OK;
        }
        Vec v = zero_, fp(n_), fm(n_);
        for (int j = 0; j < n_; ++j) {
            const double e = step_for(0.0);
            v[j] = e;
            if (auto st = model_.force(t_, q, v, fp))
                return st;
            v[j] = -e;
            if (auto st = model_.force(t_, q, v, fm))
                return st;
            v[j] = 0.0;
            C.col(j) = -(fp - fm) / (2.0 * e);
        }
        return GA_OK;
    }
    Diagnostics &diag() { return k_.diag; }

private:
    Stepper &k_;
    Model &model_;
    double t_;
    int n_, m_, r_;
    Vec zero_, f_;
    const Vec *y_before_;
    ModelMatrix M_, J_, K_, C_;
};

// Phi_q's rank and its null space: N (n x (n - rank)), orthonormal columns.
struct NullSpace {
    int rank = 0;
    Mat N;
    explicit NullSpace(const Mat &J)
    {
        const int n = static_cast<int>(J.cols());
        if (J.rows() == 0) {
            N = Mat::Identity(n, n);
            return;
        }
        Eigen::ColPivHouseholderQR<Mat> qr(J.transpose());
        rank = static_cast<int>(qr.rank());
        const Mat Q = qr.householderQ();
        N = Q.rightCols(n - rank);
    }
};

// lambda with Phi_q^T lambda = b in least squares (the minimum-norm one for redundant rows)
inline Vec multipliers(const Mat &J, const Vec &b)
{
    if (J.rows() == 0)
        return Vec(0);
    return J.transpose().completeOrthogonalDecomposition().solve(b);
}

}  // namespace rest
}  // namespace ga
