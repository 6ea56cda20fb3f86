#include "tangent_product.hpp"

#include <algorithm>
#include <tuple>

namespace ga {

void TangentProduct::setup(const ModelMatrix &A, const ConfigurationSpace &space)
{
    offset_.assign(static_cast<std::size_t>(space.rotations()), 0);
    std::size_t size = 0;
    for (int r = 0; r < space.rotations(); ++r) {
        offset_[static_cast<std::size_t>(r)] = static_cast<int>(size);
        size += static_cast<std::size_t>(space.rotation_width(r) * space.rotation_width(r));
    }
    T_.assign(size, 0.0);
    if (A.dense()) {
        out_.copy_layout(A);
        return;
    }
    // key of an entry: its row and its column, or the rotation's first column for all three
    const int nnz = A.nnz();
    const std::vector<int> &ri = A.row_index(), &ci = A.col_index();
    rotation_.assign(nnz, -1);
    local_.assign(nnz, 0);
    std::vector<std::tuple<int, int, int>> keys;  // (col0, row, entry)
    keys.reserve(static_cast<std::size_t>(nnz));
    for (int k = 0; k < nnz; ++k) {
        int l = 0;
        const int r = space.rotation_of(ci[k], &l);
        rotation_[k] = r;
        local_[k] = l;
        const int c0 = r < 0 ? ci[k] : static_cast<int>(space.rotation_start(r));
        keys.emplace_back(c0, ri[k], k);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<int> rows, cols;
    target_.assign(nnz, 0);
    for (std::size_t p = 0; p < keys.size(); ++p) {
        const auto [c0, row, k] = keys[p];
        const bool fresh = p == 0 || std::get<0>(keys[p - 1]) != c0 ||
                           std::get<1>(keys[p - 1]) != row;
        if (fresh) {
            const int width = rotation_[k] < 0 ? 1 : space.rotation_width(rotation_[k]);
            for (int w = 0; w < width; ++w) {
                rows.push_back(row);
                cols.push_back(c0 + w);
            }
        }
        target_[k] = static_cast<int>(rows.size()) -
                     (rotation_[k] < 0 ? 1 : space.rotation_width(rotation_[k]));
    }
    out_.set_pattern(A.rows(), A.cols(), rows.data(), cols.data(), static_cast<int>(rows.size()));
    out_.allocate();
}

void TangentProduct::apply(const ModelMatrix &A, const Vec *xi, const ConfigurationSpace &space)
{
    if (A.dense()) {
        std::copy(A.data(), A.data() + A.size(), out_.data());
        if (xi)
            space.right_multiply_tangent(*xi, out_.data(), A.rows(), A.rows());
        return;
    }
    out_.set_zero();
    if (xi)
        space.rotation_tangents(*xi, T_.data());
    const double *a = A.data();
    double *o = out_.data();
    for (std::size_t k = 0; k < target_.size(); ++k) {
        const int r = rotation_[k];
        if (r < 0) {
            o[target_[k]] += a[k];
        } else if (!xi) {
            o[target_[k] + local_[k]] += a[k];
        } else {  // (A T)_{i, c} = sum_l A_{i, l} T_{l, c}: row local_ of T
            const int w = space.rotation_width(r);
            const double *t = T_.data() + offset_[r] + w * local_[k];
            for (int c = 0; c < w; ++c)
                o[target_[k] + c] += a[k] * t[c];
        }
    }
}

void TangentProduct::add_bracket(const ModelMatrix &J, const Vec &v, const Vec *xi,
                                 const ConfigurationSpace &space)
{
    space.rotation_brackets(v, xi, T_.data());
    const double *a = J.data();
    double *o = out_.data();
    for (std::size_t k = 0; k < target_.size(); ++k) {
        const int r = rotation_[k];
        if (r < 0)
            continue;
        const int w = space.rotation_width(r);
        const double *g = T_.data() + offset_[r] + w * local_[k];
        for (int c = 0; c < w; ++c)
            o[target_[k] + c] += a[k] * g[c];
    }
}

}  // namespace ga
