// A dense LU with partial pivoting for the saddle-point matrices of mechanisms: unblocked,
// right-looking, in place, and skipping every multiplier that is exactly zero.
//
// Why a third dense kernel: a mechanism's iteration matrix is small (tens of unknowns) and
// mostly zero even when stored densely (the m x m zero block, a mass matrix that is diagonal
// per body, a Jacobian row that touches two bodies). A blocked library LU pays for its
// blocking at these sizes and multiplies every zero; this loop does neither. Measured on the
// real iteration matrices (bench/linear_algebra): 13 unknowns (Andrews, 7 angles) 2x faster
// than Eigen's PartialPivLU, 61 unknowns (Andrews, 31 coordinates) 3x, a 64-link chain stored
// densely 5x; on a matrix without zeros it falls behind Eigen from about 40 unknowns on, so
// the dense systems choose per factorization with unblocked_lu_preferred.
//
// Layout and pivots as LAPACK's dgetrf (column-major, leading dimension N, unit lower factor
// below the diagonal, ipiv[k]: the row exchanged with row k at step k, zero-based), so that
// lu_rcond (condition.hpp) can estimate the condition of the factors.
#pragma once

namespace ga {

// The choice made for each factorization by default (GA_LINEAR_DENSE): true when N is small
// or A (N x N, column-major) mostly zero. A function of A alone, so that a run restarted
// from a checkpoint makes the same choices as the run it continues.
bool unblocked_lu_preferred(int N, const double *A);

// false on an exactly zero pivot column (the factors are then incomplete). extent (2N ints):
// where the nonzeros of each column of L end and those of each column of U begin, so that
// banded factors are walked over their band only; inverse_diagonal (N): 1 / U_kk.
bool unblocked_lu(int N, double *A, int *ipiv, int *extent, double *inverse_diagonal);
// b <- A^-1 b with the factors of unblocked_lu.
void unblocked_lu_solve(int N, const double *LU, const int *ipiv, const int *extent,
                        const double *inverse_diagonal, double *b);

}  // namespace ga
