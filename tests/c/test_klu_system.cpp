// The sparse system behind the sparse path (src/linear/klu_system.hpp), tested directly: its
// LU (fixed_pivot_lu.hpp) chooses pivots in a full factorization, keeps them and the row scale
// factors through the refactorizations, and falls back to a fresh factorization (new pivots,
// new scale factors) when the old pivots no longer fit. The oracle is Eigen's dense LU of the
// same matrix, an independent implementation.
#include <Eigen/Dense>
#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>
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

// A saddle-point pattern like a mechanism's (n x n block with its diagonal and random
// off-diagonal entries, m x n constraint block and its transpose, zero lower-right block: the
// pivots must leave the diagonal), refactorized through a sequence of matrices with the
// pivots of the first. Some entries of the first matrix are exactly zero (structural entries
// that are numerically zero, as the tangents of a step can be); later matrices fill them in.
// Every solve is checked against Eigen's dense LU of the same matrix.
void refactorizations_follow_the_values_on_a_saddle_point_pattern(void **)
{
    const int n = 100, m = 40, N = n + m;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::uniform_int_distribution<int> column(0, n - 1);
    std::vector<std::pair<int, int>> entries;
    for (int j = 0; j < n; ++j) {
        entries.emplace_back(j, j);
        for (int k = 0; k < 2; ++k)
            entries.emplace_back(column(rng), j);
    }
    for (int i = 0; i < m; ++i)
        for (int k = 0; k < 3; ++k) {
            const int j = column(rng);
            entries.emplace_back(n + i, j);
            entries.emplace_back(j, n + i);
        }
    ga::KluSystem S;
    S.setup(N, entries);
    // one value per distinct slot, so that the dense copy and the slots agree
    std::vector<double> base(S.values().size());
    for (double &v : base)
        v = unit(rng);
    std::vector<char> starts_at_zero(base.size(), 0);
    for (std::size_t k = 0; k < base.size(); ++k)
        starts_at_zero[k] = k % 3 == 0;
    double worst = 0.0;  // largest error relative to eps cond(A)
    std::vector<double> errors;
    for (int matrix = 0; matrix < 12; ++matrix) {
        Eigen::MatrixXd A = Eigen::MatrixXd::Zero(N, N);
        for (const auto &[i, j] : entries) {
            const int k = S.slot(i, j);
            double v = base[k] * (1.0 + 0.2 * matrix * unit(rng) / 12.0);
            if (i == j)
                v = 4.0 + v;  // the n x n block diagonally dominant
            else if (i < n && j < n && matrix == 0 && starts_at_zero[k])
                v = 0.0;
            A(i, j) = v;  // duplicates in `entries` write the same slot again
        }
        for (const auto &[i, j] : entries)
            S.values()[S.slot(i, j)] = A(i, j);
        assert_true(S.factorize());
        const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
        for (int rhs = 0; rhs < 2; ++rhs) {
            Eigen::VectorXd b(N);
            for (int i = 0; i < N; ++i)
                b[i] = unit(rng);
            const Eigen::VectorXd x_ref = lu.solve(b);
            Eigen::VectorXd x = b;
            S.solve(x.data());
            errors.push_back((x - x_ref).norm() / x_ref.norm());
        }
        // the accuracy any backward-stable solve has: eps times the 2-norm condition number
        const Eigen::VectorXd sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(A).singularValues();
        const double limit = std::numeric_limits<double>::epsilon() * sigma(0) / sigma(N - 1);
        for (double e : errors)
            worst = std::max(worst, e / limit);
        errors.clear();
    }
    std::printf("  12 matrices, 1 full factorization expected, %d done; largest difference from "
                "Eigen's dense LU %.2f eps cond(A)\n",
                S.full_factorizations(), worst);
    assert_int_equal(S.full_factorizations(), 1);  // the other 11: refactorizations
    assert_true(worst < 1.0);
}

