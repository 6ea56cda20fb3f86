// Sparse LU factors of a matrix whose pattern is fixed, with a pivot sequence that is kept
// between full factorizations: factorize() chooses the pivots (threshold partial pivoting,
// in a column order given by the caller -- KLU's fill-reducing ordering), refactor() computes
// the factors of new values on the same pattern with the same pivots, solve() solves.
// Left-looking throughout (Gilbert and Peierls; Davis, Direct Methods for Sparse Linear
// Systems, ch. 6), over index lists that refactorizations and solves only read.
//
// Why not KLU's klu_factor, klu_refactor and klu_solve, which do the same arithmetic: on the
// small systems of mechanisms their general bookkeeping costs more than the arithmetic (on
// Andrews' squeezer in 31 coordinates, 61 unknowns, a refactorization took 13 500
// instructions and a solve 5 700; here 8 400 and 4 400), at 100 000 chain links the solves
// streamed the factors more slowly, and taking KLU's factors over would hold them twice at
// every full factorization (docs/design-notes.md).
#pragma once

#include <vector>

namespace ga {

class FixedPivotLU {
public:
    // The diagonal pivot (the row the ordering put there) is kept while it is at least
    // kDiagonalPreference times the largest candidate: it keeps the fill of the ordering.
    // KLU's default is 1e-3, which lets entries grow up to 1000-fold per column: on random
    // patterns (test_klu_system) solves were off by up to 97 eps cond(A), with 0.1 (UMFPACK's
    // pivot tolerance) 5.6, with 1 (plain partial pivoting) 0.3. On the mechanisms 0.1 costs
    // next to nothing (the chain: the same pivots; Andrews-31: 0.4 % more instructions per
    // step); plain partial pivoting fills the chain's factors more (6 % more per step).
    static constexpr double kDiagonalPreference = 0.1;

    enum class Outcome { Factorized, Singular, OverBudget };
    // LU factors of D A with pivots chosen now: A the N x N matrix in CSC form (colptr,
    // rowind, values; the pattern must stay alive and fixed while these factors are used),
    // D = diag(row_scale), column k of the factors from column Q[k] of A, whose diagonal row
    // is diagonal_row[k]. expected_entries: of L and of U each (storage reserved; more is
    // allocated as needed). Singular: a column has no nonzero pivot candidate. OverBudget: L
    // or U grew past fill_budget entries (0: no budget) -- the pivots the values called for
    // undo the ordering, and another ordering may do better. The factors are ready only when
    // Factorized. Allocates the first time, and later only where new pivots fill more than
    // earlier ones; throws std::bad_alloc.
    // forced_rows (optional): the pivot row of every column, as pivot_rows() gave them -- the
    // factors then have the structure of that factorization (for a refactor() to follow: the
    // values computed here may hold a zero pivot); Singular if a row is no candidate there.
    Outcome factorize(int N, const int *colptr, const int *rowind, const double *values,
                      const double *row_scale, const int *diagonal_row, const int *Q,
                      double expected_entries, double fill_budget,
                      const int *forced_rows = nullptr);
    // The pivot row of each column of the factors at hand (valid when ready()).
    const std::vector<int> &pivot_rows() const { return P_; }
    // Allocates up front what factorize() needs for an N x N matrix with nnz entries whose
    // factors hold expected_entries each (at setup: the first factorization then allocates
    // only if it fills more). Throws std::bad_alloc.
    void reserve(int N, int nnz, double expected_entries);
    bool ready() const { return ready_; }
    void clear() { ready_ = false; }  // the next matrix needs pivots chosen afresh

    // LU factors of D A for new values of A on the pattern given to factorize() (in its CSC
    // order), with the same pivots and row scaling D. Never allocates. Returns
    // min |u_ii| / max |u_ii| (0 if a pivot is zero or not finite): a small value says the
    // old pivots no longer fit these values.
    double refactor(const double *values);
    // The pivot ratio of the factors at hand, as refactor() returns it.
    double pivot_ratio() const { return pivot_ratio_; }

    // rhs <- A^{-1} rhs, in place (length N).
    void solve(double *rhs);
    // rhs <- A^{-T} rhs, in place (length N): the adjoint sweep's transposed solves.
    void solve_transpose(double *rhs);
    // The same for a right-hand side and a solution kept in two blocks of their callers: rows
    // [0, n1) of b are c1 b1, the others c2 b2; x1 gets rows [0, n1) of x, x2 the others
    // divided by div2. Bit for bit what copying them in and out around solve() gives, without
    // the two passes over a vector of length N (which at 100 000 chain links come from
    // memory, not the cache).
    void solve_blocks(const double *b1, double c1, const double *b2, double c2, int n1,
                      double *x1, double *x2, double div2);

private:
    void sweeps(double *w) const;  // w <- U^{-1} L^{-1} w
    bool ready_ = false;
    int N_ = 0;
    const int *colptr_ = nullptr;  // the caller's pattern
    std::vector<int> P_, Q_;       // row i of P A Q is row P_[i] of A; column j is column Q_[j]
    std::vector<int> qinv_;        // column j of A is column qinv_[j] of P A Q (pinv_: rows)
    std::vector<int> a_row_;       // for each entry of A (CSC order): its row in P A Q
    std::vector<double> scale_;    // D, row i of P A Q scaled by scale_[i]
    // strictly lower part of L (unit diagonal), by columns; strictly upper part of U by
    // columns, rows ascending (the order the left-looking update needs); the diagonal of U
    std::vector<int> Lp_, Li_, Up_, Ui_;
    std::vector<double> Lx_, Ux_, Ud_;
    std::vector<double> work_;  // dense column, all zero between calls
    std::vector<int> pinv_, mark_, reach_, stack_, next_;  // workspace of factorize()
    double pivot_ratio_ = 0.0;
};

}  // namespace ga
