#include "condition.hpp"

#include <cmath>
#include <cstddef>

namespace ga {

namespace {

// The factors as B = U^-1 L^-1 (the inverse of A up to its row exchanges), applied in place.
class InverseOfFactors {
public:
    InverseOfFactors(int N, const double *lu) : N_(N), lu_(lu) {}

    double at(int i, int j) const { return lu_[static_cast<std::ptrdiff_t>(j) * N_ + i]; }

    void apply(double *x) const  // x <- U^-1 L^-1 x
    {
        for (int j = 0; j < N_; ++j)
            if (x[j] != 0.0)
                for (int i = j + 1; i < N_; ++i)
                    x[i] -= at(i, j) * x[j];
        for (int j = N_ - 1; j >= 0; --j) {
            x[j] /= at(j, j);
            for (int i = 0; i < j; ++i)
                x[i] -= at(i, j) * x[j];
        }
    }

    void apply_transpose(double *x) const  // x <- L^-T U^-T x
    {
        for (int j = 0; j < N_; ++j) {
            double s = x[j];
            for (int i = 0; i < j; ++i)
                s -= at(i, j) * x[i];
            x[j] = s / at(j, j);
        }
        for (int j = N_ - 1; j >= 0; --j) {
            double s = x[j];
            for (int i = j + 1; i < N_; ++i)
                s -= at(i, j) * x[i];
            x[j] = s;
        }
    }

private:
    int N_;
    const double *lu_;
};

double sum_abs(int N, const double *x)
{
    double s = 0.0;
    for (int i = 0; i < N; ++i)
        s += std::fabs(x[i]);
    return s;
}

int index_of_max_abs(int N, const double *x)
{
    int j = 0;
    for (int i = 1; i < N; ++i)
        if (std::fabs(x[i]) > std::fabs(x[j]))
            j = i;
    return j;
}

// Hager's estimate of |B|_1 with Higham's safeguards (Higham, ACM TOMS 14, 1988, Alg. 4.1):
// at most five power-method-like sweeps over the sign vectors, then the alternating-sign
// vector as a second opinion. Returns infinity when a solve overflows.
double inverse_norm1(const InverseOfFactors &B, int N, double *x, double *sign)
{
    constexpr int kMaxSweeps = 5;
    for (int i = 0; i < N; ++i)
        x[i] = 1.0 / N;
    B.apply(x);
    double est = sum_abs(N, x);
    if (N == 1 || !std::isfinite(est))
        return est;
    for (int i = 0; i < N; ++i)
        sign[i] = std::copysign(1.0, x[i]);
    for (int i = 0; i < N; ++i)
        x[i] = sign[i];
    B.apply_transpose(x);
    int j = index_of_max_abs(N, x);
    for (int sweep = 2;; ++sweep) {
        for (int i = 0; i < N; ++i)
            x[i] = i == j ? 1.0 : 0.0;
        B.apply(x);
        const double previous = est;
        est = sum_abs(N, x);
        if (!std::isfinite(est))
            return est;
        bool same_signs = true;
        for (int i = 0; i < N && same_signs; ++i)
            same_signs = std::copysign(1.0, x[i]) == sign[i];
        if (same_signs || est <= previous)
            break;
        for (int i = 0; i < N; ++i)
            sign[i] = std::copysign(1.0, x[i]);
        for (int i = 0; i < N; ++i)
            x[i] = sign[i];
        B.apply_transpose(x);
        const int last = j;
        j = index_of_max_abs(N, x);
        if (x[last] == std::fabs(x[j]) || sweep >= kMaxSweeps)
            break;
    }
    // x_i = (-1)^i (1 + i / (N - 1)) catches the matrices on which the sweeps stall
    for (int i = 0; i < N; ++i)
        x[i] = (i % 2 == 0 ? 1.0 : -1.0) * (1.0 + static_cast<double>(i) / (N - 1));
    B.apply(x);
    const double alternating = 2.0 * sum_abs(N, x) / (3.0 * N);
    return alternating > est ? alternating : est;
}

}  // namespace

double norm1(int N, const double *a)
{
    double norm = 0.0;
    for (int j = 0; j < N; ++j) {
        const double s = sum_abs(N, a + static_cast<std::ptrdiff_t>(j) * N);
        if (s > norm || std::isnan(s))
            norm = s;
    }
    return norm;
}

double lu_rcond(int N, const double *lu, double anorm, double *work)
{
    if (N == 0)
        return 1.0;
    if (!(anorm > 0.0))
        return 0.0;
    const double inverse = inverse_norm1(InverseOfFactors(N, lu), N, work, work + N);
    if (!std::isfinite(inverse) || !(inverse > 0.0))
        return 0.0;
    return (1.0 / inverse) / anorm;
}

}  // namespace ga