// Random unsymmetric patterns, 5 to 200 unknowns, a fifth of the diagonal structurally
// absent (so that pivots must come from elsewhere), made structurally nonsingular by a random
// permutation's entries: a full factorization, then refactorizations of perturbed values,
// each solve against Eigen's dense LU. Exercises the column reach (depth first through L) and
// the pivot choice on patterns unlike the mechanisms'. Bound: an LU solve is within about
// N eps g cond(A) of the solution, g the growth of the entries, which threshold pivoting
// (diagonal preference 0.1) keeps near 1 here: measured up to 5.6 eps cond(A), where KLU's
// threshold of 1e-3 gave 97.
void random_patterns_against_dense_lu(void **)
{
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), uniform(0.0, 1.0);
    double worst = 0.0;
    int matrices = 0, full = 0, refactorizations = 0;
    for (int trial = 0; trial < 20; ++trial) {
        const int N = 5 + static_cast<int>(195.0 * uniform(rng));
        std::uniform_int_distribution<int> index(0, N - 1);
        std::vector<int> perm(N);
        for (int i = 0; i < N; ++i)
            perm[i] = i;
        std::shuffle(perm.begin(), perm.end(), rng);
        std::vector<std::pair<int, int>> entries;
        for (int j = 0; j < N; ++j) {
            entries.emplace_back(perm[j], j);
            if (uniform(rng) < 0.8)
                entries.emplace_back(j, j);
            for (int k = 0; k < 3; ++k)
                entries.emplace_back(index(rng), j);
        }
        ga::KluSystem S;
        S.setup(N, entries);
        S.reserve_factors();
        std::vector<double> base(S.values().size());
        for (double &v : base)
            v = unit(rng);
        for (int version = 0; version < 4; ++version) {
            Eigen::MatrixXd A = Eigen::MatrixXd::Zero(N, N);
            for (const auto &[i, j] : entries) {
                const int k = S.slot(i, j);
                A(i, j) = base[k] * (1.0 + 0.1 * version * unit(rng));
                S.values()[k] = A(i, j);
            }
            if (!S.factorize())
                continue;  // numerically singular values: nothing to compare
            const Eigen::VectorXd b = Eigen::VectorXd::Random(N);
            Eigen::VectorXd x = b;
            S.solve(x.data());
            const Eigen::VectorXd sigma = Eigen::BDCSVD<Eigen::MatrixXd>(A).singularValues();
            const Eigen::VectorXd x_ref = A.partialPivLu().solve(b);
            const double limit = std::numeric_limits<double>::epsilon() * sigma(0) / sigma(N - 1);
            const double ratio = (x - x_ref).norm() / x_ref.norm() / limit;
            assert_true(ratio < N);  // growth near 1: far below N
            worst = std::max(worst, ratio);
            // the transposed solve, against Eigen's dense LU of A^T
            Eigen::VectorXd xt = b;
            S.solve_transpose(xt.data());
            const Eigen::VectorXd xt_ref = A.transpose().partialPivLu().solve(b);
            const double ratio_t = (xt - xt_ref).norm() / xt_ref.norm() / limit;
            assert_true(ratio_t < N);
            worst = std::max(worst, ratio_t);
            // b and x in two blocks: bit for bit what the copies in and out around solve() give
            const int n1 = N / 3;
            const Eigen::VectorXd b1 = b.head(n1), b2 = b.tail(N - n1);
            Eigen::VectorXd x1(n1), x2(N - n1), y(N);
            S.solve_blocks(b1.data(), -0.7, b2.data(), -1.0, n1, x1.data(), x2.data(), 2.5);
            y.head(n1) = -0.7 * b1;
            y.tail(N - n1) = -b2;
            S.solve(y.data());
            assert_true((x1.array() == y.head(n1).array()).all());
            assert_true((x2.array() == (y.tail(N - n1) / 2.5).array()).all());
            ++matrices;
        }
        full += S.full_factorizations();
        refactorizations += 4 - S.full_factorizations();
    }
    std::printf("  %d matrices of 20 random patterns (%d full factorizations, %d with kept pivots): "
                "largest difference from Eigen's dense LU (solves with A and A^T) %.2f eps "
                "cond(A)\n",
                matrices, full, refactorizations, worst);
    assert_true(matrices >= 60);
    assert_true(refactorizations >= 20);  // kept pivots did most of the work
    assert_true(worst < 10.0);  // the growth threshold pivoting at 0.1 allows, measured 5.6
}

// ---- the fill count behind the choice of ordering --------------------------------------

using Adjacency = std::vector<std::vector<int>>;

Adjacency from_edges(int N, const std::vector<std::pair<int, int>> &edges)
{
    Adjacency adj(N);
    for (auto [i, j] : edges) {
        adj[i].push_back(j);
        adj[j].push_back(i);
    }
    return adj;
}

// The 5-point stencil of an nx x ny grid, nodes numbered row by row.
std::vector<std::pair<int, int>> grid_edges(int nx, int ny)
{
    std::vector<std::pair<int, int>> e;
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
            if (x + 1 < nx)
                e.emplace_back(y * nx + x, y * nx + x + 1);
            if (y + 1 < ny)
                e.emplace_back(y * nx + x, (y + 1) * nx + x);
        }
    return e;
}

