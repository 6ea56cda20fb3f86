// The sparse stabilized index-2 system (src/linear/index2_matrix.hpp), tested directly against
// the dense one on the same blocks: in its reduced form (the dense path's matrix, the products
// A B^T and Phi_q B^T assembled on fixed patterns), taken on a chain, and in the augmented
// form (the Newmark increment an unknown of its own), taken where one coordinate is in every
// constraint and Phi_q B^T would be dense; with all constraints active and with some inactive
// (redundant constraints dropped), and in both with a lower block of its own (a group space's
// Phi_q T, whose pattern spreads every entry over its rotation's columns, and Z in that
// layout). The oracle is the dense system with Eigen's LU.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "linear/index2_matrix.hpp"

// cmocka last: its fail() macro would clash with the standard library's
#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <csetjmp>
extern "C" {
#include <cmocka.h>
}

namespace {

struct Pattern {
    std::vector<int> rows, cols;
};

struct Blocks {
    int n = 0, m = 0;
    ga::ModelMatrix M, J, K, C, B, Z;
    bool lower = false;  // L = Phi_q T in the position rows, Z in L's layout (ZL)
    ga::ModelMatrix L, ZL;
};

void declare(ga::ModelMatrix &A, int rows, int cols, const Pattern &p)
{
    A.set_pattern(rows, cols, p.rows.data(), p.cols.data(), static_cast<int>(p.rows.size()));
    A.allocate();
}

// Blocks of the given Jacobian pattern: M and K diagonal, C on the diagonal of every other
// coordinate, random values; B = Phi_q(q_n) and Z share the pattern of J = Phi_q(q_{n+1}).
Blocks make_blocks(int n, int m, const Pattern &jacobian, std::mt19937 &random)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Blocks b;
    b.n = n;
    b.m = m;
    Pattern diagonal, every_other;
    for (int i = 0; i < n; ++i) {
        diagonal.rows.push_back(i);
        diagonal.cols.push_back(i);
        if (i % 2 == 0) {
            every_other.rows.push_back(i);
            every_other.cols.push_back(i);
        }
    }
    declare(b.M, n, n, diagonal);
    declare(b.K, n, n, diagonal);
    declare(b.C, n, n, every_other);
    for (ga::ModelMatrix *A : {&b.J, &b.B, &b.Z})
        declare(*A, m, n, jacobian);
    for (int k = 0; k < b.M.nnz(); ++k) {
        b.M.data()[k] = 1.5 + 0.5 * u(random);
        b.K.data()[k] = 10.0 * u(random);
    }
    for (int k = 0; k < b.C.nnz(); ++k)
        b.C.data()[k] = 2.0 + u(random);
    for (int k = 0; k < b.J.nnz(); ++k) {
        b.J.data()[k] = u(random);
        b.B.data()[k] = b.J.data()[k] + 0.05 * u(random);
        b.Z.data()[k] = u(random);
    }
    return b;
}

// A lower block as on a group space whose rotations are the column triples (3k, 3k+1, 3k+2):
// J's pattern with every entry spread over its triple, random values; Z likewise.
void add_lower_block(Blocks &b, const Pattern &jacobian, std::mt19937 &random)
{
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<std::pair<int, int>> e;
    for (std::size_t k = 0; k < jacobian.rows.size(); ++k)
        for (int c = 3 * (jacobian.cols[k] / 3); c < std::min(3 * (jacobian.cols[k] / 3) + 3, b.n);
             ++c)
            e.emplace_back(jacobian.rows[k], c);
    std::sort(e.begin(), e.end());
    e.erase(std::unique(e.begin(), e.end()), e.end());
    Pattern L;
    for (auto [r, c] : e) {
        L.rows.push_back(r);
        L.cols.push_back(c);
    }
    declare(b.L, b.m, b.n, L);
    declare(b.ZL, b.m, b.n, L);
    for (int k = 0; k < b.L.nnz(); ++k) {
        b.L.data()[k] = u(random);
        b.ZL.data()[k] = u(random);
    }
    b.lower = true;
}

