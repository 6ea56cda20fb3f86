// Operating points (docs/algorithms.md sec. 15): static equilibrium by Newton in the null
// space of Phi_q, the small motions about it in minimal coordinates, their undamped modes.
// Dense; its own scratch throughout, so that the solver's workspace and state stay as they
// were (the evaluations are counted).
#include <algorithm>
#include <cmath>
#include <limits>

#include <complex>
#include <vector>

#include <Eigen/Eigenvalues>

#include "at_rest.hpp"
#include "operating_point.hpp"

namespace ga {

using namespace rest;

ga_status static_equilibrium(Stepper &kernel, double t, double *q_io, double *lambda_out,
                             double tol, int max_iter)
{
    if (kernel.sparse_wanted() && !kernel.matrix(GA_MATRIX_STIFFNESS).dense())
        return static_equilibrium_saddle(kernel, t, q_io, lambda_out, tol, max_iter);
    return static_equilibrium_y(kernel, t, q_io, nullptr, lambda_out, tol, max_iter);
}

ga_status static_equilibrium_y(Stepper &kernel, double t, double *q_io, double *y_io,
                               double *lambda_out, double tol, int max_iter)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m(), nr = y_io ? at.r() : 0;
    const char *name = y_io ? "ga_static_equilibrium_y" : "ga_static_equilibrium";
    Vec q = Eigen::Map<const Vec>(q_io, n);
    Vec y = nr > 0 ? Vec(Eigen::Map<const Vec>(y_io, nr)) : Vec(0);
    if (!all_finite(q) || !all_finite(y))
        return at.diag().fail(GA_ERR_ARG, "%s: q or y is not finite", name);
    if (nr > 0)
        at.states(y);  // (y, and the trial yn below, are what the force sees)
    Mat J, K;
    Vec r, phi, g, f(n);
    CouplingBlocks B;
    // the multipliers that balance the forces best at the start
    if (auto st = at.force(q, f))
        return st;
    if (auto st = at.jacobian(q, J))
        return st;
    Vec lambda = multipliers(J, f);
    const auto merit = [&](const Vec &a, const Vec &b, const Vec &c) {
        return a.squaredNorm() + b.squaredNorm() + (nr > 0 ? c.squaredNorm() : 0.0);
    };
    if (auto st = at.residual(q, lambda, r, &J))
        return st;
    if (auto st = at.constraint(q, phi))
        return st;
    if (nr > 0)
        if (auto st = at.rate(q, y, g))
            return st;
    double m0 = merit(r, phi, g), last_step = 0.0;
    // a root to round-off: the residuals within a few ulps of the forces (applied, of the
    // constraints, elastic: K_t times q's size, since in a loaded structure the first two
    // cancel inside f) and of q, and the rates within a few ulps of their terms' sizes
    const auto at_roundoff = [&] {
        const double eps = std::numeric_limits<double>::epsilon();
        const double elastic = K.size() ? K.cwiseAbs().maxCoeff() * std::max(1.0, max_abs(q)) : 0.0;
        const double fscale =
            std::max({max_abs(f), m > 0 ? max_abs(J.transpose() * lambda) : 0.0, elastic});
        const bool rates =
            nr == 0 || max_abs(g) <= 8.0 * eps *
                                         std::max({B.g_q.size() ? B.g_q.cwiseAbs().maxCoeff() *
                                                                      std::max(1.0, max_abs(q))
                                                                : 0.0,
                                                   B.g_y.size() ? B.g_y.cwiseAbs().maxCoeff() *
                                                                      std::max(1.0, max_abs(y))
                                                                : 0.0,
                                                   std::numeric_limits<double>::min()});
        return max_abs(r) <= 8.0 * eps * fscale &&
               max_abs(phi) <= 8.0 * eps * std::max(1.0, max_abs(q)) && rates;
    };
    const auto accept = [&] {
        // Constraints that contradict each other (Phi = (x, x - 1)) stall Newton at their
        // least-squares point, where the minimum-norm step is zero: no equilibrium on them.
        const double eps = std::numeric_limits<double>::epsilon();
        const double reach = std::max(100.0 * tol, 8.0 * eps) * std::max(1.0, max_abs(q)) *
                             std::max(1.0, J.size() ? J.cwiseAbs().maxCoeff() : 0.0);
        if (m > 0 && !(max_abs(phi) <= reach))
            return at.diag().fail(GA_ERR_INCONSISTENT,
                                  "%s: the constraints cannot all hold: |Phi| = %.3g at the "
                                  "point nearest to them (constraints that contradict each "
                                  "other)",
                                  name, max_abs(phi));
        lambda = multipliers(J, f);  // the multipliers at the root itself (least squares)
        Eigen::Map<Vec>(q_io, n) = q;
        if (nr > 0)
            Eigen::Map<Vec>(y_io, nr) = y;
        if (lambda_out && m > 0)
            Eigen::Map<Vec>(lambda_out, m) = lambda;
        return GA_OK;
    };
    for (int it = 1; it <= max_iter; ++it) {
        if (auto st = at.stiffness(q, lambda, K))
            return st;
        if (nr > 0)
            if (auto st = at.coupling(q, y, B))
                return st;
        if (at_roundoff())
            return accept();
        // Newton on (r, Phi, g) = 0 split by Phi_q's null space N and range: the increment
        // dq = dq_p + N z with Phi_q dq_p = -Phi (minimum norm), and (z, dy) from
        // [N^T K N, -N^T f_y; g_q N, g_y] [z; dy] = -[N^T (r + K dq_p); g + g_q dq_p]
        const NullSpace ns(J);
        Vec dq = Vec::Zero(n), dy = Vec::Zero(nr);
        if (m > 0)
            dq = J.completeOrthogonalDecomposition().solve(-phi);
        const int dof = static_cast<int>(ns.N.cols());
        if (dof + nr > 0) {
            Mat Kr(dof + nr, dof + nr);
            Vec rhs(dof + nr);
            Kr.topLeftCorner(dof, dof) = ns.N.transpose() * K * ns.N;
            rhs.head(dof) = -(ns.N.transpose() * (r + K * dq));
            if (nr > 0) {
                Kr.topRightCorner(dof, nr) = -(ns.N.transpose() * B.f_y);
                Kr.bottomLeftCorner(nr, dof) = B.g_q * ns.N;
                Kr.bottomRightCorner(nr, nr) = B.g_y;
                rhs.tail(nr) = -(g + B.g_q * dq);
            }
            const Eigen::FullPivLU<Mat> lu(Kr);
            const double scale =
                std::max(Kr.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
            if (!(lu.rcond() > 1e-13) || !std::isfinite(lu.rcond()))
                return at.diag().fail(
                    GA_ERR_SINGULAR,
                    "%s: the stiffness in the %d free directions of the constraints%s is "
                    "singular at iteration %d (reciprocal condition %.3g, size %.3g): a limit "
                    "point, or a motion no force restrains",
                    name, dof, nr > 0 ? " and the first-order states" : "", it, lu.rcond(),
                    scale);
            const Vec x = lu.solve(rhs);
            dq.noalias() += ns.N * x.head(dof);
            dy = x.tail(nr);
        }
        // the multipliers of the linearized balance, K dq - f_y dy + Phi_q^T lambda_new = f
        Vec balance = f - K * dq;
        if (nr > 0)
            balance.noalias() += B.f_y * dy;
        const Vec dl = m > 0 ? Vec(multipliers(J, balance) - lambda) : Vec(0);
        if (!all_finite(dq) || !all_finite(dl) || !all_finite(dy))
            return at.diag().fail(GA_ERR_NONFINITE,
                                  "%s: the Newton increment is not finite at iteration %d", name,
                                  it);
        // Newton's own estimate of the distance to the root: within tol, q is converged even
        // where round-off keeps every step from reducing the residual
        const bool within_tol = max_abs(dq) <= tol * std::max(1.0, max_abs(q)) &&
                                (nr == 0 || max_abs(dy) <= tol * std::max(1.0, max_abs(y)));
        // backtracking on |r|^2 + |Phi|^2 (+ |g|^2), down which the Newton direction goes
        double alpha = 1.0, m1 = 0.0;
        Vec qn(n), ln, rn, phin, gn, fn(n), yn = y;
        Mat Jn;
        if (nr > 0)
            at.states(yn);
        for (;;) {
            kernel.model.space.shifted(q, alpha, dq, qn);
            ln = lambda + alpha * dl;
            if (nr > 0)
                yn = y + alpha * dy;
            if (auto st = at.residual(qn, ln, rn, &Jn))
                return st;
            fn = at.last_force();
            if (auto st = at.constraint(qn, phin))
                return st;
            if (nr > 0)
                if (auto st = at.rate(qn, yn, gn))
                    return st;
            m1 = merit(rn, phin, gn);
            if (m1 <= (1.0 - 1e-4 * alpha) * m0 || m1 == 0.0)
                break;
            alpha *= 0.5;
            if (alpha < 1.0 / 1024.0 && (within_tol || at_roundoff())) {
                if (nr > 0)
                    at.states(y);
                return accept();
            }
            if (alpha < 1.0 / 1024.0)
                return at.diag().fail(
                    GA_ERR_NEWTON,
                    "%s: no equilibrium in reach: at iteration %d no step along Newton's "
                    "direction down to 1/1024 of it reduces the residual (%.3g; the stiffness "
                    "may change sign on the way: a limit point)",
                    name, it, std::sqrt(m0));
        }
        last_step = alpha * max_abs(dq);
        const double last_dy = alpha * max_abs(dy);
        q = qn;
        lambda = ln;
        r = rn;
        phi = phin;
        J = Jn;
        f = fn;
        m0 = m1;
        if (nr > 0) {
            y = yn;
            g = gn;
            at.states(y);
        }
        if (alpha == 1.0 && last_step <= tol * std::max(1.0, max_abs(q)) &&
            (nr == 0 || last_dy <= tol * std::max(1.0, max_abs(y))))
            return accept();
    }
    if (at_roundoff())
        return accept();
    return at.diag().fail(GA_ERR_NEWTON,
                          "%s: no equilibrium in %d iterations (last step %.3g, residual %.3g)",
                          name, max_iter, last_step, std::sqrt(m0));
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
    out.stiffness_size = K.size() ? K.cwiseAbs().maxCoeff() : 0.0;
    out.N = std::move(ns.N);
    return GA_OK;
}

ga_status state_space(Stepper &kernel, double t, const double *q0, const double *y0,
                      const double *lambda0, StateSpace &out)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m(), nr = at.r();
    const Vec q = Eigen::Map<const Vec>(q0, n);
    const Vec y = nr > 0 ? Vec(Eigen::Map<const Vec>(y0, nr)) : Vec(0);
    if (!all_finite(q) || !all_finite(y) ||
        (lambda0 && m > 0 && !all_finite(Eigen::Map<const Vec>(lambda0, m))))
        return at.diag().fail(GA_ERR_ARG, "ga_state_space: q, y or lambda is not finite");
    if (nr > 0)
        at.states(y);
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
    CouplingBlocks B;
    if (nr > 0)
        if (auto st = at.coupling(q, y, B))
            return st;
    NullSpace ns(J);
    const int d = static_cast<int>(ns.N.cols());
    const Mat Mr = ns.N.transpose() * M * ns.N;
    const Eigen::PartialPivLU<Mat> mass(Mr);
    if (d > 0 && !invertible(mass))
        return at.diag().fail(GA_ERR_SINGULAR,
                              "ga_state_space: the mass in the free directions is singular "
                              "(reciprocal condition %.3g)",
                              mass.rcond());
    // x = (z, z', y): z'' = M^-1 (-K z - C z' + N^T f_y y), y' = g_q N z + g_v N z' + g_y y
    out.dof = d;
    out.dim = 2 * d + nr;
    out.A.setZero(out.dim, out.dim);
    if (d > 0) {
        out.A.block(0, d, d, d).setIdentity();
        out.A.block(d, 0, d, d) = -mass.solve(ns.N.transpose() * K * ns.N);
        out.A.block(d, d, d, d) = -mass.solve(ns.N.transpose() * C * ns.N);
    }
    if (nr > 0) {
        if (d > 0) {
            out.A.block(d, 2 * d, d, nr) = mass.solve(ns.N.transpose() * B.f_y);
            out.A.block(2 * d, 0, nr, d) = B.g_q * ns.N;
            out.A.block(2 * d, d, nr, d) = B.g_v * ns.N;
        }
        out.A.block(2 * d, 2 * d, nr, nr) = B.g_y;
    }
    out.N = std::move(ns.N);
    return GA_OK;
}

