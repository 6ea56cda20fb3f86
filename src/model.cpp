#include "model.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <limits>
#include <tuple>

namespace ga {

namespace {
const double kEps = std::numeric_limits<double>::epsilon();
// The step in t of the differences of Phi_t (relative to max(|t|, 1)): 2^-13, where the
// extrapolated difference's round-off and truncation meet for time scales ~1 (design-notes).
const double kPhiTStep = 1.0 / 8192.0;

// Forward-difference increment: sqrt(eps) relative to the component, with 1 as the typical
// magnitude below which it is absolute (as SUNDIALS does with atol = 1). Returned as the exact
// difference (x + e) - x, so that the division uses the increment actually applied.
double fd_increment(double x)
{
    const double e = std::sqrt(kEps) * std::max(std::fabs(x), 1.0);
    const double xp = x + e;
    return xp - x;
}

// Central differences: error O(e^2) + O(eps / e), smallest near e = eps^(1/3).
double central_increment(double x)
{
    const double e = std::cbrt(kEps) * std::max(std::fabs(x), 1.0);
    const double xp = x + e;
    return xp - x;
}
}  // namespace

// Built aside and moved in at the end: out of memory half way must not leave a grouping that
// counts groups but lacks their columns (the retried setup would skip it, the step crash).
void ColumnGroups::build(const ModelMatrix &A, const ConfigurationSpace *space)
{
    ColumnGroups built;
    const int nrows = A.rows(), ncols = A.cols(), nnz = A.nnz();
    const auto &ri = A.row_index();
    const auto &ci = A.col_index();
    // first occurrence of every (row, col) pair; duplicates must not receive the value twice
    std::vector<int> order(nnz);
    for (int k = 0; k < nnz; ++k)
        order[k] = k;
    std::sort(order.begin(), order.end(), [&](int a, int b) {
        return std::make_tuple(ci[a], ri[a], a) < std::make_tuple(ci[b], ri[b], b);
    });
    std::vector<int> unique;
    for (int k = 0; k < nnz; ++k)
        if (k == 0 || ci[order[k]] != ci[order[k - 1]] || ri[order[k]] != ri[order[k - 1]])
            unique.push_back(order[k]);
    // column -> rows and row -> columns adjacency
    std::vector<std::vector<int>> col_rows(ncols), row_cols(nrows);
    for (int k : unique) {
        col_rows[ci[k]].push_back(ri[k]);
        row_cols[ri[k]].push_back(ci[k]);
    }
    // greedy colouring: a column takes the first group that none of its row-neighbours has
    std::vector<int> color(ncols, -1), forbidden;
    int groups = 0;
    for (int j = 0; j < ncols; ++j) {
        if (col_rows[j].empty())
            continue;
        for (int i : col_rows[j])
            for (int jj : row_cols[i])
                if (color[jj] >= 0)
                    forbidden[color[jj]] = j;
        int local = 0;
        const int rotation = space ? space->rotation_of(j, &local) : -1;
        if (rotation >= 0)
            for (int l = 0; l < space->rotation_width(rotation); ++l) {
                const int jj = static_cast<int>(space->rotation_start(rotation)) + l;
                if (color[jj] >= 0)
                    forbidden[color[jj]] = j;
            }
        int c = 0;
        while (c < groups && forbidden[c] == j)
            ++c;
        if (c == groups) {
            ++groups;
            forbidden.push_back(-1);
        }
        color[j] = c;
    }
    built.start.assign(groups + 1, 0);
    built.entry_start.assign(groups + 1, 0);
    for (int j = 0; j < ncols; ++j)
        if (color[j] >= 0)
            ++built.start[color[j] + 1];
    for (int k : unique)
        ++built.entry_start[color[ci[k]] + 1];
    for (int g = 0; g < groups; ++g) {
        built.start[g + 1] += built.start[g];
        built.entry_start[g + 1] += built.entry_start[g];
    }
    built.cols.assign(built.start[groups], 0);
    built.entries.assign(built.entry_start[groups], 0);
    std::vector<int> fill_c(built.start.begin(), built.start.end() - 1);
    std::vector<int> fill_e(built.entry_start.begin(), built.entry_start.end() - 1);
    for (int j = 0; j < ncols; ++j)
        if (color[j] >= 0)
            built.cols[fill_c[color[j]]++] = j;
    for (int k : unique)
        built.entries[fill_e[color[ci[k]]]++] = k;
    *this = std::move(built);
}

Model::Model(const ConfigurationSpace &space_, int m, Counters &counters, Diagnostics &diag)
    : space(space_), nv_(static_cast<int>(space_.nv())), m_(m), counters_(counters), diag_(diag)
{
}

void Model::allocate_workspace(const ModelMatrix &M, const ModelMatrix &J, const ModelMatrix &K,
                               const ModelMatrix &C)
{
    q_pert_.setZero(space.nq());
    v_pert_.setZero(nv_);
    f_pert_.setZero(nv_);
    r_pert_.setZero(nv_);
    r_minus_.setZero(nv_);
    f_minus_.setZero(nv_);
    step_.setZero(nv_);
    phi_plus_.setZero(m_);
    phi_minus_.setZero(m_);
    g_plus_.setZero(m_);
    g_minus_.setZero(m_);
    J_pert_.copy_layout(J);  // also serves the constraint acceleration term
    y_pert_.setZero(r_);
    rate_pert_.setZero(r_);
    rate_minus_.setZero(r_);
    if (!g_q_pattern.dense() && g_q_pattern.nnz() > 0 && g_q_groups_.count() == 0)
        g_q_groups_.build(g_q_pattern);
    if (!g_v_pattern.dense() && g_v_pattern.nnz() > 0 && g_v_groups_.count() == 0)
        g_v_groups_.build(g_v_pattern);
    prepare_differences(M, K, C);
}

// n x n scratch only where finite differences may be needed.
void Model::prepare_differences(const ModelMatrix &M, const ModelMatrix &K, const ModelMatrix &C)
{
    const bool fd_stiffness = !cb.stiffness || tangent_mode == GA_TANGENT_FD;
    const bool fd_damping = !cb.damping || tangent_mode == GA_TANGENT_FD;
    if (fd_stiffness && !constant_mass && M_pert_.size() != M.size())
        M_pert_.copy_layout(M);
    if (fd_stiffness && !K.dense() && K.nnz() > 0 && k_groups_.count() == 0)
        k_groups_.build(K, &space);
    if (fd_damping && !C.dense() && C.nnz() > 0 && c_groups_.count() == 0)
        c_groups_.build(C);
}

ga_status Model::callback_status(int rc, const char *name, double t)
{
    if (rc == 0)
        return GA_OK;
    if (rc > 0)
        return diag_.fail(GA_ERR_CALLBACK_RETRY,
                          "%s callback returned %d (recoverable) at t = %.17g", name, rc, t);
    return diag_.fail(GA_ERR_CALLBACK, "%s callback returned %d (fatal) at t = %.17g", name, rc,
                      t);
}


ga_status Model::check_finite(const double *x, Eigen::Index size, Eigen::Index rows,
                              const char *what, double t)
{
    if (all_finite(x, size))
        return GA_OK;
    for (Eigen::Index k = 0; k < size; ++k) {  // which one, for the message
        if (!std::isfinite(x[k])) {
            if (rows == 0)  // a vector, or the values of a declared pattern
                return diag_.fail(GA_ERR_NONFINITE, "%s[%ld] = %g is not finite at t = %.17g",
                                  what, static_cast<long>(k), x[k], t);
            return diag_.fail(GA_ERR_NONFINITE, "%s(%ld,%ld) = %g is not finite at t = %.17g",
                              what, static_cast<long>(k % rows), static_cast<long>(k / rows),
                              x[k], t);
        }
    }
    return GA_OK;
}

// Where a value of a matrix sits, for messages: dense (row, col) or pattern entry k.
static Eigen::Index message_rows(const ModelMatrix &A) { return A.dense() ? A.rows() : 0; }

ga_status Model::mass(double t, const Vec &q, ModelMatrix &M)
{
    if (M.zero())
        return GA_OK;
    count(counters_, GA_COUNT_MASS_EVALS);
    if (auto st = callback_status(user([&] { return cb.mass(t, q.data(), M.data(), cb.user); }), "mass", t))
        return st;
    return check_finite(M.data(), M.size(), message_rows(M), "mass matrix M", t);
}

ga_status Model::force(double t, const Vec &q, const Vec &v, Vec &f, Check check)
{
    if (r_ > 0 && cb.force_y) {
        count(counters_, GA_COUNT_FORCE_EVALS);
        const double *y = y_now->data();
        if (auto st = callback_status(
                user([&] { return cb.force_y(t, q.data(), v.data(), y, f.data(), cb.user); }),
                "force", t))
            return st;
        return check == Check::Now ? check_finite(f.data(), nv_, 0, "force f", t) : GA_OK;
    }
    if (!cb.force) {  // no applied forces: nothing to evaluate, nothing to count
        f.setZero();
        return GA_OK;
    }
    count(counters_, GA_COUNT_FORCE_EVALS);
    if (auto st = callback_status(user([&] { return cb.force(t, q.data(), v.data(), f.data(), cb.user); }), "force",
                                  t))
        return st;
    return check == Check::Now ? check_finite(f.data(), nv_, 0, "force f", t) : GA_OK;
}

ga_status Model::force_p(double t, const Vec &q, const Vec &v, int j, Vec &out)
{
    count(counters_, GA_COUNT_FORCE_EVALS);
    if (auto st = callback_status(
            user([&] { return cb.force_p(t, q.data(), v.data(), j, out.data(), cb.user); }),
            "force_p", t))
        return st;
    return check_finite(out.data(), nv_, 0, "df/dp", t);
}

ga_status Model::mass_p(double t, const Vec &q, int j, const Vec &a, Vec &out)
{
    count(counters_, GA_COUNT_MASS_EVALS);
    if (auto st = callback_status(
            user([&] { return cb.mass_p(t, q.data(), j, a.data(), out.data(), cb.user); }),
            "mass_p", t))
        return st;
    return check_finite(out.data(), nv_, 0, "(dM/dp) a", t);
}

ga_status Model::constraint_p(double t, const Vec &q, int j, Vec &phi_p, ModelMatrix &J_p,
                              Vec *phi_tp)
{
    count(counters_, GA_COUNT_CONSTRAINT_EVALS);
    if (auto st = callback_status(user([&] {
                                      return cb.constraint_p(t, q.data(), j, phi_p.data(),
                                                             J_p.data(),
                                                             phi_tp ? phi_tp->data() : nullptr,
                                                             cb.user);
                                  }),
                                  "constraint_p", t))
        return st;
    if (auto st = check_finite(phi_p.data(), m_, 0, "dPhi/dp", t))
        return st;
    if (auto st = check_finite(J_p.data(), J_p.size(), message_rows(J_p), "dPhi_q/dp", t))
        return st;
    return phi_tp ? check_finite(phi_tp->data(), m_, 0, "dPhi_t/dp", t) : GA_OK;
}

ga_status Model::cost(ga_cost_fn fn, double t, const double *q, const double *v,
                      const double *qdd, const double *lambda, double &value, Vec &d_q,
                      Vec &d_v, Vec &d_qdd, Vec &d_lambda, Vec &d_p)
{
    if (auto st = callback_status(user([&] {
                                      return fn(t, q, v, qdd, lambda, &value, d_q.data(),
                                                d_v.data(), d_qdd.data(), d_lambda.data(),
                                                d_p.data(), cb.user);
                                  }),
                                  "cost", t))
        return st;
    if (!std::isfinite(value))
        return check_finite(&value, 1, 0, "cost value", t);
    if (auto st = check_finite(d_q.data(), d_q.size(), 0, "cost gradient in q", t))
        return st;
    if (auto st = check_finite(d_v.data(), d_v.size(), 0, "cost gradient in v", t))
        return st;
    if (auto st = check_finite(d_qdd.data(), d_qdd.size(), 0, "cost gradient in qdd", t))
        return st;
    if (auto st = check_finite(d_lambda.data(), d_lambda.size(), 0, "cost gradient in lambda", t))
        return st;
    return check_finite(d_p.data(), d_p.size(), 0, "cost gradient in p", t);
}

ga_status Model::constraint(double t, const Vec &q, Vec &phi)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_CONSTRAINT_EVALS);
    if (auto st = callback_status(user([&] { return cb.constraint(t, q.data(), phi.data(), cb.user); }), "constraint",
                                  t))
        return st;
    return check_finite(phi.data(), m_, 0, "constraint Phi", t);
}

