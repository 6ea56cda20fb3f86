// The static path through limit points (docs/algorithms.md sec. 15): pseudo-arclength
// continuation in the load factor mu that the callbacks read at *load, Newton in the null
// space of Phi_q bordered by the arc-length equation.
#include <algorithm>
#include <cmath>
#include <limits>

#include "at_rest.hpp"
#include "operating_point.hpp"

namespace ga {

using namespace rest;

namespace {

// A point of the path and its unit tangent (tq, tmu).
struct PathPoint {
    Vec q, lambda, tq;
    double mu = 0.0, tmu = 0.0;
};

class Path {
public:
    Path(Stepper &kernel, double t, double *load, double tol)
        : k_(kernel), at_(kernel, t), load_(load), tol_(tol), n_(kernel.nv()), m_(kernel.m())
    {
    }
    Diagnostics &diag() { return at_.diag(); }

    // df/dmu at (q, mu) by central differences in the load
    ga_status load_derivative(const Vec &q, double mu, Vec &fmu)
    {
        const double e = step_for(mu);
        Vec fp(n_), fm(n_);
        *load_ = mu + e;
        ga_status st = at_.force(q, fp);
        *load_ = mu - e;
        if (!st)
            st = at_.force(q, fm);
        *load_ = mu;
        if (!st)
            fmu = (fp - fm) / (2.0 * e);
        return st;
    }

    // The pieces of the bordered system at (q, lambda, mu): N, N^T K N, N^T f_mu and f_mu.
    struct Linear {
        Mat J, K, N, Kr;
        Vec f, r, phi, fmu, b;
    };
    ga_status linear_at(const Vec &q, const Vec &lambda, double mu, Linear &L)
    {
        *load_ = mu;
        ga_status st = at_.residual(q, lambda, L.r, &L.J);
        if (!st) {
            L.f = at_.last_force();
            st = at_.constraint(q, L.phi);
        }
        if (!st)
            st = at_.stiffness(q, lambda, L.K);
        if (!st)
            st = load_derivative(q, mu, L.fmu);
        if (st)
            return st;
        NullSpace ns(L.J);
        L.N = std::move(ns.N);
        L.Kr = L.N.transpose() * L.K * L.N;
        L.b = L.N.transpose() * L.fmu;
        return GA_OK;
    }

    // The tangent at a converged point: [Kr, -b; c^T, d] [z; tmu] = [0; 1] with (c, d) the
    // previous tangent (z-coordinates), normalized in (q, mu); false if the border is singular
    bool tangent(PathPoint &p, const Linear &L, const Vec &tq_prev, double tmu_prev)
    {
        const int d = static_cast<int>(L.N.cols());
        Mat A = Mat::Zero(d + 1, d + 1);
        A.topLeftCorner(d, d) = L.Kr;
        A.topRightCorner(d, 1) = -L.b;
        A.bottomLeftCorner(1, d) = (L.N.transpose() * tq_prev).transpose();
        A(d, d) = tmu_prev;
        Vec rhs = Vec::Zero(d + 1);
        rhs[d] = 1.0;
        const Eigen::FullPivLU<Mat> lu(A);
        if (!(lu.rcond() > 1e-14))
            return false;
        const Vec x = lu.solve(rhs);
        p.tq = L.N * x.head(d);
        p.tmu = x[d];
        const double norm = std::sqrt(p.tq.squaredNorm() + p.tmu * p.tmu);
        if (!(norm > 0.0) || !std::isfinite(norm))
            return false;
        p.tq /= norm;
        p.tmu /= norm;
        return true;
    }

