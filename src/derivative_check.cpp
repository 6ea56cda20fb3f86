// ga_check_derivatives: every derivative callback the solver was given, at one state, against
// central differences of the callbacks it derives (docs/algorithms.md sec. 13). A wrong sign
// in a K_t otherwise shows only as "Newton did not converge". Its own scratch throughout: the
// solver's workspace, state and set-up are not touched (the evaluations are counted).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "derivative_check.hpp"

namespace ga {

namespace {

// The worst entry of one derivative, relative to the largest entry of its matrix.
struct Worst {
    const char *name;
    const char *of;  // what the differences are taken of
    double error = 0.0, by_callback = 0.0, by_differences = 0.0;
    int row = -1, col = -1;
};

// Column j of a callback's matrix (dense, or the values of its pattern), by columns.
class Columns {
public:
    explicit Columns(const ModelMatrix &A) : A_(A)
    {
        if (A.dense())
            return;
        start_.assign(static_cast<std::size_t>(A.cols()) + 1, 0);
        for (int c : A.col_index())
            ++start_[static_cast<std::size_t>(c) + 1];
        for (int j = 0; j < A.cols(); ++j)
            start_[j + 1] += start_[j];
        order_.resize(A.col_index().size());
        std::vector<int> next(start_.begin(), start_.end() - 1);
        for (int k = 0; k < static_cast<int>(A.col_index().size()); ++k)
            order_[next[A.col_index()[k]]++] = k;
    }
    void column(int j, Vec &out) const
    {
        if (A_.dense()) {
            out = A_.as_dense().col(j);
            return;
        }
        out.setZero(A_.rows());
        for (int e = start_[j]; e < start_[j + 1]; ++e)
            out[A_.row_index()[order_[e]]] += A_.data()[order_[e]];  // duplicates add up
    }
    double max_abs() const
    {
        return A_.size() ? Eigen::Map<const Vec>(A_.data(), A_.size()).cwiseAbs().maxCoeff()
                         : 0.0;
    }

private:
    const ModelMatrix &A_;
    std::vector<int> start_, order_;
};

void compare(Worst &w, int col, const Vec &by_callback, const Vec &by_differences, double scale)
{
    const double s = std::max({scale, by_differences.cwiseAbs().maxCoeff(),
                               std::numeric_limits<double>::min()});
    for (Eigen::Index i = 0; i < by_callback.size(); ++i) {
        const double e = std::fabs(by_callback[i] - by_differences[i]) / s;
        if (e > w.error || !(e == e)) {
            w.error = e;
            w.row = static_cast<int>(i);
            w.col = col;
            w.by_callback = by_callback[i];
            w.by_differences = by_differences[i];
        }
    }
}

// cbrt(eps) times the size of x: the central difference's truncation and round-off balance
double step_for(double x) { return 6.06e-6 * std::max(std::fabs(x), 1.0); }

}  // namespace

ga_status check_derivatives(Stepper &kernel, const Sensitivities &sens, double t,
                            const double *q0, const double *v0, const double *qdd0,
                            const double *lambda0, const double *y0, double tol,
                            double *worst_out)
{
    const int n = kernel.nv(), m = kernel.m(), R = kernel.r();
    Vec q = Eigen::Map<const Vec>(q0, kernel.nq()), v = Eigen::Map<const Vec>(v0, n);
    Vec qdd = qdd0 ? Vec(Eigen::Map<const Vec>(qdd0, n)) : Vec::Zero(n);
    // (ones: the multipliers' part of K_t is checked too)
    Vec lambda = lambda0 ? Vec(Eigen::Map<const Vec>(lambda0, m)) : Vec::Ones(m);
    Vec y = R > 0 && y0 ? Vec(Eigen::Map<const Vec>(y0, R)) : Vec::Zero(R);
    if (!all_finite(q) || !all_finite(v) || !all_finite(qdd) || !all_finite(lambda) ||
        !all_finite(y))
        return kernel.diag.fail(GA_ERR_ARG,
                                "ga_check_derivatives: a value of the state is not finite");
    const Restore<const Vec *> keep_y(kernel.model.y_now);
    const Restore<ga_tangent_mode> keep_mode(kernel.model.tangent_mode);
    kernel.model.y_now = &y;
    kernel.model.tangent_mode = GA_TANGENT_AUTO;  // (the callbacks, whatever the runs use)

    ModelMatrix M, M2, J, J2, K, C;
    M.copy_layout(kernel.matrix(GA_MATRIX_MASS));
    M2.copy_layout(kernel.matrix(GA_MATRIX_MASS));
    J.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
    J2.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
    Vec f(n), f2(n), r1(n), r2(n), phi1(m), phi2(m), col_cb, col_fd;
    std::vector<Worst> checked;
    ga_status st = GA_OK;
    // r^q = M qdd - f + Phi_q^T lambda at (q, v), into r
    const auto residual_at = [&](const Vec &qq, const Vec &vv, Vec &r) {
        ga_status s2 = kernel.model.mass(t, qq, M2);
        if (!s2)
            s2 = kernel.model.force(t, qq, vv, f2);
        if (!s2 && m > 0)
            s2 = kernel.model.jacobian(t, qq, J2);
        if (!s2)
            Model::dynamics_residual(M2, qdd, f2, J2, lambda, r);
        return s2;
    };

    if (m > 0) {  // Phi_q against differences of Phi in q
        Worst w{"Phi_q", "Phi in q"};
        if ((st = kernel.model.jacobian(t, q, J)))
            return st;
        const Columns cols(J);
        const double scale = cols.max_abs();
        Vec row_max = Vec::Zero(m);
        for (int j = 0; j < n && !st; ++j) {
            Vec qq = q;
            const double e = step_for(kernel.model.space.magnitude(q, j));
            kernel.model.space.shift_coordinate(qq, q, j, e);
            st = kernel.model.constraint(t, qq, phi1);
            kernel.model.space.shift_coordinate(qq, q, j, -e);
            if (!st)
                st = kernel.model.constraint(t, qq, phi2);
            if (!st) {
                cols.column(j, col_cb);
                row_max = row_max.cwiseMax(col_cb.cwiseAbs());
                col_fd = (phi1 - phi2) / (2.0 * e);
                compare(w, j, col_cb, col_fd, scale);
            }
        }
        checked.push_back(w);
        // A constraint whose gradient vanishes here: not a wrong derivative, but the cause of
        // a singular start, which its message called "redundant".
        for (int i = 0; i < m && !st; ++i)
            if (row_max[i] == 0.0)
                return kernel.diag.fail(GA_ERR_DERIVATIVE,
                                        "constraint %d has a zero gradient at this q (its row of "
                                        "Phi_q is zero: the constraint is degenerate there, e.g. "
                                        "the square of a distance that is zero)",
                                        i);
    }
    if (!st && m > 0 && kernel.model.cb.constraint_dt) {  // Phi_t against differences in t
        Worst w{"Phi_t", "Phi in t"};
        Vec dt(m);
        const double e = step_for(t);
        st = kernel.model.constraint_dt(t, q, dt);
        if (!st)
            st = kernel.model.constraint(t + e, q, phi1);
        if (!st)
            st = kernel.model.constraint(t - e, q, phi2);
        if (!st) {
            col_fd = (phi1 - phi2) / (2.0 * e);
            compare(w, 0, dt, col_fd, 0.0);
            checked.push_back(w);
        }
    }
    if (!st && m > 0 && kernel.model.cb.constraint_accel) {
        // Phi_qq(v, v) + 2 Phi_qt v + Phi_tt = d^2/ds^2 Phi(q + s v, t + s) at s = 0
        Worst w{"constraint acceleration term", "Phi along (q + s v, t + s), second"};
        Vec accel(m), phi0(m), qq(q.size());
        const double e =
            1.2e-4 * std::max({1.0, std::fabs(t), kernel.model.space.max_magnitude(q)}) /
            std::max(1.0, v.cwiseAbs().maxCoeff());
        st = kernel.model.constraint_accel(t, q, v, accel);
        if (!st)
            st = kernel.model.constraint(t, q, phi0);
        if (!st)
            kernel.model.space.shifted(q, e, v, qq), st = kernel.model.constraint(t + e, qq, phi1);
        if (!st)
            kernel.model.space.shifted(q, -e, v, qq), st = kernel.model.constraint(t - e, qq, phi2);
        if (!st) {
            col_fd = (phi1 - 2.0 * phi0 + phi2) / (e * e);
            compare(w, 0, accel, col_fd, 0.0);
            checked.push_back(w);
        }
    }
    if (!st && kernel.model.cb.stiffness) {  // K_t against differences of r^q in q
        Worst w{"K_t", "r^q = M qdd - f + Phi_q^T lambda in q"};
        K.copy_layout(kernel.matrix(GA_MATRIX_STIFFNESS));
        if (!K.zero()) {
            if (!(st = residual_at(q, v, r1)))  // (M, f, Phi_q at q for the callback's r^q)
                st = kernel.model.stiffness(t, q, v, qdd, lambda, r1, M2, K);
            const Columns cols(K);
            const double scale = cols.max_abs();
            for (int j = 0; j < n && !st; ++j) {
                Vec qq = q;
                const double e = step_for(kernel.model.space.magnitude(q, j));
                kernel.model.space.shift_coordinate(qq, q, j, e);
                st = residual_at(qq, v, r1);
                kernel.model.space.shift_coordinate(qq, q, j, -e);
                if (!st)
                    st = residual_at(qq, v, r2);
                if (!st) {
                    cols.column(j, col_cb);
                    col_fd = (r1 - r2) / (2.0 * e);
                    compare(w, j, col_cb, col_fd, scale);
                }
            }
            checked.push_back(w);
        }
    }
    if (!st && kernel.model.cb.damping) {  // C_t = -df/dv against differences of f in v
        Worst w{"C_t", "-f in v"};
        C.copy_layout(kernel.matrix(GA_MATRIX_DAMPING));
        if (!C.zero()) {
            if (!(st = kernel.model.force(t, q, v, f)))
                st = kernel.model.damping(t, q, v, f, C);
            const Columns cols(C);
            const double scale = cols.max_abs();
            for (int j = 0; j < n && !st; ++j) {
                Vec vv = v;
                const double e = step_for(v[j]);
                vv[j] = v[j] + e;
                st = kernel.model.force(t, q, vv, f);
                vv[j] = v[j] - e;
                if (!st)
                    st = kernel.model.force(t, q, vv, f2);
                if (!st) {
                    cols.column(j, col_cb);
                    col_fd = -(f - f2) / (2.0 * e);
                    compare(w, j, col_cb, col_fd, scale);
                }
            }
            checked.push_back(w);
        }
    }
    if (!st && R > 0 && kernel.model.cb.coupling) {  // g_q, g_v, g_y and f_y against differences
        CouplingBlocks B;
        B.allocate(n, R);
        Vec g(R), g1(R), g2(R);
        if (!(st = kernel.model.force(t, q, v, f)))
            st = kernel.model.rate(t, q, v, y, g);
        if (!st)
            st = kernel.model.coupling(t, q, v, y, f, g, B);
        Worst wq{"g_q", "g in q"}, wv{"g_v", "g in v"}, wy{"g_y", "g in y"}, wf{"f_y", "f in y"};
        for (int block = 0; block < 3 && !st; ++block) {
            Worst &w = block == 0 ? wq : block == 1 ? wv : wy;
            const Mat &G = block == 0 ? B.g_q : block == 1 ? B.g_v : B.g_y;
            const double scale = G.size() ? G.cwiseAbs().maxCoeff() : 0.0;
            for (int j = 0; j < G.cols() && !st; ++j) {
                Vec qq = q, vv = v, yy = y;
                Vec &x = block == 0 ? qq : block == 1 ? vv : yy;
                // (q through the space: along a right increment on a rotation)
                const double e =
                    step_for(block == 0 ? kernel.model.space.magnitude(q, j) : x[j]);
                if (block == 0)
                    kernel.model.space.shift_coordinate(qq, q, j, e);
                else
                    x[j] += e;
                kernel.model.y_now = &yy;
                st = kernel.model.rate(t, qq, vv, yy, g1);
                if (!st && block == 2)
                    st = kernel.model.force(t, qq, vv, f);
                if (block == 0)
                    kernel.model.space.shift_coordinate(qq, q, j, -e);
                else
                    x[j] -= 2.0 * e;
                if (!st)
                    st = kernel.model.rate(t, qq, vv, yy, g2);
                if (!st && block == 2)
                    st = kernel.model.force(t, qq, vv, f2);
                kernel.model.y_now = &y;
                if (!st) {
                    col_cb = G.col(j);
                    col_fd = (g1 - g2) / (2.0 * e);
                    compare(w, j, col_cb, col_fd, scale);
                    if (block == 2) {
                        col_cb = B.f_y.col(j);
                        col_fd = (f - f2) / (2.0 * e);
                        compare(wf, j, col_cb, col_fd, B.f_y.cwiseAbs().maxCoeff());
                    }
                }
            }
        }
        for (const Worst *w : {&wq, &wv, &wy, &wf})
            checked.push_back(*w);
    }
    // parameter derivatives against differences in p_j (perturbed in place, as the
    // sensitivities do, and put back)
    for (int j = 0; j < sens.np && !st; ++j) {
        double &p = sens.p[j];
        const double p_kept = p, e = step_for(p) * std::max(1.0, sens.scale[j]);
        const auto at = [&](double value, auto &&eval) {
            p = value;
            const ga_status s2 = eval();
            p = p_kept;
            return s2;
        };
        if (kernel.model.cb.force_p) {
            Worst w{"df/dp", "f in p"};
            Vec fp(n);
            st = kernel.model.force_p(t, q, v, j, fp);
            if (!st)
                st = at(p_kept + e, [&] { return kernel.model.force(t, q, v, f); });
            if (!st)
                st = at(p_kept - e, [&] { return kernel.model.force(t, q, v, f2); });
            if (!st) {
                col_fd = (f - f2) / (2.0 * e);
                compare(w, j, fp, col_fd, 0.0);
                checked.push_back(w);
            }
        }
        if (!st && kernel.model.cb.mass_p) {
            Worst w{"(dM/dp) a", "M a in p, a = qdd"};
            Vec mp(n);
            st = kernel.model.mass_p(t, q, j, qdd, mp);
            if (!st)
                st = at(p_kept + e, [&] { return kernel.model.mass(t, q, M2); });
            if (!st) {
                r1.setZero();
                M2.multiply_add(1.0, qdd, r1);
                st = at(p_kept - e, [&] { return kernel.model.mass(t, q, M2); });
            }
            if (!st) {
                r2.setZero();
                M2.multiply_add(1.0, qdd, r2);
                col_fd = (r1 - r2) / (2.0 * e);
                compare(w, j, mp, col_fd, 0.0);
                checked.push_back(w);
            }
        }
        if (!st && m > 0 && kernel.model.cb.constraint_p) {
            Worst wp{"dPhi/dp", "Phi in p"}, wj{"dPhi_q/dp", "Phi_q in p"};
            Vec phi_p(m);
            ModelMatrix J_p;
            J_p.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
            st = kernel.model.constraint_p(t, q, j, phi_p, J_p, nullptr);
            if (!st)
                st = at(p_kept + e, [&] {
                    const ga_status s2 = kernel.model.constraint(t, q, phi1);
                    return s2 ? s2 : kernel.model.jacobian(t, q, J);
                });
            if (!st)
                st = at(p_kept - e, [&] {
                    const ga_status s2 = kernel.model.constraint(t, q, phi2);
                    return s2 ? s2 : kernel.model.jacobian(t, q, J2);
                });
            if (!st) {
                col_fd = (phi1 - phi2) / (2.0 * e);
                compare(wp, j, phi_p, col_fd, 0.0);
                const Columns dj(J_p), plus(J), minus(J2);
                Vec col_minus;
                for (int k = 0; k < n; ++k) {
                    dj.column(k, col_cb);
                    plus.column(k, col_fd);
                    minus.column(k, col_minus);
                    col_fd = (col_fd - col_minus) / (2.0 * e);
                    compare(wj, k, col_cb, col_fd, dj.max_abs());
                }
                checked.push_back(wp);
                checked.push_back(wj);
            }
        }
    }
    if (st) {
        kernel.diag.append(" (ga_check_derivatives)");
        return st;
    }
    double worst = 0.0;
    for (const Worst &w : checked)
        worst = std::max(worst, w.error);
    if (worst_out)
        *worst_out = worst;
    if (!(worst > tol))
        return GA_OK;
    kernel.diag.fail(GA_ERR_DERIVATIVE, "derivatives that disagree with central differences "
              "(relative to their largest entry, tolerance %g):", tol);
    for (const Worst &w : checked)
        if (w.error > tol)
            kernel.diag.append(" %s(%d, %d) = %.6g by the callback, %.6g by differences of %s "
                        "(relative error %.2g);", w.name, w.row, w.col, w.by_callback,
                        w.by_differences, w.of, w.error);
    return GA_ERR_DERIVATIVE;
}

}  // namespace ga
