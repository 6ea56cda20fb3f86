// The sparse system behind the sparse path (src/linear/klu_system.hpp), tested directly: galpha
// scales the rows itself and keeps the scale factors through KLU's refactorizations, and falls
// back to a fresh factorization (new pivots, new scale factors) when the old pivots no longer
// fit. The oracle is Eigen's dense LU of the same matrix, an independent implementation.
#include <Eigen/Dense>
#include <cstdio>
#include <utility>
#include <vector>

#include "linear/klu_system.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

// A full 3 x 3 pattern; rows of very different size (1e8, 1, 1e-8), so that pivoting without
// the row scaling would choose differently.
const double kRowSize[3] = {1e8, 1.0, 1e-8};

std::vector<std::pair<int, int>> pattern()
{
    std::vector<std::pair<int, int>> p;
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            p.emplace_back(i, j);
    return p;
}

// B scaled by the row sizes, written into the system's slots; the dense matrix back
Eigen::Matrix3d assemble(ga::KluSystem &S, const Eigen::Matrix3d &B)
{
    Eigen::Matrix3d A = B;
    for (int i = 0; i < 3; ++i)
        A.row(i) *= kRowSize[i];
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            S.values()[S.slot(i, j)] = A(i, j);
    return A;
}

double solve_error(ga::KluSystem &S, const Eigen::Matrix3d &A)
{
    const Eigen::Vector3d b(1.0, -2.0, 3.0);
    const Eigen::Vector3d x_ref = A.partialPivLu().solve(b);
    Eigen::Vector3d x = b;
    S.solve(x.data());
    return (x - x_ref).norm() / x_ref.norm();
}

void refactorization_and_fresh_pivots_solve_correctly(void **)
{
    ga::KluSystem S;
    S.setup(3, pattern());
    const double e = 1e-3;
    Eigen::Matrix3d diagonal, swapped, near;
    diagonal << 1, e, e, e, 1, e, e, e, 1;  // scaled: pivots on the diagonal
    near << 1.1, e, e, e, 0.9, e, e, 2 * e, 1;
    swapped << 0, 1, e, 1, 0, e, e, e, 1;   // the first pivot vanishes
    // factorize B (rows scaled), check how many full factorizations there were, solve
    auto factorize_and_solve = [&S](const Eigen::Matrix3d &B, int full_factorizations) {
        const Eigen::Matrix3d A = assemble(S, B);
        assert_true(S.factorize());
        assert_int_equal(S.full_factorizations(), full_factorizations);
        return solve_error(S, A);
    };
    const double e1 = factorize_and_solve(diagonal, 1);
    // similar values: refactorized with the same pivots and scale factors
    const double e2 = factorize_and_solve(near, 1);
    // the old first pivot is zero now: factorized afresh, new pivots and scale factors
    const double e3 = factorize_and_solve(swapped, 2);
    // back to the first values, refactorized with the pivots of the swapped ones
    const double e4 = factorize_and_solve(diagonal, 2);
    std::printf("  relative error against Eigen's dense LU: %.1e (first), %.1e (refactorized), "
                "%.1e (new pivots), %.1e (refactorized on them)\n",
                e1, e2, e3, e4);
    for (double err : {e1, e2, e3, e4})
        assert_true(err < 1e-13);
}

void singular_matrix_is_reported(void **)
{
    ga::KluSystem S;
    S.setup(3, pattern());
    Eigen::Matrix3d B;
    B << 1, 2, 3, 2, 4, 6, 0, 1, 1;  // rows 0 and 1 are parallel
    assemble(S, B);
    assert_false(S.factorize());
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(refactorization_and_fresh_pivots_solve_correctly),
        cmocka_unit_test(singular_matrix_is_reported),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