ga_status Model::jacobian(double t, const Vec &q, ModelMatrix &J, Check check)
{
    if (m_ == 0 || J.zero())
        return GA_OK;
    count(counters_, GA_COUNT_JACOBIAN_EVALS);
    if (auto st = callback_status(user([&] { return cb.jacobian(t, q.data(), J.data(), cb.user); }), "jacobian", t))
        return st;
    if (check == Check::Deferred)
        return GA_OK;
    return check_finite(J.data(), J.size(), message_rows(J), "constraint Jacobian Phi_q", t);
}

ga_status Model::check_deferred(double t, const Vec &f, const ModelMatrix &J)
{
    if (has_force())
        if (auto st = check_finite(f.data(), nv_, 0, "force f", t))
            return st;
    if (m_ == 0 || J.zero())
        return GA_OK;
    return check_finite(J.data(), J.size(), message_rows(J), "constraint Jacobian Phi_q", t);
}

// Each Phi_i has a symmetric second derivative, so Phi_qq(v, w) = (d/de Phi_q(q + e v)) w:
// the whole block is one directional difference of Phi_q along (v, 1) in (q, t), which also
// takes in Phi_qt = d(Phi_t)/dq for rheonomic constraints.
ga_status Model::velocity_constraint_tangent(double t, const Vec &q, const Vec &v,
                                             const ModelMatrix &J, ModelMatrix &Z,
                                             bool central)
{
    const double q_scale = std::max(space.max_magnitude(q), 1.0);
    const double e = (central ? std::cbrt(kEps) : std::sqrt(kEps)) * q_scale /
                     std::max(v.lpNorm<Eigen::Infinity>(), 1.0);
    space.shifted(q, e, v, q_pert_);
    if (auto st = jacobian(t + e, q_pert_, Z))
        return st;
    if (central) {
        space.shifted(q, -e, v, q_pert_);
        if (auto st = jacobian(t - e, q_pert_, J_pert_))
            return st;
    }
    const double *j = central ? J_pert_.data() : J.data();
    const double span = central ? 2.0 * e : e;
    double *z = Z.data();
    for (Eigen::Index k = 0; k < Z.size(); ++k)
        z[k] = (z[k] - j[k]) / span;
    // The difference is the derivative of Phi_q w along v; Z w differentiates Phi_q v along
    // w. In R^n they are equal; on a group they differ by Phi_q [w, v] (sec. 14), which on a
    // pattern falls outside Phi_q's: there the step adds it in the expanded layout
    // (TangentProduct::add_bracket).
    if (!space.euclidean() && J.dense())
        space.add_bracket(v, J.data(), J.rows(), Z.data());
    return GA_OK;
}