// The independent count: symbolic Gaussian elimination on a dense boolean matrix, in the
// given order (eliminating a node joins all its later neighbours), O(N^3); entries and the
// sum of the squared column counts of L.
ga::CholeskyFill dense_symbolic_fill(const Adjacency &adj, const std::vector<int> &order)
{
    const int N = static_cast<int>(order.size());
    std::vector<int> position(N);
    for (int k = 0; k < N; ++k)
        position[order[k]] = k;
    std::vector<std::vector<char>> A(N, std::vector<char>(N, 0));
    for (int i = 0; i < N; ++i)
        for (int j : adj[i])
            A[position[i]][position[j]] = 1;
    ga::CholeskyFill fill;
    for (int k = 0; k < N; ++k) {
        double column = 1.0;  // the diagonal
        for (int i = k + 1; i < N; ++i)
            if (A[i][k]) {
                column += 1.0;
                for (int j = k + 1; j < N; ++j)
                    if (A[j][k])
                        A[i][j] = A[j][i] = 1;
            }
        fill.entries += column;
        fill.flops += column * column;
    }
    return fill;
}

void cholesky_fill_against_analysis(void **)
{
    const double inf = std::numeric_limits<double>::infinity();
    const int N = 50;
    std::vector<int> natural(N), reversed(N);
    for (int k = 0; k < N; ++k)
        natural[k] = k, reversed[k] = N - 1 - k;
    // a path: no fill in either direction, 2N - 1 entries, columns of 2 but the last
    std::vector<std::pair<int, int>> path;
    for (int k = 0; k + 1 < N; ++k)
        path.emplace_back(k, k + 1);
    for (const auto &order : {natural, reversed}) {
        const ga::CholeskyFill f = ga::cholesky_fill(from_edges(N, path), order, inf);
        assert_true(f.entries == 2 * N - 1 && f.flops == 4 * (N - 1) + 1);
    }
    // an arrow, node 0 joined to all: eliminated first it fills L solid, N (N + 1) / 2
    // entries, columns of N, N - 1, ..., 1; last, nothing fills (columns of 2, the hub 1)
    std::vector<std::pair<int, int>> arrow;
    for (int k = 1; k < N; ++k)
        arrow.emplace_back(0, k);
    const ga::CholeskyFill first = ga::cholesky_fill(from_edges(N, arrow), natural, inf);
    assert_true(first.entries == N * (N + 1) / 2 && first.flops == N * (N + 1) * (2 * N + 1) / 6);
    const ga::CholeskyFill last = ga::cholesky_fill(from_edges(N, arrow), reversed, inf);
    assert_true(last.entries == 2 * N - 1 && last.flops == 4 * (N - 1) + 1);
    // a 9 x 7 grid in random orders, against the dense symbolic elimination
    const Adjacency grid = from_edges(63, grid_edges(9, 7));
    std::vector<int> order(63);
    for (int k = 0; k < 63; ++k)
        order[k] = k;
    std::mt19937 random(7);
    for (int trial = 0; trial < 20; ++trial) {
        std::shuffle(order.begin(), order.end(), random);
        const ga::CholeskyFill f = ga::cholesky_fill(grid, order, inf);
        const ga::CholeskyFill ref = dense_symbolic_fill(grid, order);
        assert_true(f.entries == ref.entries && f.flops == ref.flops);
    }
    // the count stops past the limit, and says so
    const double stopped = ga::cholesky_fill(from_edges(N, arrow), natural, 100.0).entries;
    assert_true(stopped > 100.0 && stopped < first.entries);
}

// A pattern from edges, diagonal included, with diagonally dominant values: x from a solve
// against Eigen's dense LU.
double setup_and_solve(ga::KluSystem &S, int N, const std::vector<std::pair<int, int>> &edges)
{
    std::vector<std::pair<int, int>> entries;
    for (int i = 0; i < N; ++i)
        entries.emplace_back(i, i);
    for (auto [i, j] : edges) {
        entries.emplace_back(i, j);
        entries.emplace_back(j, i);
    }
    S.setup(N, entries);
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(N, N);
    for (auto [i, j] : edges) {
        S.values()[S.slot(i, j)] = A(i, j) = -1.0 - 0.001 * i;
        S.values()[S.slot(j, i)] = A(j, i) = -1.0 + 0.001 * j;
    }
    for (int i = 0; i < N; ++i)
        S.values()[S.slot(i, i)] = A(i, i) = 5.0;
    assert_true(S.factorize());
    Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(N, 1.0, 2.0), x = b;
    S.solve(x.data());
    const Eigen::VectorXd x_ref = A.partialPivLu().solve(b);
    return (x - x_ref).norm() / x_ref.norm();
}

