// galpha's unblocked dense LU (src/linear/unblocked_lu.hpp), tested directly on the shapes it
// meets: full matrices, bands, saddle-point matrices with their zero block and zero diagonal
// entries that force row exchanges, and mostly-zero random patterns, 1 to 70 unknowns. The
// oracle is Eigen's LU of the same matrix, an independent implementation: the solutions agree
// to a multiple of the condition number times the rounding unit.
#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "linear/unblocked_lu.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

enum class Shape { Full, Band, Saddle, Sparse };

Eigen::MatrixXd make(Shape shape, int N, std::mt19937 &rng)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(N, N);
    switch (shape) {
    case Shape::Full:
        for (int j = 0; j < N; ++j)
            for (int i = 0; i < N; ++i)
                A(i, j) = u(rng);
        break;
    case Shape::Band:  // half-bandwidth 2, diagonal not dominant: pivoting inside the band
        for (int j = 0; j < N; ++j)
            for (int i = std::max(0, j - 2); i <= std::min(N - 1, j + 2); ++i)
                A(i, j) = u(rng);
        break;
    case Shape::Saddle: {  // [D J^T; J 0] with D diagonal, some entries of D zero
        const int m = N / 3, n = N - m;
        for (int i = 0; i < n; ++i)
            A(i, i) = (i % 4 == 1) ? 0.0 : 1.0 + u(rng) * u(rng);
        for (int r = 0; r < m; ++r)
            for (int c = 0; c < n; ++c)
                if ((c + r) % 3 == 0 || c == r + 1) {
                    A(n + r, c) = u(rng);
                    A(c, n + r) = A(n + r, c);
                }
        break;
    }
    case Shape::Sparse:
        for (int j = 0; j < N; ++j) {
            A(j, j) = 0.1 * u(rng);  // small diagonal: the pivots come from elsewhere
            for (int i = 0; i < N; ++i)
                if (rng() % 10 == 0)
                    A(i, j) = u(rng);
        }
        break;
    }
    return A;
}

void solutions_agree_with_eigen(void **)
{
    std::mt19937 rng(12345);
    const Shape shapes[] = {Shape::Full, Shape::Band, Shape::Saddle, Shape::Sparse};
    const char *names[] = {"full", "band", "saddle", "sparse"};
    int tested = 0;
    for (int s = 0; s < 4; ++s) {
        double worst = 0.0;
        for (int N = 1; N <= 70; N += (N < 10 ? 1 : 7)) {
            const Eigen::MatrixXd A = make(shapes[s], N, rng);
            Eigen::FullPivLU<Eigen::MatrixXd> check(A);
            if (!check.isInvertible())
                continue;  // a random draw without full rank: nothing to compare
            const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(N, 1.0, 2.0);
            const Eigen::VectorXd x_ref = A.partialPivLu().solve(b);
            Eigen::MatrixXd LU = A;
            std::vector<int> ipiv(N), extent(2 * N);
            std::vector<double> inverse_diagonal(N);
            assert_true(ga::unblocked_lu(N, LU.data(), ipiv.data(), extent.data(),
                                         inverse_diagonal.data()));
            Eigen::VectorXd x = b;
            ga::unblocked_lu_solve(N, LU.data(), ipiv.data(), extent.data(),
                                   inverse_diagonal.data(), x.data());
            // condition number (1-norm, exact from the inverse) times the rounding unit
            const double cond = A.cwiseAbs().colwise().sum().maxCoeff() *
                                A.inverse().cwiseAbs().colwise().sum().maxCoeff();
            const double err = (x - x_ref).lpNorm<Eigen::Infinity>() /
                               x_ref.lpNorm<Eigen::Infinity>();
            const double scaled = err / (cond * std::numeric_limits<double>::epsilon());
            worst = std::max(worst, scaled);
            assert_true(scaled < 100.0 * N);
            // the factors reproduce P A = L U
            Eigen::MatrixXd L = Eigen::MatrixXd::Identity(N, N), U = Eigen::MatrixXd::Zero(N, N);
            for (int j = 0; j < N; ++j)
                for (int i = 0; i < N; ++i)
                    (i > j ? L(i, j) : U(i, j)) = LU(i, j);
            Eigen::MatrixXd PA = A;
            for (int k = 0; k < N; ++k)
                PA.row(k).swap(PA.row(ipiv[k]));
            const double residual = (PA - L * U).lpNorm<Eigen::Infinity>() /
                                    A.lpNorm<Eigen::Infinity>();
            assert_true(residual < 100.0 * N * std::numeric_limits<double>::epsilon());
            ++tested;
        }
        std::printf("  %-6s: largest error / (condition number x eps) %.2f\n", names[s], worst);
    }
    assert_true(tested > 60);
}

void zero_column_is_singular(void **)
{
    Eigen::MatrixXd A = Eigen::MatrixXd::Identity(4, 4);
    A.col(2).setZero();
    std::vector<int> ipiv(4), extent(8);
    std::vector<double> inverse_diagonal(4);
    assert_false(ga::unblocked_lu(4, A.data(), ipiv.data(), extent.data(),
                                  inverse_diagonal.data()));
}

void preference_follows_size_and_fill(void **)
{
    Eigen::MatrixXd small = Eigen::MatrixXd::Ones(40, 40);
    assert_true(ga::unblocked_lu_preferred(40, small.data()));  // small: always
    Eigen::MatrixXd full = Eigen::MatrixXd::Ones(41, 41);
    assert_false(ga::unblocked_lu_preferred(41, full.data()));  // full: Eigen's
    Eigen::MatrixXd band = Eigen::MatrixXd::Zero(100, 100);
    for (int i = 0; i < 100; ++i)
        for (int j = std::max(0, i - 2); j <= std::min(99, i + 2); ++j)
            band(i, j) = 1.0;  // 5 % nonzero
    assert_true(ga::unblocked_lu_preferred(100, band.data()));
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(solutions_agree_with_eigen),
        cmocka_unit_test(zero_column_is_singular),
        cmocka_unit_test(preference_follows_size_and_fill),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