void Model::dynamics_residual(const ModelMatrix &M, const Vec &qdd, const Vec &f,
                              const ModelMatrix &J, const Vec &lambda, Vec &rq)
{
    rq = -f;
    M.multiply_add(1.0, qdd, rq);
    if (lambda.size() > 0)
        J.multiply_transpose_add(1.0, lambda, rq);
}

// r^q at a perturbed position qp (v, qdd, lambda fixed), into r.
ga_status Model::perturbed_residual(double t, const Vec &qp, const Vec &v, const Vec &qdd,
                                    const Vec &lambda, const ModelMatrix &M, Vec &r)
{
    if (!constant_mass) {
        if (M_pert_.size() != M.size())  // prepare_differences was not called: a bug
            return diag_.fail(GA_ERR_INTERNAL, "finite-difference workspace for M missing");
        if (auto st = mass(t, qp, M_pert_))
            return st;
    }
    if (auto st = force(t, qp, v, f_pert_))
        return st;
    if (auto st = jacobian(t, qp, J_pert_))
        return st;
    dynamics_residual(constant_mass ? M : M_pert_, qdd, f_pert_, J_pert_, lambda, r);
    count(counters_, GA_COUNT_RESIDUALS);  // all work counts: the differences' residuals too
    return GA_OK;
}

