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
    const Eigen::Matrix3d A1 = assemble(S, diagonal);
    assert_true(S.factorize());
    const double e1 = solve_error(S, A1);
    assert_int_equal(S.full_factorizations(), 1);
    // similar values: refactorized with the same pivots and scale factors
    const Eigen::Matrix3d A2 = assemble(S, near);
    assert_true(S.factorize());
    const double e2 = solve_error(S, A2);
    assert_int_equal(S.full_factorizations(), 1);
    // the old first pivot is zero now: factorized afresh, new pivots and scale factors
    const Eigen::Matrix3d A3 = assemble(S, swapped);
    assert_true(S.factorize());
    const double e3 = solve_error(S, A3);
    assert_int_equal(S.full_factorizations(), 2);
    // back to the first values, with the pivots of the swapped ones
    const Eigen::Matrix3d A4 = assemble(S, diagonal);
    assert_true(S.factorize());
    const double e4 = solve_error(S, A4);
    std::printf("  relative error against Eigen's dense LU: %.1e (first), %.1e (refactorized), "
                "%.1e (new pivots), %.1e (after them); %d full factorizations\n",
                e1, e2, e3, e4, S.full_factorizations());
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
