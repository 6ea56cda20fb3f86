#include "unblocked_lu.hpp"

#include <cmath>
#include <cstddef>
#include <utility>

namespace ga {

namespace {
// y[i] -= a x[i] over [begin, end): distinct columns, so the compiler may assume no overlap
inline void subtract_scaled(double *__restrict y, const double *__restrict x, double a,
                            int begin, int end)
{
    for (int i = begin; i < end; ++i)
        y[i] -= x[i] * a;
}

inline double *column(double *A, int N, int j) { return A + static_cast<std::ptrdiff_t>(j) * N; }
inline const double *column(const double *A, int N, int j)
{
    return A + static_cast<std::ptrdiff_t>(j) * N;
}

// The unblocked kernel up to this many unknowns whatever the fill, and beyond while at most
// this fraction of the matrix is nonzero. bench/linear_algebra: on matrices without zeros
// Eigen's blocked LU is ahead from about 40 unknowns on; on mechanisms' matrices (Andrews in 31
// coordinates: 4.5 % nonzero; the chain: 7 % at 8 links, less beyond) the unblocked kernel is
// ahead at every size measured. In between the fill of the factors decides, which the matrix
// does not show: random patterns with 15 % nonzero fill in and favour Eigen's from about 100
// unknowns on.
constexpr int kUnblockedAlways = 40;
constexpr double kUnblockedMaxFill = 0.1;
}  // namespace

bool unblocked_lu_preferred(int N, const double *A)
{
    if (N <= kUnblockedAlways)
        return true;
    const std::ptrdiff_t entries = static_cast<std::ptrdiff_t>(N) * N;
    std::ptrdiff_t nonzero = 0;
    for (std::ptrdiff_t k = 0; k < entries; ++k)
        nonzero += A[k] != 0.0;
    return static_cast<double>(nonzero) <= kUnblockedMaxFill * static_cast<double>(entries);
}

bool unblocked_lu(int N, double *A, int *ipiv, int *extent, double *inverse_diagonal)
{
    int *l_end = extent, *u_begin = extent + N;
    for (int k = 0; k < N; ++k) {
        double *ck = column(A, N, k);
        int p = k;
        double largest = std::abs(ck[k]);
        for (int i = k + 1; i < N; ++i)
            if (std::abs(ck[i]) > largest) {
                largest = std::abs(ck[i]);
                p = i;
            }
        ipiv[k] = p;
        if (largest == 0.0)
            return false;
        if (p != k)  // whole rows, as dgetrf: the factors' rows stay in pivot order
            for (int j = 0; j < N; ++j)
                std::swap(column(A, N, j)[k], column(A, N, j)[p]);
        // the multipliers end at the last nonzero of the column (a band ends early)
        int end = N;
        while (end > k + 1 && ck[end - 1] == 0.0)
            --end;
        const double inverse = 1.0 / ck[k];
        inverse_diagonal[k] = inverse;  // the solves multiply: a division stalls their chain
        for (int i = k + 1; i < end; ++i)
            ck[i] *= inverse;
        // rank-one update of the trailing matrix, column by column; a zero entry of row k
        // leaves its column untouched (most of them in a saddle-point matrix)
        for (int j = k + 1; j < N; ++j) {
            double *cj = column(A, N, j);
            const double u = cj[k];
            if (u != 0.0)
                subtract_scaled(cj, ck, u, k + 1, end);
        }
    }
    // The extent of the final factors, for the solves (later row exchanges move the
    // multipliers of earlier columns: their ends are known only now).
    for (int k = 0; k < N; ++k) {
        const double *ck = column(A, N, k);
        int begin = 0, end = N;
        while (begin < k && ck[begin] == 0.0)
            ++begin;
        while (end > k + 1 && ck[end - 1] == 0.0)
            --end;
        u_begin[k] = begin;
        l_end[k] = end;
    }
    return true;
}

void unblocked_lu_solve(int N, const double *LU, const int *ipiv, const int *extent,
                        const double *inverse_diagonal, double *b)
{
    const int *l_end = extent, *u_begin = extent + N;
    for (int k = 0; k < N; ++k)
        if (ipiv[k] != k)
            std::swap(b[k], b[ipiv[k]]);
    for (int k = 0; k < N; ++k) {  // L y = P b, unit diagonal
        const double y = b[k];
        if (y != 0.0)
            subtract_scaled(b, column(LU, N, k), y, k + 1, l_end[k]);
    }
    for (int k = N - 1; k >= 0; --k) {  // U x = y
        const double *ck = column(LU, N, k);
        b[k] *= inverse_diagonal[k];
        const double x = b[k];
        if (x != 0.0)
            subtract_scaled(b, ck, x, u_begin[k], k);
    }
}

}  // namespace ga
