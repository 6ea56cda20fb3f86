#include "fixed_pivot_lu.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "../types.hpp"

namespace ga {

namespace {
// min |d_i| / max |d_i|; 0 if an entry is not finite or all are zero
double ratio_of(const double *d, int N)
{
    if (!all_finite(d, N))
        return 0.0;
    double lo = HUGE_VAL, hi = 0.0;
    for (int i = 0; i < N; ++i) {
        const double a = std::abs(d[i]);
        lo = a < lo ? a : lo;
        hi = a > hi ? a : hi;
    }
    return hi > 0.0 ? lo / hi : 0.0;
}

// The rows of column k of L and U: those reached from the rows of A's column [first, last)
// through the columns of L computed so far (row i leads to the rows of L(:, pinv[i]) once
// it is a pivot row), depth first without recursion. Returns top: reach[top..N) lists them in
// an order where every row comes before the rows it updates. mark[i] == k: row i is listed.
int reach_of(int k, const int *first, const int *last, const int *Lp, const int *Li,
             const int *pinv, int *mark, int *reach, int *stack, int *next, int N)
{
    int top = N;
    for (const int *row = first; row != last; ++row) {
        if (mark[*row] == k)
            continue;
        int head = 0;
        stack[0] = *row;
        mark[*row] = k;
        next[0] = pinv[*row] >= 0 ? Lp[pinv[*row]] : 0;
        while (head >= 0) {
            const int i = stack[head], c = pinv[i];
            const int end = c >= 0 ? Lp[c + 1] : 0;
            int q = next[head];
            while (q < end && mark[Li[q]] == k)
                ++q;
            if (q < end) {  // descend into an unvisited row
                next[head] = q + 1;
                const int r = Li[q];
                mark[r] = k;
                stack[++head] = r;
                next[head] = pinv[r] >= 0 ? Lp[pinv[r]] : 0;
            } else {
                reach[--top] = i;  // every row below it is listed: finished
                --head;
            }
        }
    }
    return top;
}
}  // namespace

void FixedPivotLU::reserve(int N, int nnz, double expected_entries)
{
    for (auto *v : {&pinv_, &mark_, &reach_, &stack_, &next_, &P_, &Q_, &qinv_})
        v->reserve(N);
    for (auto *v : {&Lp_, &Up_})
        v->reserve(N + 1);
    for (auto *v : {&work_, &Ud_, &scale_})
        v->reserve(N);
    a_row_.reserve(nnz);
    const auto expected = static_cast<std::size_t>(std::min(expected_entries, 1e9));
    Li_.reserve(expected);
    Lx_.reserve(expected);
    Ui_.reserve(expected);
    Ux_.reserve(expected);
}

FixedPivotLU::Outcome FixedPivotLU::factorize(int N, const int *colptr, const int *rowind,
                                              const double *values, const double *row_scale,
                                              const int *diagonal_row, const int *Q,
                                              double expected_entries, double fill_budget,
                                              const int *forced_rows)
{
    ready_ = false;
    N_ = N;
    colptr_ = colptr;
    Q_.assign(Q, Q + N);
    qinv_.resize(N);
    for (int k = 0; k < N; ++k)
        qinv_[Q[k]] = k;
    // During the factorization, rows keep their own numbers: row i is the pivot of column
    // pinv[i] once chosen (-1 before); L's row indices are renumbered at the end. The
    // workspace and the factors' storage stay from one full factorization to the next: new
    // pivots allocate only where they fill more than earlier ones did.
    pinv_.assign(N, -1);
    mark_.assign(N, -1);
    reach_.resize(N);
    stack_.resize(N);
    next_.resize(N);
    int *pinv = pinv_.data(), *mark = mark_.data(), *reach = reach_.data();
    work_.assign(N, 0.0);
    double *x = work_.data();
    Lp_.assign(N + 1, 0);
    Up_.assign(N + 1, 0);
    Ud_.assign(N, 0.0);
    Li_.clear();
    Lx_.clear();
    Ui_.clear();
    Ux_.clear();
    reserve(N, colptr[N], expected_entries);  // no allocation if reserved before

    for (int k = 0; k < N; ++k) {
        const int col = Q[k];
        const int top = reach_of(k, rowind + colptr[col], rowind + colptr[col + 1], Lp_.data(),
                                 Li_.data(), pinv, mark, reach, stack_.data(), next_.data(), N);
        // Numeric: x = (D A)(:, col), minus the columns of L of the pivotal rows in reach
        for (int p = colptr[col]; p < colptr[col + 1]; ++p)
            x[rowind[p]] = row_scale[rowind[p]] * values[p];
        for (int t = top; t < N; ++t) {
            const int i = reach[t], c = pinv[i];
            if (c < 0)
                continue;
            const double u = x[i];
            for (int q = Lp_[c]; q < Lp_[c + 1]; ++q)
                x[Li_[q]] -= Lx_[q] * u;
        }
        // The pivot: the diagonal row if its entry is within kDiagonalPreference of the
        // largest candidate (as KLU's default), else the largest.
        int pivot = -1;
        double largest = 0.0;
        for (int t = top; t < N; ++t) {
            const int i = reach[t];
            if (pinv[i] < 0 && std::abs(x[i]) > largest) {
                largest = std::abs(x[i]);
                pivot = i;
            }
        }
        const int diagonal = diagonal_row[k];
        if (pivot >= 0 && mark[diagonal] == k && pinv[diagonal] < 0 &&
            std::abs(x[diagonal]) >= kDiagonalPreference * largest)
            pivot = diagonal;
        bool usable = pivot >= 0 && largest > 0.0 && std::isfinite(largest);
        if (forced_rows) {  // the structure only: any nonzero divisor will do
            pivot = forced_rows[k];
            usable = pivot >= 0 && pivot < N && mark[pivot] == k && pinv[pivot] < 0;
        }
        if (!usable) {
            for (int t = top; t < N; ++t)
                x[reach[t]] = 0.0;
            return Outcome::Singular;  // no usable pivot
        }
        const double d = x[pivot] != 0.0 || !forced_rows ? x[pivot] : 1.0;
        pinv[pivot] = k;
        Ud_[k] = d;
        for (int t = top; t < N; ++t) {
            const int i = reach[t];
            if (pinv[i] >= 0 && i != pivot) {  // an earlier pivot row: an entry of U
                Ui_.push_back(pinv[i]);
                Ux_.push_back(x[i]);
            } else if (pinv[i] < 0) {  // not yet a pivot row: an entry of L
                Li_.push_back(i);
                Lx_.push_back(x[i] / d);
            }
            x[i] = 0.0;
        }
        Lp_[k + 1] = static_cast<int>(Li_.size());
        Up_[k + 1] = static_cast<int>(Ui_.size());
        if (fill_budget > 0.0 &&
            static_cast<double>(std::max(Li_.size(), Ui_.size())) > fill_budget)
            return Outcome::OverBudget;  // the work column is all zero again here
    }

    // Rows in pivot order: P_[k] is the pivot row of column k, L renumbered accordingly;
    // each column of U sorted by row (an order the refactorization's updates can follow).
    P_.resize(N);
    for (int i = 0; i < N; ++i)
        P_[pinv[i]] = i;
    for (int &i : Li_)
        i = pinv[i];
    for (int j = 0; j < N; ++j) {  // insertion sort: the columns are short
        for (int p = Up_[j] + 1; p < Up_[j + 1]; ++p) {
            const int i = Ui_[p];
            const double u = Ux_[p];
            int q = p;
            for (; q > Up_[j] && Ui_[q - 1] > i; --q) {
                Ui_[q] = Ui_[q - 1];
                Ux_[q] = Ux_[q - 1];
            }
            Ui_[q] = i;
            Ux_[q] = u;
        }
    }
    a_row_.resize(colptr[N]);
    for (int p = 0; p < colptr[N]; ++p)
        a_row_[p] = pinv[rowind[p]];
    scale_.resize(N);
    for (int i = 0; i < N; ++i)
        scale_[i] = row_scale[P_[i]];
    pivot_ratio_ = ratio_of(Ud_.data(), N);
    ready_ = true;
    return Outcome::Factorized;
}

// Column j of P D A Q = L U, left-looking: scatter column Q_[j] of D A into the dense work
// column, apply the columns k of L with u_kj != 0 in ascending k (each x_k is final once every
// column before it is applied), then split the column into U(:, j), u_jj and L(:, j). Every
// work entry touched lies in the pattern of L(:, j) and U(:, j) and is zeroed on the way out.
double FixedPivotLU::refactor(const double *values)
{
    double *x = work_.data();
    const double *D = scale_.data();
    const int *Lp = Lp_.data(), *Li = Li_.data(), *Up = Up_.data(), *Ui = Ui_.data();
    double *Lx = Lx_.data(), *Ux = Ux_.data(), *Ud = Ud_.data();
    double lo = HUGE_VAL, hi = 0.0, overflow = 0.0;  // the pivot ratio on the way (ratio_of)
    for (int j = 0; j < N_; ++j) {
        const int col = Q_[j];
        for (int p = colptr_[col]; p < colptr_[col + 1]; ++p) {
            const int i = a_row_[p];
            x[i] = D[i] * values[p];
        }
        for (int p = Up[j]; p < Up[j + 1]; ++p) {
            const int k = Ui[p];
            const double u = x[k];
            x[k] = 0.0;
            Ux[p] = u;
            for (int q = Lp[k]; q < Lp[k + 1]; ++q)
                x[Li[q]] -= Lx[q] * u;
        }
        const double d = x[j];
        x[j] = 0.0;
        Ud[j] = d;
        const double size = std::abs(d);
        lo = size < lo ? size : lo;
        hi = size > hi ? size : hi;
        overflow += 0.0 * d;
        for (int q = Lp[j]; q < Lp[j + 1]; ++q) {
            Lx[q] = x[Li[q]] / d;
            x[Li[q]] = 0.0;
        }
    }
    pivot_ratio_ = overflow == 0.0 && hi > 0.0 ? lo / hi : 0.0;
    return pivot_ratio_;
}

// A x = b as P D A Q = L U: w = P D b, L y = w, U z = y, x = Q z (column-oriented sweeps).
void FixedPivotLU::solve(double *rhs)
{
    double *w = work_.data();
    for (int i = 0; i < N_; ++i)
        w[i] = scale_[i] * rhs[P_[i]];
    sweeps(w);
    for (int k = 0; k < N_; ++k) {
        rhs[Q_[k]] = w[k];
        w[k] = 0.0;  // the work column stays zero between calls (refactor relies on it)
    }
}

// A = (S P)^{-1} L U Q^{-1} (S the row scaling, P and Q the permutations of solve()), so
// A^{-T} = P^T S L^{-T} U^{-T} Q^T: U^T and L^T are triangular, read by the columns of U and L.
void FixedPivotLU::solve_transpose(double *rhs)
{
    double *w = work_.data();
    const int *Lp = Lp_.data(), *Li = Li_.data(), *Up = Up_.data(), *Ui = Ui_.data();
    const double *Lx = Lx_.data(), *Ux = Ux_.data();
    for (int k = 0; k < N_; ++k)
        w[k] = rhs[Q_[k]];
    for (int k = 0; k < N_; ++k) {  // U^T z = w, forward
        double z = w[k];
        for (int p = Up[k]; p < Up[k + 1]; ++p)
            z -= Ux[p] * w[Ui[p]];
        w[k] = z / Ud_[k];
    }
    for (int k = N_ - 1; k >= 0; --k) {  // L^T y = z, backward (unit diagonal)
        double y = w[k];
        for (int q = Lp[k]; q < Lp[k + 1]; ++q)
            y -= Lx[q] * w[Li[q]];
        w[k] = y;
    }
    for (int i = 0; i < N_; ++i) {
        rhs[P_[i]] = scale_[i] * w[i];
        w[i] = 0.0;  // the work column stays zero between calls
    }
}

// As solve(), walking b and x in their own order: row r of b goes to row pinv_[r] of w,
// column c of x comes from row qinv_[c] of z (clearing it, as solve() does).
void FixedPivotLU::solve_blocks(const double *b1, double c1, const double *b2, double c2,
                                int n1, double *x1, double *x2, double div2)
{
    double *w = work_.data();
    const int *pinv = pinv_.data(), *qinv = qinv_.data();
    const double *D = scale_.data();
    for (int r = 0; r < n1; ++r) {
        const int i = pinv[r];
        w[i] = D[i] * (c1 * b1[r]);
    }
    for (int r = n1; r < N_; ++r) {
        const int i = pinv[r];
        w[i] = D[i] * (c2 * b2[r - n1]);
    }
    sweeps(w);
    for (int c = 0; c < n1; ++c) {
        const int k = qinv[c];
        x1[c] = w[k];
        w[k] = 0.0;
    }
    for (int c = n1; c < N_; ++c) {
        const int k = qinv[c];
        x2[c - n1] = w[k] / div2;
        w[k] = 0.0;
    }
}

void FixedPivotLU::sweeps(double *w) const
{
    const int *Lp = Lp_.data(), *Li = Li_.data(), *Up = Up_.data(), *Ui = Ui_.data();
    const double *Lx = Lx_.data(), *Ux = Ux_.data();
    for (int k = 0; k < N_; ++k) {
        const double y = w[k];
        for (int q = Lp[k]; q < Lp[k + 1]; ++q)
            w[Li[q]] -= Lx[q] * y;
    }
    for (int k = N_ - 1; k >= 0; --k) {
        const double z = w[k] / Ud_[k];
        w[k] = z;
        for (int p = Up[k]; p < Up[k + 1]; ++p)
            w[Ui[p]] -= Ux[p] * z;
    }
}

}  // namespace ga
