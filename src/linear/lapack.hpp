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
