// Operating points (docs/algorithms.md sec. 17): static equilibrium by Newton in the null
// space of Phi_q, the small motions about it in minimal coordinates, their undamped modes.
// Dense; its own scratch throughout, so that the solver's workspace and state stay as they
// were (the evaluations are counted).
#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "operating_point.hpp"

namespace ga
{

namespace
{

Mat dense_of(const ModelMatrix &A)
{
    if (A.dense())
        return A.as_dense();
    Mat D = Mat::Zero(A.rows(), A.cols());
    for (int e = 0; e < A.nnz(); ++e) // repeated entries add up
        D(A.row_index()[e], A.col_index()[e]) += A.data()[e];
    return D;
}

double max_abs(const Vec &x)
{
    return x.size() ? x.cwiseAbs().maxCoeff() : 0.0;
}

// cbrt(eps) times the size of x: the central difference's truncation and round-off balance
double step_for(double x)
{
    return 6.06e-6 * std::max(std::fabs(x), 1.0);
}

// The model's pieces at rest (v = 0, qdd = 0), dense.
class AtRest
{
  public:
    AtRest(Stepper &kernel, double t)
        : k_(kernel), model_(kernel.model), t_(t), n_(kernel.nv()), m_(kernel.m()),
          zero_(Vec::Zero(kernel.nv())), f_(kernel.nv())
    {
        M_.copy_layout(kernel.matrix(GA_MATRIX_MASS));
        J_.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
        K_.copy_layout(kernel.matrix(GA_MATRIX_STIFFNESS));
        C_.copy_layout(kernel.matrix(GA_MATRIX_DAMPING));
    }
    int n() const { return n_; }
    int m() const { return m_; }

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
    const Vec &last_force() const { return f_; } // f of the last residual
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
    int n_, m_;
    Vec zero_, f_;
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
Vec multipliers(const Mat &J, const Vec &b)
{
    if (J.rows() == 0)
        return Vec(0);
    return J.transpose().completeOrthogonalDecomposition().solve(b);
}

} // namespace

ga_status static_equilibrium(Stepper &kernel, double t, double *q_io, double *lambda_out,
                             double tol, int max_iter)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    Vec q = Eigen::Map<const Vec>(q_io, n);
    if (!all_finite(q))
        return at.diag().fail(GA_ERR_ARG, "ga_static_equilibrium: q is not finite");
    Mat J, K;
    Vec r, phi, f(n);
    // the multipliers that balance the forces best at the start
    if (auto st = at.force(q, f))
        return st;
    if (auto st = at.jacobian(q, J))
        return st;
    Vec lambda = multipliers(J, f);
    const auto merit = [](const Vec &a, const Vec &b) { return a.squaredNorm() + b.squaredNorm(); };
    if (auto st = at.residual(q, lambda, r, &J))
        return st;
    if (auto st = at.constraint(q, phi))
        return st;
    double m0 = merit(r, phi), last_step = 0.0;
    // a root to round-off: the residuals within a few ulps of the forces and of q, where
    // neither Newton's step nor the line search can tell more
    const auto at_roundoff = [&] {
        const double eps = std::numeric_limits<double>::epsilon();
        const double fscale = std::max(max_abs(f), m > 0 ? max_abs(J.transpose() * lambda) : 0.0);
        return max_abs(r) <= 64.0 * eps * fscale &&
               max_abs(phi) <= 64.0 * eps * std::max(1.0, max_abs(q));
    };
    const auto accept = [&] {
        lambda = multipliers(J, f); // the multipliers at the root itself (least squares)
        Eigen::Map<Vec>(q_io, n) = q;
        if (lambda_out && m > 0)
            Eigen::Map<Vec>(lambda_out, m) = lambda;
        return GA_OK;
    };
    for (int it = 1; it <= max_iter; ++it) {
        if (at_roundoff())
            return accept();
        if (auto st = at.stiffness(q, lambda, K))
            return st;
        // Newton on (r, Phi) = 0 split by Phi_q's null space N and range: the increment
        // dq = dq_p + N z with Phi_q dq_p = -Phi (minimum norm), (N^T K N) z = -N^T (r + K dq_p)
        const NullSpace ns(J);
        Vec dq = Vec::Zero(n);
        if (m > 0)
            dq = J.completeOrthogonalDecomposition().solve(-phi);
        const int dof = static_cast<int>(ns.N.cols());
        if (dof > 0) {
            const Mat Kr = ns.N.transpose() * K * ns.N;
            const Eigen::FullPivLU<Mat> lu(Kr);
            const double scale =
                std::max(Kr.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
            if (!(lu.rcond() > 1e-13) || !std::isfinite(lu.rcond()))
                return at.diag().fail(
                    GA_ERR_SINGULAR,
                    "ga_static_equilibrium: the stiffness in the %d free directions of the "
                    "constraints is singular at iteration %d (reciprocal condition %.3g, size "
                    "%.3g): a limit point, or a motion no force restrains",
                    dof, it, lu.rcond(), scale);
            const Vec z = lu.solve(-(ns.N.transpose() * (r + K * dq)));
            dq.noalias() += ns.N * z;
        }
        // the multipliers of the linearized balance, K dq + Phi_q^T lambda_new = f
        const Vec dl = m > 0 ? Vec(multipliers(J, f - K * dq) - lambda) : Vec(0);
        if (!all_finite(dq) || !all_finite(dl))
            return at.diag().fail(GA_ERR_NONFINITE,
                                  "ga_static_equilibrium: the Newton increment is not finite "
                                  "at iteration %d",
                                  it);
        // backtracking on |r|^2 + |Phi|^2, down which the Newton direction goes
        double alpha = 1.0, m1 = 0.0;
        Vec qn(n), ln, rn, phin, fn(n);
        Mat Jn;
        for (;;) {
            kernel.model.space.shifted(q, alpha, dq, qn);
            ln = lambda + alpha * dl;
            if (auto st = at.residual(qn, ln, rn, &Jn))
                return st;
            fn = at.last_force();
            if (auto st = at.constraint(qn, phin))
                return st;
            m1 = merit(rn, phin);
            if (m1 <= (1.0 - 1e-4 * alpha) * m0 || m1 == 0.0)
                break;
            alpha *= 0.5;
            if (alpha < 1.0 / 1024.0 && at_roundoff())
                return accept();
            if (alpha < 1.0 / 1024.0)
                return at.diag().fail(
                    GA_ERR_NEWTON,
                    "ga_static_equilibrium: no equilibrium in reach: at iteration %d no step "
                    "along Newton's direction down to 1/1024 of it reduces the residual (%.3g; "
                    "the stiffness may change sign on the way: a limit point)",
                    it, std::sqrt(m0));
        }
        last_step = alpha * max_abs(dq);
        q = qn;
        lambda = ln;
        r = rn;
        phi = phin;
        J = Jn;
        f = fn;
        m0 = m1;
        if (alpha == 1.0 && last_step <= tol * std::max(1.0, max_abs(q)))
            return accept();
    }
    if (at_roundoff())
        return accept();
    return at.diag().fail(GA_ERR_NEWTON,
                          "ga_static_equilibrium: no equilibrium in %d iterations (last step "
                          "%.3g, residual %.3g)",
                          max_iter, last_step, std::sqrt(m0));
}

ga_status linearize(Stepper &kernel, double t, const double *q0, const double *lambda0,
                    Linearization &out)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    const Vec q = Eigen::Map<const Vec>(q0, n);
    if (!all_finite(q) || (lambda0 && m > 0 && !all_finite(Eigen::Map<const Vec>(lambda0, m))))
        return at.diag().fail(GA_ERR_ARG, "ga_linearize: q or lambda is not finite");
    Mat J, M, K, C;
    Vec f(n);
    if (auto st = at.jacobian(q, J))
        return st;
    Vec lambda;
    if (lambda0 && m > 0) {
        lambda = Eigen::Map<const Vec>(lambda0, m);
    } else {
        if (auto st = at.force(q, f))
            return st;
        lambda = multipliers(J, f);
    }
    if (auto st = at.mass(q, M))
        return st;
    if (auto st = at.stiffness(q, lambda, K))
        return st;
    if (auto st = at.damping(q, C))
        return st;
    NullSpace ns(J);
    out.dof = static_cast<int>(ns.N.cols());
    out.M = ns.N.transpose() * M * ns.N;
    out.C = ns.N.transpose() * C * ns.N;
    out.K = ns.N.transpose() * K * ns.N;
    out.N = std::move(ns.N);
    return GA_OK;
}

ga_status modes(Stepper &kernel, double t, const double *q0, const double *lambda0, int count,
                double *omega2, double *shapes)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    const Vec q = Eigen::Map<const Vec>(q0, n);
    if (!all_finite(q) || (lambda0 && m > 0 && !all_finite(Eigen::Map<const Vec>(lambda0, m))))
        return at.diag().fail(GA_ERR_ARG, "ga_modes: q or lambda is not finite");
    // an equilibrium on the constraints, or the modes mean nothing
    Vec phi, f(n), r;
    Mat J;
    if (auto st = at.constraint(q, phi))
        return st;
    if (auto st = at.force(q, f))
        return st;
    if (auto st = at.jacobian(q, J))
        return st;
    const Vec lambda =
        lambda0 && m > 0 ? Vec(Eigen::Map<const Vec>(lambda0, m)) : multipliers(J, f);
    if (auto st = at.residual(q, lambda, r))
        return st;
    const double phi_scale = std::max(1.0, max_abs(q));
    if (max_abs(phi) > 1e-8 * phi_scale)
        return at.diag().fail(GA_ERR_INCONSISTENT,
                              "ga_modes: q is off the constraints (|Phi| = %.3g)", max_abs(phi));
    {
        const NullSpace ns(J);
        const double fscale = std::max({max_abs(f), m > 0 ? max_abs(J.transpose() * lambda) : 0.0,
                                        std::numeric_limits<double>::min()});
        const double unbalanced = ns.N.cols() ? max_abs(ns.N.transpose() * r) : 0.0;
        if (unbalanced > 1e-8 * fscale)
            return at.diag().fail(GA_ERR_INCONSISTENT,
                                  "ga_modes: q is not an equilibrium: the forces along the "
                                  "free directions are %.3g of their size %.3g "
                                  "(ga_static_equilibrium finds one)",
                                  unbalanced / fscale, fscale);
        if (lambda0 && m > 0 && max_abs(r) > 1e-8 * fscale)
            return at.diag().fail(GA_ERR_INCONSISTENT,
                                  "ga_modes: lambda does not balance the forces at q (%.3g of "
                                  "their size; NULL takes the balancing multipliers)",
                                  max_abs(r) / fscale);
    }
    Linearization lin;
    if (auto st = linearize(kernel, t, q0, lambda.data(), lin))
        return st;
    if (lin.dof == 0 || count > lin.dof)
        return at.diag().fail(GA_ERR_ARG,
                              "ga_modes: %d modes asked for, the constraints leave %d degrees "
                              "of freedom%s",
                              count, lin.dof, lin.dof == 0 ? " (they lock the mechanism)" : "");
    const double kscale = std::max(lin.K.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
    const double asym = (lin.K - lin.K.transpose()).cwiseAbs().maxCoeff() / kscale;
    if (asym > 1e-6)
        return at.diag().fail(GA_ERR_ARG,
                              "ga_modes: the stiffness in the free directions is not symmetric "
                              "(by %.3g of its size): a non-conservative force, whose modes the "
                              "undamped problem does not give",
                              asym);
    const Mat Ks = 0.5 * (lin.K + lin.K.transpose());
    const Mat Ms = 0.5 * (lin.M + lin.M.transpose());
    const Eigen::LLT<Mat> mass_factor(Ms);
    if (mass_factor.info() != Eigen::Success)
        return at.diag().fail(GA_ERR_SINGULAR,
                              "ga_modes: the mass in the free directions is not positive "
                              "definite (a direction that carries no mass)");
    const Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig(Ks, Ms);
    if (eig.info() != Eigen::Success)
        return at.diag().fail(GA_ERR_INTERNAL, "ga_modes: the eigensolver did not converge");
    for (int k = 0; k < count; ++k) // (ascending; eigenvectors with z^T M z = 1)
        omega2[k] = eig.eigenvalues()[k];
    if (shapes)
        Eigen::Map<Mat>(shapes, n, count) = lin.N * eig.eigenvectors().leftCols(count);
    return GA_OK;
}

} // namespace ga