namespace {

// The linearization at (q, lambda) for the modes of `name`, once q is known to be an
// equilibrium on the constraints whose dof degrees of freedom have `count` modes (per_dof
// each: 1 undamped, 2 damped), else refused.
ga_status equilibrium_linearization(Stepper &kernel, double t, const double *q0,
                                    const double *lambda0, int count, int per_dof, const char *name,
                                    Linearization &lin)
{
    AtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    const Vec q = Eigen::Map<const Vec>(q0, n);
    if (!all_finite(q) || (lambda0 && m > 0 && !all_finite(Eigen::Map<const Vec>(lambda0, m))))
        return at.diag().fail(GA_ERR_ARG, "%s: q or lambda is not finite", name);
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
        return at.diag().fail(GA_ERR_INCONSISTENT, "%s: q is off the constraints (|Phi| = %.3g)",
                              name, max_abs(phi));
    if (auto st = linearize(kernel, t, q0, lambda.data(), lin))
        return st;
    // the forces' size: applied, constraint, and elastic (the stiffness over q's size), since
    // at rest the first two may cancel inside f itself (a preloaded structure)
    const double fscale =
        std::max({max_abs(f), m > 0 ? max_abs(J.transpose() * lambda) : 0.0,
                  lin.stiffness_size * phi_scale, std::numeric_limits<double>::min()});
    const double unbalanced = lin.dof ? max_abs(lin.N.transpose() * r) : 0.0;
    if (unbalanced > 1e-8 * fscale)
        return at.diag().fail(GA_ERR_INCONSISTENT,
                              "%s: q is not an equilibrium: the forces along the free "
                              "directions are %.3g of their size %.3g (ga_static_equilibrium "
                              "finds one)",
                              name, unbalanced / fscale, fscale);
    if (lambda0 && m > 0 && max_abs(r) > 1e-8 * fscale)
        return at.diag().fail(GA_ERR_INCONSISTENT,
                              "%s: lambda does not balance the forces at q (%.3g of their "
                              "size; NULL takes the balancing multipliers)",
                              name, max_abs(r) / fscale);
    if (lin.dof == 0 || count > per_dof * lin.dof)
        return at.diag().fail(GA_ERR_ARG,
                              "%s: %d modes asked for, the constraints leave %d degrees of "
                              "freedom (%d modes)%s",
                              name, count, lin.dof, per_dof * lin.dof,
                              lin.dof == 0 ? " (they lock the mechanism)" : "");
    return GA_OK;
}

}  // namespace

