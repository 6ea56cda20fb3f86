// Sparse LU factors of a matrix whose pattern and pivot sequence are fixed: the row and column
// orders and the patterns of L and U are taken once from a factorization that chose them
// (KLU's, with partial pivoting), and every later matrix on the same pattern is refactorized
// and solved by a left-looking kernel over those index lists.
//
// Why not klu_refactor and klu_solve: on the small systems of mechanisms their general
// bookkeeping costs more than the arithmetic. On Andrews' squeezer in 31 coordinates (61
// unknowns, 177 entries, 341 in L and U) KLU took 11 000 instructions to refactorize and 5 600
// to solve (docs/design-notes.md has the figures with this kernel).
#pragma once

#ifdef GALPHA_HAVE_KLU
#include <klu.h>

#include <vector>

namespace ga {

class FixedPivotLU {
public:
    // The orders and patterns of KLU's factorization `numeric` of D A, A the N x N matrix in
    // CSC form (colptr, rowind) and D = diag(row_scale) (no block triangular form, no
    // scaling by KLU), and its values. Frees `numeric` (sets it to null) as soon as its
    // factors are copied. Throws std::bad_alloc (the caller then frees `numeric`).
    void build(int N, const int *colptr, const int *rowind, const double *row_scale,
               klu_symbolic *symbolic, klu_numeric *&numeric, klu_common *common);
    bool ready() const { return ready_; }
    void clear() { ready_ = false; }  // the next matrix needs pivots chosen afresh

    // LU factors of D A for a new matrix A on the pattern given to build() (values in its CSC
    // order), with the same pivots and row scaling D. Returns min |u_ii| / max |u_ii| (0 if a pivot is zero or not
    // finite): a small value says the old pivots no longer fit these values.
    double refactor(const double *values);
    // The pivot ratio of the factors at hand, as refactor() returns it.
    double pivot_ratio() const { return pivot_ratio_; }

    // rhs <- A^{-1} rhs, in place (length N).
    void solve(double *rhs);

private:
    bool ready_ = false;
    int N_ = 0;
    const int *colptr_ = nullptr;  // the caller's pattern (KluSystem keeps it alive and fixed)
    std::vector<int> P_, Q_;       // row i of P A Q is row P_[i] of A; column j is column Q_[j]
    std::vector<int> a_row_;       // for each entry of A (CSC order): its row in P A Q
    std::vector<double> scale_;    // D, row i of P A Q scaled by scale_[i]
    // strictly lower part of L (unit diagonal), by columns; strictly upper part of U by
    // columns, rows ascending (the order the left-looking update needs); the diagonal of U
    std::vector<int> Lp_, Li_, Up_, Ui_;
    std::vector<double> Lx_, Ux_, Ud_;
    std::vector<double> work_;  // dense column, all zero between calls
    double pivot_ratio_ = 0.0;
};

}  // namespace ga
#endif