    // Newton from the predictor for the point at arc length ds from `from` along its tangent.
    // GA_OK: `to` holds it; GA_ERR_NEWTON or GA_ERR_SINGULAR: try a shorter ds; other
    // statuses are the callbacks'.
    ga_status correct(const PathPoint &from, double ds, int max_iter, PathPoint &to, Linear &L,
                      int &iterations)
    {
        const ConfigurationSpace &space = k_.model.space;
        Vec q(n_), dq;
        space.shifted(from.q, ds, from.tq, q);
        double mu = from.mu + ds * from.tmu;
        Vec lambda = from.lambda;
        for (int it = 1; it <= max_iter; ++it) {
            iterations = it;
            if (auto st = linear_at(q, lambda, mu, L))
                return st;
            const int d = static_cast<int>(L.N.cols());
            Vec dqp = Vec::Zero(n_);
            if (m_ > 0)
                dqp = L.J.completeOrthogonalDecomposition().solve(-L.phi);
            Vec moved = q - from.q;  // (R^n: the path's chord)
            const double g = from.tq.dot(moved) + from.tmu * (mu - from.mu) - ds;
            Mat A = Mat::Zero(d + 1, d + 1);
            A.topLeftCorner(d, d) = L.Kr;
            A.topRightCorner(d, 1) = -L.b;
            A.bottomLeftCorner(1, d) = (L.N.transpose() * from.tq).transpose();
            A(d, d) = from.tmu;
            Vec rhs(d + 1);
            rhs.head(d) = -(L.N.transpose() * (L.r + L.K * dqp));
            rhs[d] = -(g + from.tq.dot(dqp));
            const Eigen::FullPivLU<Mat> lu(A);
            if (!(lu.rcond() > 1e-14))
                return GA_ERR_SINGULAR;
            const Vec x = lu.solve(rhs);
            dq = dqp + L.N * x.head(d);
            const double dmu = x[d];
            const Vec lambda_next =
                multipliers(L.J, Vec(L.f + L.fmu * dmu - L.K * dq));  // K dq + J^T l = f + f_mu dmu
            if (!all_finite(dq) || !std::isfinite(dmu) || !all_finite(lambda_next))
                return GA_ERR_NEWTON;
            Vec qn(n_);
            space.shifted(q, 1.0, dq, qn);
            q = qn;
            mu += dmu;
            lambda = lambda_next;
            if (max_abs(dq) <= tol_ * std::max(1.0, max_abs(q)) &&
                std::fabs(dmu) <= tol_ * std::max(1.0, std::fabs(mu))) {
                to.q = q;
                to.mu = mu;
                // the multipliers at the point itself (least squares: round-off)
                *load_ = mu;
                Vec f(n_);
                Mat J;
                if (auto st = at_.force(q, f))
                    return st;
                if (auto st = at_.jacobian(q, J))
                    return st;
                to.lambda = multipliers(J, f);
                return GA_OK;
            }
        }
        return GA_ERR_NEWTON;
    }

private:
    Stepper &k_;
    AtRest at_;
    double *load_;
    double tol_;
    int n_, m_;
};

}  // namespace

ga_status static_path(Stepper &kernel, double t, double *load, double *q_io, double *lambda_io,
                      double ds, int max_points, double tol, ga_path_fn fn, void *fn_user)
{
    const int n = kernel.nv(), m = kernel.m();
    const double mu0 = *load;
    PathPoint p;
    p.q = Eigen::Map<const Vec>(q_io, n);
    p.mu = mu0;
    p.lambda = Vec::Zero(m);
    if (!all_finite(p.q) || !std::isfinite(mu0))
        return kernel.diag.fail(GA_ERR_ARG, "ga_static_path: q or *load is not finite");
    // the start: the equilibrium at the load given, from q
    if (auto st = static_equilibrium(kernel, t, p.q.data(), p.lambda.data(), tol, 50)) {
        kernel.diag.append(" (the start of ga_static_path, at load %g)", mu0);
        *load = mu0;
        return st;
    }
    Path path(kernel, t, load, tol);
    Path::Linear L;
    // on return *load, q and lambda hold the last point reached
    const auto finish = [&](ga_status st) {
        *load = p.mu;
        Eigen::Map<Vec>(q_io, n) = p.q;
        if (lambda_io && m > 0)
            Eigen::Map<Vec>(lambda_io, m) = p.lambda;
        return st;
    };
    if (auto st = path.linear_at(p.q, p.lambda, p.mu, L))
        return finish(st);
    // the first tangent: along the load (the sign of ds), then oriented by the last one
    const double dir = ds > 0.0 ? 1.0 : -1.0;
    if (!path.tangent(p, L, Vec::Zero(n), dir))
        return finish(path.diag().fail(GA_ERR_SINGULAR,
                                       "ga_static_path: no tangent at the start (load %g): the "
                                       "bordered stiffness is singular there",
                                       p.mu));
    const double ds_max = std::fabs(ds), ds_min = ds_max / 1024.0;
    double step = ds_max;
    for (int k = 0; k < max_points; ++k) {
        PathPoint next;
        int iterations = 0;
        ga_status st;
        while ((st = path.correct(p, step, 12, next, L, iterations)) == GA_ERR_NEWTON ||
               st == GA_ERR_SINGULAR) {
            step *= 0.5;
            if (step < ds_min)
                return finish(path.diag().fail(
                    GA_ERR_NEWTON,
                    "ga_static_path: the path does not go on from load %.17g after %d points: "
                    "Newton fails down to an arc length of %g (ds / 1024)",
                    p.mu, k, ds_min));
        }
        if (st)
            return finish(st);
        // the tangent there, oriented along the last (the border's last row)
        if (auto s2 = path.linear_at(next.q, next.lambda, next.mu, L))
            return finish(s2);
        if (!path.tangent(next, L, p.tq, p.tmu))
            return finish(path.diag().fail(GA_ERR_SINGULAR,
                                           "ga_static_path: no tangent at load %.17g (a "
                                           "bifurcation of the path)",
                                           next.mu));
        p = std::move(next);
        if (iterations <= 3)
            step = std::min(ds_max, 1.5 * step);
        if (fn) {
            *load = p.mu;
            const int rc = kernel.model.run_user(
                [&] { return fn(p.mu, p.q.data(), m > 0 ? p.lambda.data() : nullptr, fn_user); });
            if (rc != 0)
                return finish(GA_STOPPED);
        }
    }
    return finish(GA_OK);
}

}  // namespace ga