ga_status Model::stiffness(double t, const Vec &q, const Vec &v, const Vec &qdd,
                           const Vec &lambda, const Vec &rq, const ModelMatrix &M, ModelMatrix &K,
                           bool central)
{
    count(counters_, GA_COUNT_STIFFNESS_EVALS);
    if (cb.stiffness && tangent_mode == GA_TANGENT_AUTO) {
        if (auto st = callback_status(user([&] { return cb.stiffness(t, q.data(), v.data(), qdd.data(),
                                                   lambda.data(), K.data(), cb.user); }),
                                      "stiffness", t))
            return st;
        return check_finite(K.data(), K.size(), message_rows(K), "tangent stiffness K_t", t);
    }
    // Forward differences of r^q; they include the derivatives of M(q) qdd and of
    // Phi_q(q)^T lambda, which structural codes often drop.
    q_pert_ = q;
    if (K.dense()) {
        auto Kd = K.as_dense();
        for (int j = 0; j < nv_; ++j) {
            const double e = central ? central_increment(q[j]) : fd_increment(q[j]);
            space.shift_coordinate(q_pert_, q, j, e);
            if (auto st = perturbed_residual(t, q_pert_, v, qdd, lambda, M, r_pert_))
                return st;
            if (central) {
                space.shift_coordinate(q_pert_, q, j, -e);
                if (auto st = perturbed_residual(t, q_pert_, v, qdd, lambda, M, r_minus_))
                    return st;
                Kd.col(j) = (r_pert_ - r_minus_) / (2.0 * e);
            } else {
                Kd.col(j) = (r_pert_ - rq) / e;
            }
            space.restore_coordinate(q_pert_, q, j);
        }
        return GA_OK;
    }
    K.set_zero();
    if (k_groups_.count() == 0 && K.nnz() > 0)  // prepare_differences was not called: a bug
        return diag_.fail(GA_ERR_INTERNAL, "finite-difference column groups for K_t missing");
    const auto &ri = K.row_index();
    const auto &ci = K.col_index();
    for (int g = 0; g < k_groups_.count(); ++g) {
        for (int p = k_groups_.start[g]; p < k_groups_.start[g + 1]; ++p) {
            const int j = k_groups_.cols[p];
            step_[j] = central ? central_increment(q[j]) : fd_increment(q[j]);
            space.shift_coordinate(q_pert_, q, j, step_[j]);
        }
        if (auto st = perturbed_residual(t, q_pert_, v, qdd, lambda, M, r_pert_))
            return st;
        if (central) {
            for (int p = k_groups_.start[g]; p < k_groups_.start[g + 1]; ++p)
                space.shift_coordinate(q_pert_, q, k_groups_.cols[p], -step_[k_groups_.cols[p]]);
            if (auto st = perturbed_residual(t, q_pert_, v, qdd, lambda, M, r_minus_))
                return st;
        }
        const Vec &base = central ? r_minus_ : rq;
        const double span = central ? 2.0 : 1.0;
        for (int p = k_groups_.entry_start[g]; p < k_groups_.entry_start[g + 1]; ++p) {
            const int k = k_groups_.entries[p];
            K.data()[k] = (r_pert_[ri[k]] - base[ri[k]]) / (span * step_[ci[k]]);
        }
        for (int p = k_groups_.start[g]; p < k_groups_.start[g + 1]; ++p)
            space.restore_coordinate(q_pert_, q, k_groups_.cols[p]);
    }
    return GA_OK;
}

