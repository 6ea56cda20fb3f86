// Assembly of dense matrices from the model's blocks, shared by the dense saddle-point backend
// and the dense stabilized index-2 system.
#pragma once

#include <cstddef>

#include "../matrix.hpp"

namespace ga {

// S(row0 + i, col0 + j) += c A(i, j), S column-major with leading dimension ld; A dense or a
// declared pattern. Plain loops: at mechanism sizes Eigen's block expressions cost several
// times the additions.
inline void add_block(double *S, int ld, int row0, int col0, double c, const ModelMatrix &A)
{
    const double *a = A.data();
    if (A.dense()) {
        const int rows = A.rows();
        for (int j = 0; j < A.cols(); ++j) {
            double *s = S + static_cast<std::ptrdiff_t>(col0 + j) * ld + row0;
            const double *aj = a + static_cast<std::ptrdiff_t>(j) * rows;
            for (int i = 0; i < rows; ++i)
                s[i] += c * aj[i];
        }
        return;
    }
    const auto &ri = A.row_index();
    const auto &ci = A.col_index();
    for (int k = 0; k < A.nnz(); ++k)
        S[static_cast<std::ptrdiff_t>(col0 + ci[k]) * ld + row0 + ri[k]] += c * a[k];
}

}  // namespace ga