ga_status modes(Stepper &kernel, double t, const double *q0, const double *lambda0, int count,
                double *omega2, double *shapes)
{
    const int n = kernel.nv();
    Linearization lin;
    if (auto st = equilibrium_linearization(kernel, t, q0, lambda0, count, 1, "ga_modes", lin))
        return st;
    Diagnostics &diag = kernel.diag;
    const double kscale = std::max(lin.K.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
    const double asym = (lin.K - lin.K.transpose()).cwiseAbs().maxCoeff() / kscale;
    if (asym > 1e-6)
        return diag.fail(GA_ERR_ARG,
                         "ga_modes: the stiffness in the free directions is not symmetric "
                         "(by %.3g of its size): a non-conservative force, whose modes the "
                         "undamped problem does not give",
                         asym);
    const Mat Ks = 0.5 * (lin.K + lin.K.transpose());
    const Mat Ms = 0.5 * (lin.M + lin.M.transpose());
    const Eigen::LLT<Mat> mass_factor(Ms);
    if (mass_factor.info() != Eigen::Success)
        return diag.fail(GA_ERR_SINGULAR,
                         "ga_modes: the mass in the free directions is not positive "
                         "definite (a direction that carries no mass)");
    const Eigen::GeneralizedSelfAdjointEigenSolver<Mat> eig(Ks, Ms);
    if (eig.info() != Eigen::Success)
        return diag.fail(GA_ERR_INTERNAL, "ga_modes: the eigensolver did not converge");
    for (int k = 0; k < count; ++k)  // (ascending; eigenvectors with z^T M z = 1)
        omega2[k] = eig.eigenvalues()[k];
    if (shapes)
        Eigen::Map<Mat>(shapes, n, count) = lin.N * eig.eigenvectors().leftCols(count);
    return GA_OK;
}

}  // namespace ga