// The band (RCM) where it fills about like AMD, AMD where the band would fill much more: a
// 30 x 30 grid, whose band is 30 wide and fills solid.
void ordering_follows_the_fill(void **)
{
    const int N = 900;
    std::vector<std::pair<int, int>> ladder;  // two rails and rungs: mechanism-like
    for (int k = 0; k + 2 < N; ++k)
        ladder.emplace_back(k, k + 2);
    for (int k = 0; k + 1 < N; k += 2)
        ladder.emplace_back(k, k + 1);
    ga::KluSystem chain_like, mesh;
    const double e1 = setup_and_solve(chain_like, N, ladder);
    const double e2 = setup_and_solve(mesh, N, grid_edges(30, 30));
    std::printf("  ladder: AMD fills %.0f (%.0f flops), RCM %.0f (%.0f) -> %s; 30 x 30 grid: "
                "AMD %.0f (%.0f), RCM over %.0f (count stopped) -> %s; errors %.1e %.1e\n",
                chain_like.amd_fill().entries, chain_like.amd_fill().flops,
                chain_like.rcm_fill().entries, chain_like.rcm_fill().flops, chain_like.ordering(),
                mesh.amd_fill().entries, mesh.amd_fill().flops, mesh.rcm_fill().entries,
                mesh.ordering(), e1, e2);
    assert_string_equal(chain_like.ordering(), "RCM");
    assert_true(chain_like.rcm_fill().entries <= 1.5 * chain_like.amd_fill().entries);
    assert_true(chain_like.rcm_fill().flops <= 1.5 * chain_like.amd_fill().flops);
    assert_string_equal(mesh.ordering(), "AMD");
    assert_true(mesh.rcm_fill().entries > 1.5 * mesh.amd_fill().entries);
    assert_true(e1 < 1e-13 && e2 < 1e-13);
}

// A system set up like another of the same pattern (the solver's output and projection
// matrices, like its step matrix) takes that one's orderings and choice instead of computing
// them: the same fill counts and ordering, and bit for bit the same solution; with another
// pattern (entries in another order and duplicated count as the same) it computes its own.
void setup_like_takes_the_analysis_of_the_same_pattern(void **)
{
    const int N = 900;
    for (const auto &edges : {grid_edges(30, 30), std::vector<std::pair<int, int>>{}}) {  // AMD, RCM
        std::vector<std::pair<int, int>> links = edges;
        if (links.empty()) {
            for (int k = 0; k + 2 < N; ++k)
                links.emplace_back(k, k + 2);
            for (int k = 0; k + 1 < N; k += 2)
                links.emplace_back(k, k + 1);
        }
        std::vector<std::pair<int, int>> entries, shuffled;
        for (int i = 0; i < N; ++i)
            entries.emplace_back(i, i);
        for (auto [i, j] : links) {
            entries.emplace_back(i, j);
            entries.emplace_back(j, i);
        }
        shuffled = entries;
        shuffled.insert(shuffled.end(), entries.begin(), entries.begin() + 50);
        std::reverse(shuffled.begin(), shuffled.end());
        ga::KluSystem first, second;
        first.setup(N, entries);
        second.setup(N, shuffled, ga::KluSystem::Ordering::Auto, &first);
        assert_string_equal(first.ordering(), second.ordering());
        assert_true(first.amd_fill().entries == second.amd_fill().entries);
        assert_true(first.rcm_fill().entries == second.rcm_fill().entries);
        for (ga::KluSystem *S : {&first, &second}) {
            for (auto [i, j] : links) {
                S->values()[S->slot(i, j)] = -1.0 - 0.001 * i;
                S->values()[S->slot(j, i)] = -1.0 + 0.001 * j;
            }
            for (int i = 0; i < N; ++i)
                S->values()[S->slot(i, i)] = 5.0;
            assert_true(S->factorize());
        }
        std::vector<double> x1(N), x2(N);
        for (int i = 0; i < N; ++i)
            x1[i] = x2[i] = 1.0 + 0.001 * i;
        first.solve(x1.data());
        second.solve(x2.data());
        assert_memory_equal(x1.data(), x2.data(), sizeof(double) * N);
    }
    // another pattern: its own analysis (a 30 x 30 grid like a ladder chooses AMD, not RCM)
    std::vector<std::pair<int, int>> ladder;
    for (int k = 0; k + 2 < N; ++k)
        ladder.emplace_back(k, k + 2);
    ga::KluSystem band, grid;
    setup_and_solve(band, N, ladder);
    std::vector<std::pair<int, int>> entries;
    for (int i = 0; i < N; ++i)
        entries.emplace_back(i, i);
    for (auto [i, j] : grid_edges(30, 30)) {
        entries.emplace_back(i, j);
        entries.emplace_back(j, i);
    }
    grid.setup(N, entries, ga::KluSystem::Ordering::Auto, &band);
    assert_string_equal(band.ordering(), "RCM");
    assert_string_equal(grid.ordering(), "AMD");
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(refactorization_and_fresh_pivots_solve_correctly),
        cmocka_unit_test(singular_matrix_is_reported),
        cmocka_unit_test(refactorizations_follow_the_values_on_a_saddle_point_pattern),
        cmocka_unit_test(random_patterns_against_dense_lu),
        cmocka_unit_test(cholesky_fill_against_analysis),
        cmocka_unit_test(ordering_follows_the_fill),
        cmocka_unit_test(setup_like_takes_the_analysis_of_the_same_pattern),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
