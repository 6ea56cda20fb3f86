// The undamped modes nearest a shift sigma of a large model (docs/algorithms.md sec. 15,
// "Large models"):
// Lanczos on the shift-inverted operator
//     Op x = y,   [K_t - sigma M, Phi_q^T; Phi_q, 0] [y; mu] = [M x; 0],
// which maps the constraints' tangent space into itself and is self-adjoint there in the
// M inner product, with eigenvalues theta = 1 / (omega^2 - sigma): the omega^2 nearest sigma
// are its largest |theta|. Thick restarts (Krylov-Schur for a symmetric operator: Stewart
// 2001; Wu and Simon 2000) keep the Ritz vectors nearest sigma; every new vector is
// M-orthogonalized twice against all kept ones.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>

#include "at_rest.hpp"
#include "operating_point.hpp"
#include "saddle_at_rest.hpp"

namespace ga {

namespace {

// A fixed start (no global state): xorshift64*, uniform in [-1, 1].
class StartVector {
public:
    double next()
    {
        s_ ^= s_ >> 12;
        s_ ^= s_ << 25;
        s_ ^= s_ >> 27;
        const std::uint64_t x = s_ * 2685821657736338717ULL;
        return static_cast<double>(x >> 11) * (2.0 / 9007199254740992.0) - 1.0;
    }

private:
    std::uint64_t s_ = 0x9E3779B97F4A7C15ULL;
};

class ShiftInvertLanczos {
public:
    ShiftInvertLanczos(SaddleAtRest &at, int basis) : at_(at), n_(at.n()), m_(at.m())
    {
        V_.setZero(n_, basis + 1);
        MV_.setZero(n_, basis + 1);
        H_.setZero(basis + 1, basis + 1);
        rhs_.setZero(n_ + m_);
        w_.setZero(n_);
        Mw_.setZero(n_);
    }
    int applications = 0;

    // y = Op x
    void apply(const Vec &x, Vec &y)
    {
        rhs_.head(n_).setZero();
        Vec Mx = Vec::Zero(n_);
        at_.M.multiply_add(1.0, x, Mx);
        rhs_.head(n_) = Mx;
        if (m_ > 0)
            rhs_.tail(m_).setZero();
        at_.solve(rhs_);
        y = rhs_.head(n_);
        ++applications;
    }
    double m_norm(const Vec &x, Vec &Mx) const
    {
        Mx.setZero(n_);
        at_.M.multiply_add(1.0, x, Mx);
        return x.dot(Mx);
    }
    // w minus its M-projection on the first j basis vectors, twice; the coefficients into h
    void orthogonalize(int j, Vec &w, Vec &h) const
    {
        h = MV_.leftCols(j).transpose() * w;
        w.noalias() -= V_.leftCols(j) * h;
        const Vec h2 = MV_.leftCols(j).transpose() * w;
        w.noalias() -= V_.leftCols(j) * h2;
        h += h2;
    }
    // a fresh direction M-orthogonal to the first j vectors into column j; false if there is
    // none (the mass is not positive there)
    bool fresh(int j, StartVector &start)
    {
        Vec x(n_), h;
        for (int i = 0; i < n_; ++i)
            x[i] = start.next();
        apply(x, w_);  // into the constraints' tangent space
        if (j > 0)
            orthogonalize(j, w_, h);
        const double b2 = m_norm(w_, Mw_);
        if (!(b2 > 0.0) || !std::isfinite(b2))
            return false;
        V_.col(j) = w_ / std::sqrt(b2);
        MV_.col(j) = Mw_ / std::sqrt(b2);
        return true;
    }