ga_status Model::damping(double t, const Vec &q, const Vec &v, const Vec &f, ModelMatrix &C,
                         bool central)
{
    count(counters_, GA_COUNT_DAMPING_EVALS);
    if (cb.damping && tangent_mode == GA_TANGENT_AUTO) {
        if (auto st = callback_status(user([&] { return cb.damping(t, q.data(), v.data(), C.data(), cb.user); }),
                                      "damping", t))
            return st;
        return check_finite(C.data(), C.size(), message_rows(C), "tangent damping C_t", t);
    }
    if (!has_force()) {
        C.set_zero();
        return GA_OK;
    }
    v_pert_ = v;
    if (C.dense()) {
        auto Cd = C.as_dense();
        for (int j = 0; j < nv_; ++j) {
            const double e = central ? central_increment(v[j]) : fd_increment(v[j]);
            v_pert_[j] = v[j] + e;
            if (auto st = force(t, q, v_pert_, f_pert_))
                return st;
            if (central) {
                v_pert_[j] = v[j] - e;
                if (auto st = force(t, q, v_pert_, f_minus_))
                    return st;
                Cd.col(j) = -(f_pert_ - f_minus_) / (2.0 * e);
            } else {
                Cd.col(j) = -(f_pert_ - f) / e;
            }
            v_pert_[j] = v[j];
        }
        return GA_OK;
    }
    C.set_zero();
    if (c_groups_.count() == 0 && C.nnz() > 0)  // prepare_differences was not called: a bug
        return diag_.fail(GA_ERR_INTERNAL, "finite-difference column groups for C_t missing");
    const auto &ri = C.row_index();
    const auto &ci = C.col_index();
    for (int g = 0; g < c_groups_.count(); ++g) {
        for (int p = c_groups_.start[g]; p < c_groups_.start[g + 1]; ++p) {
            const int j = c_groups_.cols[p];
            step_[j] = central ? central_increment(v[j]) : fd_increment(v[j]);
            v_pert_[j] = v[j] + step_[j];
        }
        if (auto st = force(t, q, v_pert_, f_pert_))
            return st;
        if (central) {
            for (int p = c_groups_.start[g]; p < c_groups_.start[g + 1]; ++p)
                v_pert_[c_groups_.cols[p]] = v[c_groups_.cols[p]] - step_[c_groups_.cols[p]];
            if (auto st = force(t, q, v_pert_, f_minus_))
                return st;
        }
        const Vec &base = central ? f_minus_ : f;
        const double span = central ? 2.0 : 1.0;
        for (int p = c_groups_.entry_start[g]; p < c_groups_.entry_start[g + 1]; ++p) {
            const int k = c_groups_.entries[p];
            C.data()[k] = -(f_pert_[ri[k]] - base[ri[k]]) / (span * step_[ci[k]]);
        }
        for (int p = c_groups_.start[g]; p < c_groups_.start[g + 1]; ++p)
            v_pert_[c_groups_.cols[p]] = v[c_groups_.cols[p]];
    }
    return GA_OK;
}

