// The LAPACK routines galpha calls (Fortran calling convention; gfortran passes CHARACTER
// lengths as trailing size_t arguments).
#pragma once

#include <cstddef>

extern "C" {
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info, std::size_t trans_len);
double dlange_(const char *norm, const int *m, const int *n, const double *a, const int *lda,
               double *work, std::size_t norm_len);
void dgecon_(const char *norm, const int *n, const double *a, const int *lda, const double *anorm,
             double *rcond, double *work, int *iwork, int *info, std::size_t norm_len);
}

namespace ga {
// Reciprocal 1-norm condition estimate of an N x N matrix from its LU factors in LAPACK layout
// (any of galpha's dense kernels), given the 1-norm of the matrix; work 4N, iwork N.
inline double lu_rcond(int N, const double *lu, double anorm, double *work, int *iwork)
{
    double rcond = 0.0;
    int info = 0;
    dgecon_("1", &N, lu, &N, &anorm, &rcond, work, iwork, &info, 1);
    return rcond;
}

// 1-norm of an N x N column-major matrix (work is not referenced for this norm).
inline double norm1(int N, const double *a, double *work)
{
    return dlange_("1", &N, &N, a, &N, work, 1);
}
}  // namespace ga
