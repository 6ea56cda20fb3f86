#include "matrix.hpp"

#include <cmath>

namespace ga {

void ModelMatrix::set_dense(int rows, int cols)
{
    rows_ = rows;
    cols_ = cols;
    dense_ = true;
    diagonal_ = false;
    row_.clear();
    col_.clear();
}

void ModelMatrix::set_pattern(int rows, int cols, const int *row, const int *col, int nnz)
{
    // copied first: running out of memory leaves the matrix as it was (it was left declared
    // sparse with a part of its pattern, or none)
    std::vector<int> r(row, row + nnz), c(col, col + nnz);
    rows_ = rows;
    cols_ = cols;
    dense_ = false;
    row_.swap(r);
    col_.swap(c);
    diagonal_ = rows == cols && row_ == col_;
}

void ModelMatrix::allocate()
{
    const Eigen::Index size = dense_ ? Eigen::Index(rows_) * cols_ : Eigen::Index(row_.size());
    values_.setZero(size);
}

void ModelMatrix::to_dense(Mat &D) const
{
    if (dense_) {
        D = as_dense();
        return;
    }
    D.setZero(rows_, cols_);
    for (std::size_t k = 0; k < row_.size(); ++k)
        D(row_[k], col_[k]) += values_[static_cast<Eigen::Index>(k)];
}

void ModelMatrix::copy_layout(const ModelMatrix &other)
{
    rows_ = other.rows_;
    cols_ = other.cols_;
    dense_ = other.dense_;
    diagonal_ = other.diagonal_;
    row_ = other.row_;
    col_ = other.col_;
    allocate();
}

void ModelMatrix::multiply_add(double alpha, const Vec &x, Vec &y) const
{
    if (dense_) {
        if (rows_ > 0 && cols_ > 0)
            y.noalias() += alpha * (as_dense() * x);
        return;
    }
    const double *v = values_.data();
    for (std::size_t k = 0; k < row_.size(); ++k)
        y[row_[k]] += alpha * v[k] * x[col_[k]];
}

void ModelMatrix::multiply_transpose_add(double alpha, const Vec &x, Vec &y) const
{
    if (dense_) {
        if (rows_ > 0 && cols_ > 0)
            y.noalias() += alpha * (as_dense().transpose() * x);
        return;
    }
    const double *v = values_.data();
    for (std::size_t k = 0; k < row_.size(); ++k)
        y[col_[k]] += alpha * v[k] * x[row_[k]];
}

void ModelMatrix::multiply_add_row_abs_sums(const Vec &x, Vec &y, Vec &s) const
{
    const double *v = values_.data();
    if (dense_) {  // column by column, as stored
        for (int j = 0; j < cols_; ++j, v += rows_)
            for (int i = 0; i < rows_; ++i) {
                y[i] += v[i] * x[j];
                s[i] += std::abs(v[i]);
            }
        return;
    }
    for (std::size_t k = 0; k < row_.size(); ++k) {
        y[row_[k]] += v[k] * x[col_[k]];
        s[row_[k]] += std::abs(v[k]);
    }
}

}  // namespace ga
