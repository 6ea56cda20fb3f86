// Dense LU factorization with partial pivoting (LAPACK dgetrf/dgetrs) and a condition estimate
// (dgecon), on buffers sized once: factorize and solve never allocate.
#pragma once

#include "../types.hpp"

namespace ga {

class DenseLU {
public:
    void allocate(int size);

    // Factorizes A (copied). Returns false when A is singular or numerically singular
    // (reciprocal condition number below machine epsilon); rcond() then tells how close.
    bool factorize(const Mat &A);
    // Solves A x = b in place.
    void solve(Vec &b) const;

    double rcond() const { return rcond_; }
    int size() const { return size_; }

private:
    int size_ = 0;
    Mat lu_;
    Eigen::VectorXi ipiv_, iwork_;
    mutable Vec work_;
    double rcond_ = 0.0;
};

}  // namespace ga