ga_status Model::constraint_dt(double t, const Vec &q, Vec &out, bool coarse)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_CONSTRAINT_DT_EVALS);
    if (cb.constraint_dt) {
        if (auto st = callback_status(user([&] { return cb.constraint_dt(t, q.data(), out.data(), cb.user); }),
                                      "constraint_dt", t))
            return st;
        return check_finite(out.data(), m_, 0, "constraint time derivative Phi_t", t);
    }
    // Central differences in t over d and d/2, extrapolated (Richardson): error O(d^4) instead
    // of O(d^2), so that a longer d keeps the round-off eps |Phi| / d smaller; index 2 carries
    // the error of Phi_t into Phi_q v (docs/design-notes.md). For constraints that do not
    // depend on t every difference is 0 exactly.
    const double d = kPhiTStep * std::max(std::fabs(t), 1.0);
    for (int half = 0; half < (coarse ? 1 : 2); ++half) {
        const double e = half ? 0.5 * d : d;
        if (auto st = constraint(t + e, q, phi_plus_))
            return st;
        if (auto st = constraint(t - e, q, phi_minus_))
            return st;
        if (half)
            out = (4.0 * (phi_plus_ - phi_minus_) / (2.0 * e) - out) / 3.0;
        else
            out = (phi_plus_ - phi_minus_) / (2.0 * e);
    }
    return GA_OK;
}