// The chain's pattern: constraint pair i joins coordinates of bodies i - 1 and i.
Pattern chain_jacobian(int bodies)
{
    Pattern p;
    for (int i = 0; i < bodies; ++i)
        for (int d = 0; d < 2; ++d)
            for (int body = i - 1; body <= i; ++body)
                if (body >= 0)
                    for (int c : {d, 2}) {
                        p.rows.push_back(2 * i + d);
                        p.cols.push_back(3 * body + c);
                    }
    return p;
}

// Coordinate 0 in every constraint (a hub): Phi_q B^T is dense, m x m.
Pattern hub_jacobian(int m)
{
    Pattern p;
    for (int i = 0; i < m; ++i) {
        p.rows.insert(p.rows.end(), {i, i});
        p.cols.insert(p.cols.end(), {0, i + 1});
    }
    return p;
}

// Largest difference between the sparse and the dense solution, relative to the solution,
// against what the two LUs may differ by: each solution is within about N eps cond(S) of the
// exact one (backward-stable LU; cond from LAPACK's estimate on the dense factors).
void sparse_against_dense(const char *what, const Blocks &b, const unsigned char *active,
                          bool expect_reduced, bool amd_first = false,
                          const char *expect_ordering = nullptr)
{
    const ga::Params p = ga::params_from_rho_inf(0.8);
    const double h = 1e-2;
    ga::Index2Matrix sparse, dense;
    const ga::ModelMatrix *L = b.lower ? &b.L : nullptr, *Z = b.lower ? &b.ZL : &b.Z;
    sparse.setup(b.n, b.m, true, ga::DenseKind::Auto, b.M, b.J, b.K, b.C, L, active, amd_first);
    dense.setup(b.n, b.m, false, ga::DenseKind::Eigen, b.M, b.J, b.K, b.C, nullptr, active);
    assert_true(sparse.sparse() && !dense.sparse());
    assert_int_equal(sparse.sparse_reduced(), expect_reduced);
    assert_true(sparse.factorize(b.M, &b.C, &b.K, b.J, b.B, Z, p, h, L));
    assert_true(dense.factorize(b.M, &b.C, &b.K, b.J, b.B, Z, p, h, L));
    const ga::Vec rq = ga::Vec::LinSpaced(b.n, -1.0, 2.0), phi = ga::Vec::LinSpaced(b.m, 0.5, -0.5),
                  phi_v = ga::Vec::LinSpaced(b.m, -0.3, 0.7);
    ga::Vec d1, w1, l1, e1, d2, w2, l2, e2;
    for (ga::Vec *x : {&d1, &w1, &d2, &w2})
        x->setZero(b.n);
    for (ga::Vec *x : {&l1, &e1, &l2, &e2})
        x->setZero(b.m);
    sparse.solve(rq, phi, phi_v, p, h, b.B, d1, w1, l1, e1);
    dense.solve(rq, phi, phi_v, p, h, b.B, d2, w2, l2, e2);
    double worst = 0.0;
    for (auto [x, y] : {std::pair{&d1, &d2}, {&w1, &w2}, {&l1, &l2}, {&e1, &e2}})
        worst = std::max(worst, (*x - *y).lpNorm<Eigen::Infinity>() /
                                    std::max(y->lpNorm<Eigen::Infinity>(), 1e-300));
    if (active)
        for (int i = 0; i < b.m; ++i)
            if (!active[i])
                assert_true(l1[i] == 0.0 && e1[i] == 0.0);
    const int N = b.n + 2 * b.m;
    const double bound = 2.0 * N * std::numeric_limits<double>::epsilon() / dense.rcond();
    std::printf("  %s: sparse - dense %.1e <= %.1e (N = %d, 1/cond %.1e; ordering %s)\n", what,
                worst, bound, N, dense.rcond(), sparse.ordering());
    if (expect_ordering)
        assert_string_equal(sparse.ordering(), expect_ordering);
    assert_true(dense.rcond() > 0.0);
    assert_true(worst <= bound);
}

