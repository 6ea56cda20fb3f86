// ga::ModelMatrix: a matrix that a user callback fills -- M, Phi_q, K_t or C_t.
// Dense and column-major by default; when the user declared a sparsity pattern (triplets),
// the callback writes one value per declared entry, in the declared order (duplicates add up),
// and no dense rows x cols object exists. An empty pattern declares the matrix identically
// zero: it is never evaluated.
#pragma once

#include <vector>

#include "types.hpp"

namespace ga {

class ModelMatrix {
public:
    void set_dense(int rows, int cols);
    void set_pattern(int rows, int cols, const int *row, const int *col, int nnz);
    void allocate();  // sizes the value buffer once (setup)

    int rows() const { return rows_; }
    int cols() const { return cols_; }
    bool dense() const { return dense_; }
    bool zero() const { return !dense_ && row_.empty(); }
    bool diagonal() const { return diagonal_; }  // a declared pattern on the diagonal only
    int nnz() const { return static_cast<int>(row_.size()); }  // pattern entries
    const std::vector<int> &row_index() const { return row_; }
    const std::vector<int> &col_index() const { return col_; }

    double *data() { return values_.data(); }
    const double *data() const { return values_.data(); }
    Eigen::Index size() const { return values_.size(); }
    Eigen::Map<const Mat> as_dense() const { return {values_.data(), rows_, cols_}; }
    Eigen::Map<Mat> as_dense() { return {values_.data(), rows_, cols_}; }
    void set_zero() { values_.setZero(); }

    void multiply_add(double alpha, const Vec &x, Vec &y) const;            // y += a A x
    void multiply_transpose_add(double alpha, const Vec &x, Vec &y) const;  // y += a A^T x
    // y += A x and s_i += sum_j |A_ij|, in one pass
    void multiply_add_row_abs_sums(const Vec &x, Vec &y, Vec &s) const;

    // The matrix as a dense one, into D (a pattern's repeated entries add up).
    void to_dense(Mat &D) const;

    // Same layout (and pattern) as another matrix, for scratch copies.
    void copy_layout(const ModelMatrix &other);

private:
    int rows_ = 0, cols_ = 0;
    bool dense_ = true, diagonal_ = false;
    std::vector<int> row_, col_;
    Vec values_;
};

}  // namespace ga