ga_status Model::constraint_accel(double t, const Vec &q, const Vec &v, Vec &out)
{
    if (m_ == 0)
        return GA_OK;
    count(counters_, GA_COUNT_ACCEL_EVALS);
    if (cb.constraint_accel) {
        if (auto st = callback_status(user([&] { return cb.constraint_accel(t, q.data(), v.data(), out.data(),
                                                          cb.user); }),
                                      "constraint_accel", t))
            return st;
        return check_finite(out.data(), m_, 0, "constraint acceleration term", t);
    }
    // Along the path s -> (q + s v, t + s) the velocity constraint is
    // g(s) = Phi_q v + Phi_t, and g'(0) = Phi_qq(v, v) + 2 Phi_qt v + Phi_tt. Central
    // difference of g, with an increment that moves q by ~cbrt(eps) relative to its size.
    const double qscale = std::max(space.max_magnitude(q), 1.0);
    const double vscale = std::max(v.lpNorm<Eigen::Infinity>(), 1.0);
    const double s = std::cbrt(kEps) * qscale / vscale;
    for (int side = 0; side < 2; ++side) {
        const double sig = side == 0 ? s : -s;
        Vec &g = side == 0 ? g_plus_ : g_minus_;
        space.shifted(q, sig, v, q_pert_);
        if (auto st = jacobian(t + sig, q_pert_, J_pert_))
            return st;
        if (auto st = constraint_dt(t + sig, q_pert_, g))
            return st;
        J_pert_.multiply_add(1.0, v, g);
    }
    out = (g_plus_ - g_minus_) / (2.0 * s);
    return GA_OK;
}

}  // namespace ga

namespace ga {

ga_status Model::rate(double t, const Vec &q, const Vec &v, const Vec &y, Vec &ydot)
{
    count(counters_, GA_COUNT_RATE_EVALS);
    if (auto st = callback_status(
            user([&] { return cb.rate(t, q.data(), v.data(), y.data(), ydot.data(), cb.user); }),
            "rate", t))
        return st;
    return check_finite(ydot.data(), r_, 0, "rate g", t);
}

// Forward differences with fd_increment: column j of g_q from g at q + e_j, of g_v from v + e_j
// (a group of columns at once where a pattern is declared), of g_y and f_y from y + e_j (the
// force sees the perturbed y through y_now).
ga_status Model::coupling(double t, const Vec &q, const Vec &v, const Vec &y, const Vec &f,
                          const Vec &ydot, CouplingBlocks &B, bool central)
{
    count(counters_, GA_COUNT_COUPLING_EVALS);
    if (cb.coupling) {
        if (auto st = callback_status(user([&] {
                                          return cb.coupling(t, q.data(), v.data(), y.data(),
                                                             B.g_q.data(), B.g_v.data(),
                                                             B.g_y.data(), B.f_y.data(), cb.user);
                                      }),
                                      "coupling", t))
            return st;
        for (const Mat *X : {&B.g_q, &B.g_v, &B.g_y, &B.f_y})
            if (!all_finite(X->data(), X->size()))
                return check_finite(X->data(), X->size(), X->rows(), "coupling block", t);
        return GA_OK;
    }
    for (const bool of_q : {true, false})
        if (auto st = coupling_block(t, q, v, y, ydot, of_q, of_q ? g_q_pattern : g_v_pattern,
                                     of_q ? g_q_groups_ : g_v_groups_, of_q ? B.g_q : B.g_v,
                                     central))
            return st;
    const Vec *y_before = y_now;
    y_pert_ = y;
    y_now = &y_pert_;
    for (int j = 0; j < r_; ++j) {
        const double e = central ? central_increment(y[j]) : fd_increment(y[j]);
        ga_status st = GA_OK;
        for (int side = 0; side < (central ? 2 : 1) && !st; ++side) {
            y_pert_[j] = y[j] + (side == 0 ? e : -e);
            st = rate(t, q, v, y_pert_, side == 0 ? rate_pert_ : rate_minus_);
            if (!st && cb.force_y)
                st = force(t, q, v, side == 0 ? f_pert_ : f_minus_);
        }
        y_pert_[j] = y[j];
        if (st) {
            y_now = y_before;
            return st;
        }
        const double span = central ? 2.0 * e : e;
        B.g_y.col(j) = (rate_pert_ - (central ? rate_minus_ : ydot)) / span;
        if (cb.force_y)
            B.f_y.col(j) = (f_pert_ - (central ? f_minus_ : f)) / span;
        else
            B.f_y.col(j).setZero();
    }
    y_now = y_before;
    return GA_OK;
}

}  // namespace ga