    SaddleAtRest &at_;
    int n_, m_;
    Mat V_, MV_, H_;
    Vec rhs_, w_, Mw_;
};

}  // namespace

ga_status modes_near(Stepper &kernel, double t, const double *q0, const double *lambda0,
                     double sigma, int count, double *omega2, double *shapes)
{
    const char *name = "ga_modes_near";
    SaddleAtRest at(kernel, t);
    const int n = at.n(), m = at.m();
    const Vec q = Eigen::Map<const Vec>(q0, n);
    if (!all_finite(q) || (lambda0 && m > 0 && !all_finite(Eigen::Map<const Vec>(lambda0, m))))
        return at.diag().fail(GA_ERR_ARG, "%s: q or lambda is not finite", name);
    if (auto st = at.constraint(q))
        return st;
    const double q_scale = std::max(1.0, rest::max_abs(q));
    if (m > 0 && rest::max_abs(at.phi) > 1e-8 * q_scale)
        return at.diag().fail(GA_ERR_INCONSISTENT, "%s: q is off the constraints (|Phi| = %.3g)",
                              name, rest::max_abs(at.phi));
    if (auto st = at.mass(q))
        return st;
    if (auto st = at.jacobian(q))
        return st;
    if (auto st = at.force(q))
        return st;
    Vec lambda;
    if (lambda0 && m > 0)
        lambda = Eigen::Map<const Vec>(lambda0, m);
    else if (!at.balancing_multipliers(lambda))
        return at.diag().fail(GA_ERR_SINGULAR,
                              "%s: [M, Phi_q^T; Phi_q, 0] is singular (a free direction that "
                              "carries no mass, or redundant constraints)",
                              name);
    if (auto st = at.stiffness(q, lambda))
        return st;
    Vec r;
    at.residual(lambda, r);
    const double fscale =
        std::max({at.max_abs_f(), at.max_abs_constraint_force(lambda),
                  at.max_abs_stiffness() * q_scale, std::numeric_limits<double>::min()});
    if (rest::max_abs(r) > 1e-8 * fscale)
        return at.diag().fail(GA_ERR_INCONSISTENT,
                              lambda0 && m > 0
                                  ? "%s: lambda does not balance the forces at q (%.3g of their "
                                    "size %.3g; NULL takes the balancing multipliers)"
                                  : "%s: q is not an equilibrium: the unbalanced forces are "
                                    "%.3g of their size %.3g (ga_static_equilibrium finds one)",
                              name, rest::max_abs(r) / fscale, fscale);
    const int dof = n - m;  // S below is regular only for independent constraints
    if (count > dof)
        return at.diag().fail(GA_ERR_ARG,
                              "%s: %d modes asked for, the constraints leave %d degrees of "
                              "freedom",
                              name, count, dof);
    if (!at.factorize(-sigma, 1.0))
        return at.diag().fail(GA_ERR_SINGULAR,
                              "%s: [K_t - sigma M, Phi_q^T; Phi_q, 0] is singular at sigma = "
                              "%.17g: sigma is an eigenvalue (move it), or the constraints are "
                              "redundant",
                              name, sigma);

    // basis of p vectors, the `count` wanted kept and half of the others at each restart
    const int p = std::min(dof, std::max(2 * count + 10, 20));
    ShiftInvertLanczos lz(at, p);
    StartVector start;
    const auto no_mass = [&] {
        return at.diag().fail(GA_ERR_SINGULAR,
                              "%s: the mass is not positive definite in the "
                              "free directions (a direction that carries no "
                              "mass)",
                              name);
    };
    if (!lz.fresh(0, start))
        return no_mass();
    Mat &V = lz.V_, &MV = lz.MV_, &H = lz.H_;
    Vec &w = lz.w_, &Mw = lz.Mw_;
    Vec h, theta;
    Mat Y;
    std::vector<int> order;
    int k = 0, built = 0;
    constexpr int kMaxRestarts = 200;
    constexpr double kTol = 1e-11;
    bool done = false;
    for (int restart = 0; restart <= kMaxRestarts && !done; ++restart) {
        built = p;
        for (int j = k; j < p; ++j) {
            lz.apply(V.col(j), w);
            const double size = std::sqrt(std::max(0.0, lz.m_norm(w, Mw)));
            lz.orthogonalize(j + 1, w, h);
            H.col(j).head(j + 1) = h;
            const double b2 = lz.m_norm(w, Mw);
            if (!std::isfinite(b2) || !all_finite(h))
                return at.diag().fail(GA_ERR_NONFINITE,
                                      "%s: the Lanczos vectors are not "
                                      "finite",
                                      name);
            if (j + 1 == dof) {  // the whole space: its Ritz pairs are exact
                H(j + 1, j) = 0.0;
                built = j + 1;
                break;
            }
            if (b2 > 0.0 && std::sqrt(b2) > 1e-12 * size) {
                V.col(j + 1) = w / std::sqrt(b2);
                MV.col(j + 1) = Mw / std::sqrt(b2);
                H(j + 1, j) = std::sqrt(b2);
            } else {  // an invariant subspace: go on in a fresh direction
                if (b2 < -1e-12 * size * size)
                    return no_mass();
                H(j + 1, j) = 0.0;
                if (!lz.fresh(j + 1, start))
                    return no_mass();
            }
        }
        const Mat Hs = H.topLeftCorner(built, built);
        const double hsize = std::max(Hs.cwiseAbs().maxCoeff(), std::numeric_limits<double>::min());
        const double asym = (Hs - Hs.transpose()).cwiseAbs().maxCoeff() / hsize;
        if (asym > 1e-6)
            return at.diag().fail(GA_ERR_ARG,
                                  "%s: the stiffness in the free directions is not symmetric "
                                  "(by %.3g of its size): a non-conservative force, whose modes "
                                  "the undamped problem does not give (ga_modes_damped)",
                                  name, asym);
        const Eigen::SelfAdjointEigenSolver<Mat> eig(0.5 * (Hs + Hs.transpose()));
        if (eig.info() != Eigen::Success)
            return at.diag().fail(GA_ERR_INTERNAL,
                                  "%s: the projected eigenproblem did not "
                                  "converge",
                                  name);
        theta = eig.eigenvalues();
        Y = eig.eigenvectors();
        order.resize(built);
        for (int i = 0; i < built; ++i)
            order[i] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](int a, int b) { return std::fabs(theta[a]) > std::fabs(theta[b]); });
        const double beta = H(built, built - 1);
        done = true;
        for (int i = 0; i < count; ++i) {
            const int c = order[i];
            if (!(std::fabs(beta * Y(built - 1, c)) <= kTol * std::fabs(theta[c])))
                done = false;
        }
        if (done || restart == kMaxRestarts)
            break;
        // thick restart: the Ritz vectors nearest sigma, with the residual direction after them
        const int keep = std::min(built - 1, count + (built - count) / 2);
        Mat Yk(built, keep);
        for (int i = 0; i < keep; ++i)
            Yk.col(i) = Y.col(order[i]);
        const Mat Vk = V.leftCols(built) * Yk, MVk = MV.leftCols(built) * Yk;
        V.col(keep) = V.col(built);
        MV.col(keep) = MV.col(built);
        V.leftCols(keep) = Vk;
        MV.leftCols(keep) = MVk;
        H.setZero();
        for (int i = 0; i < keep; ++i) {
            H(i, i) = theta[order[i]];
            H(keep, i) = beta * Yk(built - 1, i);
        }
        k = keep;
    }
    if (!done) {
        int converged = 0;
        const double beta = H(built, built - 1);
        for (int i = 0; i < count; ++i)
            converged +=
                std::fabs(beta * Y(built - 1, order[i])) <= kTol * std::fabs(theta[order[i]]);
        return at.diag().fail(GA_ERR_INTERNAL,
                              "%s: %d of the %d modes nearest sigma converged in %d restarts (%d "
                              "solves): eigenvalues clustered there; another sigma may do",
                              name, converged, count, kMaxRestarts, lz.applications);
    }
    // the count nearest sigma, by omega^2 ascending
    std::vector<int> chosen(order.begin(), order.begin() + count);
    std::sort(chosen.begin(), chosen.end(),
              [&](int a, int b) { return sigma + 1.0 / theta[a] < sigma + 1.0 / theta[b]; });
    for (int i = 0; i < count; ++i) {
        const int c = chosen[i];
        omega2[i] = sigma + 1.0 / theta[c];
        if (!shapes)
            continue;
        Vec x = V.leftCols(built) * Y.col(c);
        const double norm = std::sqrt(lz.m_norm(x, Mw));
        Eigen::Index big = 0;
        x.cwiseAbs().maxCoeff(&big);
        x /= x[big] < 0.0 ? -norm : norm;  // unit modal mass, largest entry positive
        Eigen::Map<Vec>(shapes + static_cast<std::size_t>(n) * i, n) = x;
    }
    return GA_OK;
}

}  // namespace ga
