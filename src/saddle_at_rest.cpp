// The model at rest with a saddle-point factorization of its own (saddle_at_rest.hpp).
#include "saddle_at_rest.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <new>

#include "at_rest.hpp"

namespace ga {

SaddleAtRest::SaddleAtRest(Stepper &kernel, double t)
    : f(kernel.nv()), phi(kernel.m()), kernel_(kernel), model_(kernel.model), t_(t),
      n_(kernel.nv()), m_(kernel.m()), zero_(Vec::Zero(kernel.nv())), rp_(kernel.nv()),
      rm_(kernel.nv()), qq_(kernel.nv()), step_(Vec::Zero(kernel.nv()))
{
    M.copy_layout(kernel.matrix(GA_MATRIX_MASS));
    J.copy_layout(kernel.matrix(GA_MATRIX_JACOBIAN));
    K.copy_layout(kernel.matrix(GA_MATRIX_STIFFNESS));
    J_pert_.copy_layout(J);
    // the statics need K_t itself: sparse only where it has a pattern
    if (kernel.sparse_wanted() && !K.dense())
        backend_ = make_sparse_backend();
    sparse_ = backend_ != nullptr;
    if (!backend_) {
        const double N = static_cast<double>(n_) + static_cast<double>(m_);
        if (N * N * sizeof(double) > static_cast<double>(PTRDIFF_MAX))
            throw std::bad_alloc();
        backend_ = make_dense_backend(DenseKind::Auto);
    }
    ModelMatrix no_damping;  // at rest C_t does not enter S
    no_damping.set_pattern(n_, n_, nullptr, nullptr, 0);
    backend_->setup(n_, m_, M, J, K, no_damping, false);
    if (!K.dense() && K.nnz() > 0 && !(model_.cb.stiffness))
        groups_.build(K, &model_.space);
}

ga_status SaddleAtRest::force(const Vec &q)
{
    return model_.force(t_, q, zero_, f);
}

ga_status SaddleAtRest::constraint(const Vec &q)
{
    return m_ > 0 ? model_.constraint(t_, q, phi) : GA_OK;
}

ga_status SaddleAtRest::jacobian(const Vec &q)
{
    return m_ > 0 ? model_.jacobian(t_, q, J) : GA_OK;
}

ga_status SaddleAtRest::mass(const Vec &q)
{
    return model_.mass(t_, q, M);
}

void SaddleAtRest::residual(const Vec &lambda, Vec &r) const
{
    r = -f;
    if (m_ > 0)
        J.multiply_transpose_add(1.0, lambda, r);
}

ga_status SaddleAtRest::residual_at(const Vec &q, const Vec &lambda, Vec &r)
{
    if (auto st = model_.force(t_, q, zero_, r))
        return st;
    r = -r;
    if (m_ > 0) {
        if (auto st = model_.jacobian(t_, q, J_pert_))
            return st;
        J_pert_.multiply_transpose_add(1.0, lambda, r);
    }
    return GA_OK;
}

ga_status SaddleAtRest::stiffness(const Vec &q, const Vec &lambda)
{
    if (model_.cb.stiffness) {
        if (K.zero())
            return GA_OK;
        const Restore<ga_tangent_mode> keep(model_.tangent_mode);
        model_.tangent_mode = GA_TANGENT_AUTO;
        Vec unused;
        return model_.stiffness(t_, q, zero_, zero_, lambda, unused, M, K);
    }
    // central differences (docs/algorithms.md sec. 15: truncation and round-off balanced)
    qq_ = q;
    const ConfigurationSpace &space = model_.space;
    if (K.dense()) {
        auto Kd = K.as_dense();
        for (int j = 0; j < n_; ++j) {
            const double e = rest::step_for(q[j]);
            space.shift_coordinate(qq_, q, j, e);
            if (auto st = residual_at(qq_, lambda, rp_))
                return st;
            space.shift_coordinate(qq_, q, j, -e);
            if (auto st = residual_at(qq_, lambda, rm_))
                return st;
            space.restore_coordinate(qq_, q, j);
            Kd.col(j) = (rp_ - rm_) / (2.0 * e);
        }
        return GA_OK;
    }
    K.set_zero();
    const auto &ri = K.row_index();
    const auto &ci = K.col_index();
    for (int g = 0; g < groups_.count(); ++g) {
        const int c0 = groups_.start[g], c1 = groups_.start[g + 1];
        for (int p = c0; p < c1; ++p) {
            const int j = groups_.cols[p];
            step_[j] = rest::step_for(q[j]);
            space.shift_coordinate(qq_, q, j, step_[j]);
        }
        if (auto st = residual_at(qq_, lambda, rp_))
            return st;
        for (int p = c0; p < c1; ++p)
            space.shift_coordinate(qq_, q, groups_.cols[p], -step_[groups_.cols[p]]);
        if (auto st = residual_at(qq_, lambda, rm_))
            return st;
        for (int p = c0; p < c1; ++p)
            space.restore_coordinate(qq_, q, groups_.cols[p]);
        // no two columns of a group share a row: row i of the difference is column j's
        for (int e = groups_.entry_start[g]; e < groups_.entry_start[g + 1]; ++e) {
            const int k = groups_.entries[e];
            K.data()[k] = (rp_[ri[k]] - rm_[ri[k]]) / (2.0 * step_[ci[k]]);
        }
    }
    return GA_OK;
}

bool SaddleAtRest::factorize(double cM, double cK)
{
    SaddleBlocks b;
    b.M = &M;
    b.cM = cM;
    b.K = cK != 0.0 ? &K : nullptr;
    b.cK = cK;
    b.J = &J;
    return backend_->factorize(b);
}

bool SaddleAtRest::balancing_multipliers(Vec &lambda)
{
    if (m_ == 0) {
        lambda.resize(0);
        return true;
    }
    if (!factorize(1.0, 0.0))
        return false;
    Vec rhs(n_ + m_);
    rhs.head(n_) = f;
    rhs.tail(m_).setZero();
    solve(rhs);
    lambda = rhs.tail(m_);
    return all_finite(lambda);
}

double SaddleAtRest::max_abs_f() const
{
    return rest::max_abs(f);
}

double SaddleAtRest::max_abs_stiffness() const
{
    if (K.zero())
        return 0.0;
    const Eigen::Map<const Vec> values(K.data(), K.size());
    return rest::max_abs(values);
}

double SaddleAtRest::max_abs_constraint_force(const Vec &lambda) const
{
    if (m_ == 0)
        return 0.0;
    Vec g = Vec::Zero(n_);
    J.multiply_transpose_add(1.0, lambda, g);
    return rest::max_abs(g);
}

}  // namespace ga