namespace ga {

ga_status Model::coupling_block(double t, const Vec &q, const Vec &v, const Vec &y,
                                const Vec &ydot, bool of_q, const ModelMatrix &pattern,
                                const ColumnGroups &groups, Mat &G, bool central)
{
    Vec &x = of_q ? q_pert_ : v_pert_;
    x = of_q ? q : v;
    const auto evaluate = [&](Vec &out) {
        return of_q ? rate(t, q_pert_, v, y, out) : rate(t, q, v_pert_, y, out);
    };
    // q moves through the space, v is a vector
    const auto shift = [&](int j, double e) {
        if (of_q)
            space.shift_coordinate(x, q, j, e);
        else
            x[j] = v[j] + e;
    };
    const auto restore = [&](int j) {
        if (of_q)
            space.restore_coordinate(x, q, j);
        else
            x[j] = v[j];
    };
    const double span = central ? 2.0 : 1.0;
    if (pattern.dense()) {
        for (int j = 0; j < nv_; ++j) {
            const double e = central ? central_increment(x[j]) : fd_increment(x[j]);
            shift(j, e);
            ga_status st = evaluate(rate_pert_);
            if (!st && central) {
                shift(j, -e);
                st = evaluate(rate_minus_);
            }
            restore(j);
            if (st)
                return st;
            G.col(j) = (rate_pert_ - (central ? rate_minus_ : ydot)) / (span * e);
        }
        return GA_OK;
    }
    G.setZero();
    const auto &rows = pattern.row_index();
    const auto &cols = pattern.col_index();
    for (int g = 0; g < groups.count(); ++g) {
        for (int side = 0; side < (central ? 2 : 1); ++side) {
            for (int k = groups.start[g]; k < groups.start[g + 1]; ++k) {
                const int j = groups.cols[k];
                step_[j] = central ? central_increment(x[j]) : fd_increment(x[j]);
                shift(j, side == 0 ? step_[j] : -step_[j]);
            }
            const ga_status st = evaluate(side == 0 ? rate_pert_ : rate_minus_);
            for (int k = groups.start[g]; k < groups.start[g + 1]; ++k)
                restore(groups.cols[k]);
            if (st)
                return st;
        }
        const Vec &base = central ? rate_minus_ : ydot;
        for (int k = groups.entry_start[g]; k < groups.entry_start[g + 1]; ++k) {
            const int e = groups.entries[k], i = rows[e], j = cols[e];
            G(i, j) = (rate_pert_[i] - base[i]) / (span * step_[j]);
        }
    }
    return GA_OK;
}

}  // namespace ga
