// The 1-norm condition estimate of a dense LU, computed by galpha itself rather than by
// LAPACK's dgecon: dgecon's bits are those of the system BLAS it calls (reference, OpenBLAS and
// BLIS round differently), and GA_INFO_RCOND would follow whichever BLAS the machine selects.
#pragma once

namespace ga {

// 1-norm of an N x N column-major matrix (the largest column sum of |a_ij|).
double norm1(int N, const double *a);

// Reciprocal 1-norm condition estimate 1 / (|A|_1 |A^-1|_1) of an N x N matrix from its LU
// factors in LAPACK's layout (unit lower factor below the diagonal, U on and above it; the
// row exchanges do not change a 1-norm), given anorm = |A|_1. |A^-1|_1 is estimated by
// Hager's method as refined by Higham (LAPACK's dlacon/dlacn2), which is a lower bound and
// exact for most small matrices. work: 2N doubles. 0 when a factor solve overflows.
double lu_rcond(int N, const double *lu, double anorm, double *work);

}  // namespace ga
