#include "fixed_pivot_lu.hpp"

#ifdef GALPHA_HAVE_KLU
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace ga {

namespace {
// min |d_i| / max |d_i|; 0 if an entry is not finite or all are zero
double ratio_of(const double *d, int N)
{
    double lo = HUGE_VAL, hi = 0.0, finite = 0.0;
    for (int i = 0; i < N; ++i) {
        const double a = std::abs(d[i]);
        lo = a < lo ? a : lo;
        hi = a > hi ? a : hi;
        finite += 0.0 * d[i];  // stays 0 unless some d_i is Inf or NaN
    }
    return finite == 0.0 && hi > 0.0 ? lo / hi : 0.0;
}
}  // namespace

void FixedPivotLU::build(int N, const int *colptr, const int *rowind, const double *row_scale,
                         klu_symbolic *symbolic, klu_numeric *&numeric, klu_common *common)
{
    ready_ = false;
    N_ = N;
    colptr_ = colptr;
    // KLU's factors straight into the members (no second copy of them at any time)
    const int lnz = numeric->lnz, unz = numeric->unz;
    Lp_.resize(N + 1);
    Li_.resize(lnz);
    Lx_.resize(lnz);
    Up_.resize(N + 1);
    Ui_.resize(unz);
    Ux_.resize(unz);
    P_.resize(N);
    Q_.resize(N);
    if (!klu_extract(numeric, symbolic, Lp_.data(), Li_.data(), Lx_.data(), Up_.data(),
                     Ui_.data(), Ux_.data(), nullptr, nullptr, nullptr, P_.data(), Q_.data(),
                     nullptr, nullptr, common))
        throw std::logic_error("klu_extract failed");
    klu_free_numeric(&numeric, common);  // before anything else is allocated: a lower peak

    // L without its unit diagonal, compacted in place
    int out = 0;
    for (int k = 0, p = 0; k < N; ++k) {
        const int end = Lp_[k + 1];
        Lp_[k] = out;
        for (; p < end; ++p)
            if (Li_[p] != k) {
                Li_[out] = Li_[p];
                Lx_[out++] = Lx_[p];
            }
    }
    Lp_[N] = out;
    Li_.resize(out);
    Lx_.resize(out);
    // U: the diagonal apart, the rest of each column in place and sorted by row (insertion
    // sort: columns are short, and nearly sorted)
    Ud_.assign(N, 0.0);
    out = 0;
    for (int j = 0, p = 0; j < N; ++j) {
        const int end = Up_[j + 1];
        Up_[j] = out;
        for (; p < end; ++p) {
            if (Ui_[p] == j) {
                Ud_[j] = Ux_[p];
                continue;
            }
            const int i = Ui_[p];
            const double u = Ux_[p];
            int q = out++;
            for (; q > Up_[j] && Ui_[q - 1] > i; --q) {
                Ui_[q] = Ui_[q - 1];
                Ux_[q] = Ux_[q - 1];
            }
            Ui_[q] = i;
            Ux_[q] = u;
        }
    }
    Up_[N] = out;
    Ui_.resize(out);
    Ux_.resize(out);

    std::vector<int> pinv(N);
    scale_.resize(N);
    for (int i = 0; i < N; ++i) {
        pinv[P_[i]] = i;
        scale_[i] = row_scale[P_[i]];
    }
    a_row_.resize(colptr[N]);
    for (int p = 0; p < colptr[N]; ++p)
        a_row_[p] = pinv[rowind[p]];
    work_.assign(N, 0.0);
    pivot_ratio_ = ratio_of(Ud_.data(), N);
    ready_ = true;
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
        for (int q = Lp[j]; q < Lp[j + 1]; ++q) {
            Lx[q] = x[Li[q]] / d;
            x[Li[q]] = 0.0;
        }
    }
    pivot_ratio_ = ratio_of(Ud, N_);
    return pivot_ratio_;
}

// A x = b as P D A Q = L U: w = P D b, L y = w, U z = y, x = Q z (column-oriented sweeps).
void FixedPivotLU::solve(double *rhs)
{
    double *w = work_.data();
    const int *Lp = Lp_.data(), *Li = Li_.data(), *Up = Up_.data(), *Ui = Ui_.data();
    const double *Lx = Lx_.data(), *Ux = Ux_.data();
    for (int i = 0; i < N_; ++i)
        w[i] = scale_[i] * rhs[P_[i]];
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
    for (int k = 0; k < N_; ++k) {
        rhs[Q_[k]] = w[k];
        w[k] = 0.0;  // the work column stays zero between calls (refactor relies on it)
    }
}

}  // namespace ga
#endif