void reduced_form_on_a_chain(void **)
{
    std::mt19937 random(3);
    const int bodies = 40;
    const Blocks b = make_blocks(3 * bodies, 2 * bodies, chain_jacobian(bodies), random);
    std::vector<unsigned char> some_inactive(2 * bodies, 1);
    some_inactive[5] = some_inactive[17] = some_inactive[2 * bodies - 1] = 0;
    sparse_against_dense("chain, reduced form, all active", b, nullptr, true);
    sparse_against_dense("chain, reduced form, 3 inactive", b, some_inactive.data(), true);
    Blocks g = make_blocks(3 * bodies, 2 * bodies, chain_jacobian(bodies), random);
    add_lower_block(g, chain_jacobian(bodies), random);
    sparse_against_dense("chain, reduced form, lower block", g, nullptr, true);
    sparse_against_dense("chain, reduced form, lower block, 3 inactive", g, some_inactive.data(),
                         true);
}

// The chain straight and at rest, as galpha's chain scene starts (unit links along x): the
// angle entries of the x-constraints are exactly zero there, the y-constraints' are +-1/2.
Blocks straight_chain_at_rest(int bodies, std::mt19937 &random)
{
    Blocks b = make_blocks(3 * bodies, 2 * bodies, chain_jacobian(bodies), random);
    for (int k = 0; k < b.M.nnz(); ++k) {
        b.M.data()[k] = k % 3 == 2 ? 1.0 / 12.0 : 1.0;  // mass, and inertia of a unit bar
        b.K.data()[k] = 0.0;
    }
    for (int k = 0; k < b.C.nnz(); ++k)
        b.C.data()[k] = 0.0;
    const Pattern p = chain_jacobian(bodies);
    for (int k = 0; k < b.J.nnz(); ++k) {
        const int row = p.rows[k], col = p.cols[k], body = col / 3, link = row / 2;
        const bool x_row = row % 2 == 0, angle = col % 3 == 2;
        double v = body == link ? 1.0 : -1.0;  // x_i - x_{i-1} + ...
        if (angle)
            v = x_row ? 0.0 : 0.5;  // d/dtheta of -/+ (1/2) cos/sin at theta = 0
        b.J.data()[k] = b.B.data()[k] = v;
        b.Z.data()[k] = 0.0;
    }
    return b;
}

// AMD's ordering of the chain's reduced system looks as good as the band by its Cholesky count,
// but with the straight chain's values the pivots undo it: L fills 8x the count at 100 bodies,
// 22x at 300 (growing like N^2). The LU stops such a factorization at 4x and takes the band
// instead: the solution is as accurate, and the band is in use afterwards.
void amd_undone_by_pivoting_gives_way_to_the_band(void **)
{
    std::mt19937 random(3);
    const int bodies = 100;
    const Blocks b = straight_chain_at_rest(bodies, random);
    sparse_against_dense("chain, started from AMD", b, nullptr, true, true, "RCM");
    sparse_against_dense("chain, ordering by the count", b, nullptr, true, false, "RCM");
}

void augmented_form_around_a_hub(void **)
{
    std::mt19937 random(5);
    const int m = 60, n = m + 1;
    const Blocks b = make_blocks(n, m, hub_jacobian(m), random);
    std::vector<unsigned char> some_inactive(m, 1);
    some_inactive[0] = some_inactive[30] = 0;
    sparse_against_dense("hub, augmented form, all active", b, nullptr, false);
    sparse_against_dense("hub, augmented form, 2 inactive", b, some_inactive.data(), false);
    Blocks g = make_blocks(n, m, hub_jacobian(m), random);
    add_lower_block(g, hub_jacobian(m), random);
    sparse_against_dense("hub, augmented form, lower block", g, nullptr, false);
    sparse_against_dense("hub, augmented form, lower block, 2 inactive", g,
                         some_inactive.data(), false);
}

}  // namespace

int main()
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(reduced_form_on_a_chain),
        cmocka_unit_test(amd_undone_by_pivoting_gives_way_to_the_band),
        cmocka_unit_test(augmented_form_around_a_hub),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
