#include "dense_lu.hpp"

#include <cstddef>
#include <limits>

extern "C" {
// LAPACK (Fortran calling convention; gfortran passes CHARACTER lengths as trailing size_t).
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info, std::size_t trans_len);
double dlange_(const char *norm, const int *m, const int *n, const double *a, const int *lda,
               double *work, std::size_t norm_len);
void dgecon_(const char *norm, const int *n, const double *a, const int *lda, const double *anorm,
             double *rcond, double *work, int *iwork, int *info, std::size_t norm_len);
}

namespace ga {

void DenseLU::allocate(int size)
{
    size_ = size;
    lu_.setZero(size, size);
    ipiv_.setZero(size);
    iwork_.setZero(size);
    work_.setZero(4 * static_cast<Eigen::Index>(size));
}

bool DenseLU::factorize(const Mat &A)
{
    lu_ = A;  // same size: no allocation
    const int n = size_;
    int info = 0;
    const double anorm = dlange_("1", &n, &n, lu_.data(), &n, work_.data(), 1);
    dgetrf_(&n, &n, lu_.data(), &n, ipiv_.data(), &info);
    if (info > 0) {  // exact zero pivot
        rcond_ = 0.0;
        return false;
    }
    dgecon_("1", &n, lu_.data(), &n, &anorm, &rcond_, work_.data(), iwork_.data(), &info, 1);
    return rcond_ >= std::numeric_limits<double>::epsilon();
}

void DenseLU::solve(Vec &b) const
{
    const int n = size_;
    const int nrhs = 1;
    int info = 0;
    dgetrs_("N", &n, &nrhs, lu_.data(), &n, ipiv_.data(), b.data(), &n, &info, 1);
}

}  // namespace ga
