// The sparse path's pieces on a group space, tested directly: TangentProduct (A T(xi) in the
// expanded pattern) against the dense product of the same matrix, multiplied column by column
// here with T(xi) from the exported ga_so3_tangent (an independent route); and the column
// groups of finite differences, which never hold two columns of one rotation.
#include <Eigen/Dense>
#include <random>
#include <vector>

#include "configuration_space.hpp"
#include "galpha.h"
#include "model.hpp"
#include "tangent_product.hpp"

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

using ga::ConfigurationSpace;

// R^2 x SO(3) x R^1 x SO(3) (quaternions): nv = 9
ConfigurationSpace space()
{
    using K = ConfigurationSpace::Kind;
    return ConfigurationSpace({{K::Vector, 2}, {K::Quaternion, 3}, {K::Vector, 1},
                               {K::Quaternion, 3}});
}

// A T with T applied by hand: columns 2..4 and 6..8 are the rotations
Eigen::MatrixXd dense_product(const Eigen::MatrixXd &A, const Eigen::VectorXd &xi)
{
    Eigen::MatrixXd out = A;
    for (int c0 : {2, 6}) {
        double T[9];
        assert_int_equal(ga_so3_tangent(1, xi.data() + c0, T), GA_OK);
        const Eigen::Map<const Eigen::Matrix3d> Tm(T);  // column-major
        out.middleCols(c0, 3) = A.middleCols(c0, 3) * Tm;
    }
    return out;
}

Eigen::MatrixXd as_dense(const ga::ModelMatrix &A)
{
    Eigen::MatrixXd D = Eigen::MatrixXd::Zero(A.rows(), A.cols());
    for (int k = 0; k < A.nnz(); ++k)
        D(A.row_index()[k], A.col_index()[k]) += A.data()[k];
    return D;
}

// A 5 x 9 pattern that touches one or two columns of each rotation in some rows, with a
// duplicate entry (duplicates add up)
void sparse_matrix(ga::ModelMatrix &A, std::mt19937 &rng)
{
    const std::vector<int> rows = {0, 0, 1, 1, 2, 2, 3, 4, 4, 4, 1};
    const std::vector<int> cols = {0, 3, 2, 7, 4, 8, 5, 1, 6, 3, 2};
    A.set_pattern(5, 9, rows.data(), cols.data(), static_cast<int>(rows.size()));
    A.allocate();
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < A.nnz(); ++k)
        A.data()[k] = u(rng);
}

void test_sparse_product_is_the_dense_one(void **)
{
    const ConfigurationSpace S = space();
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    ga::ModelMatrix A;
    sparse_matrix(A, rng);
    ga::TangentProduct P;
    P.setup(A, S);
    // whole rotation blocks: every row that touches a rotation has all three of its columns
    const Eigen::MatrixXd D = as_dense(A);
    for (int i = 0; i < 5; ++i)
        for (int c0 : {2, 6}) {
            const bool touched = D.row(i).segment(c0, 3).cwiseAbs().sum() > 0.0;
            int present = 0;
            for (int k = 0; k < P.out().nnz(); ++k)
                present += P.out().row_index()[k] == i && P.out().col_index()[k] >= c0 &&
                           P.out().col_index()[k] < c0 + 3;
            assert_int_equal(present, touched ? 3 : 0);
        }
    for (int trial = 0; trial < 20; ++trial) {
        ga::Vec xi(9);
        for (int i = 0; i < 9; ++i)
            xi[i] = u(rng);
        P.apply(A, &xi, S);
        const double diff = (as_dense(P.out()) - dense_product(D, xi)).cwiseAbs().maxCoeff();
        assert_true(diff < 1e-14);
        P.apply(A, nullptr, S);  // T = I: A itself
        assert_true((as_dense(P.out()) - D).cwiseAbs().maxCoeff() == 0.0);
    }
}

void test_dense_product_is_the_dense_one(void **)
{
    const ConfigurationSpace S = space();
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.5, 1.5);
    ga::ModelMatrix A;
    A.set_dense(4, 9);
    A.allocate();
    for (int k = 0; k < A.size(); ++k)
        A.data()[k] = u(rng);
    ga::TangentProduct P;
    P.setup(A, S);
    ga::Vec xi(9);
    for (int i = 0; i < 9; ++i)
        xi[i] = u(rng);
    P.apply(A, &xi, S);
    const Eigen::MatrixXd D = A.as_dense();
    assert_true((P.out().as_dense() - dense_product(D, xi)).cwiseAbs().maxCoeff() < 1e-14);
}

// Columns 2 and 4 of a rotation share no row: without the space they are one group; with it
// they are not (a shift in one would replace the other's), while vector columns still share.
void test_column_groups_keep_a_rotation_apart(void **)
{
    const ConfigurationSpace S = space();
    const std::vector<int> rows = {0, 1, 2, 3};
    const std::vector<int> cols = {2, 4, 0, 1};
    ga::ModelMatrix A;
    A.set_pattern(9, 9, rows.data(), cols.data(), 4);
    ga::ColumnGroups plain, grouped;
    plain.build(A);
    grouped.build(A, &S);
    assert_int_equal(plain.count(), 1);  // all four columns are structurally orthogonal
    assert_int_equal(grouped.count(), 2);
    for (int g = 0; g < grouped.count(); ++g) {
        int in_rotation = 0;
        for (int p = grouped.start[g]; p < grouped.start[g + 1]; ++p)
            in_rotation += grouped.cols[p] >= 2 && grouped.cols[p] < 5;
        assert_true(in_rotation <= 1);
    }
}

}  // namespace

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sparse_product_is_the_dense_one),
        cmocka_unit_test(test_dense_product_is_the_dense_one),
        cmocka_unit_test(test_column_groups_keep_a_rotation_apart),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
