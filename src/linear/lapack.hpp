// The LAPACK routines galpha calls, for GA_LINEAR_DENSE_LAPACK alone: the one choice whose bits
// are the system BLAS's (Fortran calling convention; gfortran passes CHARACTER lengths as
// trailing size_t arguments).
#pragma once

#include <cstddef>

extern "C" {
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info, std::size_t trans_len);
}