namespace ga {

ga_status damped_modes(Stepper &kernel, double t, const double *q0, const double *lambda0,
                       int count, double *re, double *im, double *shapes_re, double *shapes_im)
{
    const int n = kernel.nv();
    Linearization lin;
    if (auto st =
            equilibrium_linearization(kernel, t, q0, lambda0, count, 2, "ga_modes_damped", lin))
        return st;
    const int d = lin.dof;
    const Eigen::PartialPivLU<Mat> mass(lin.M);
    const double mscale = std::max(lin.M.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
    if (!rest::invertible(mass))
        return kernel.diag.fail(GA_ERR_SINGULAR,
                                "ga_modes_damped: the mass in the free directions is singular "
                                "(reciprocal condition %.3g, size %.3g)",
                                mass.rcond(), mscale);
    // x' = A x, x = (z, z'): A = [0, I; -M^-1 K, -M^-1 C]
    Mat A = Mat::Zero(2 * d, 2 * d);
    A.topRightCorner(d, d).setIdentity();
    A.bottomLeftCorner(d, d) = -mass.solve(lin.K);
    A.bottomRightCorner(d, d) = -mass.solve(lin.C);
    const Eigen::EigenSolver<Mat> eig(A);
    if (eig.info() != Eigen::Success)
        return kernel.diag.fail(GA_ERR_INTERNAL, "ga_modes_damped: the eigensolver did not "
                                                 "converge");
    // by |s| ascending, a conjugate pair with its positive imaginary part first
    std::vector<int> order(2 * d);
    for (int k = 0; k < 2 * d; ++k)
        order[k] = k;
    const auto &s = eig.eigenvalues();
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
        const double ma = std::abs(s[a]), mb = std::abs(s[b]);
        if (std::fabs(ma - mb) > 1e-12 * std::max(ma, mb))
            return ma < mb;
        return s[a].imag() > s[b].imag();
    });
    for (int k = 0; k < count; ++k) {
        const int j = order[k];
        re[k] = s[j].real();
        im[k] = s[j].imag();
        if (!shapes_re && !shapes_im)
            continue;
        // the displacement part in q, scaled so that its largest entry is 1
        Eigen::VectorXcd shape =
            lin.N.cast<std::complex<double>>() * eig.eigenvectors().col(j).head(d);
        Eigen::Index big = 0;
        shape.cwiseAbs().maxCoeff(&big);
        if (std::abs(shape[big]) > 0.0)
            shape /= shape[big];
        for (int i = 0; i < n; ++i) {
            if (shapes_re)
                shapes_re[i + static_cast<std::size_t>(n) * k] = shape[i].real();
            if (shapes_im)
                shapes_im[i + static_cast<std::size_t>(n) * k] = shape[i].imag();
        }
    }
    return GA_OK;
}

}  // namespace ga
