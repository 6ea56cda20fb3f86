// The dense LUs (Eigen's blocked PartialPivLU, LAPACK's dgetrf/dgetrs, galpha's unblocked
// kernel) against each other and against the sparse path (galpha's sparse LU in KLU's
// ordering; its rows are named "klu" for continuity with earlier runs), on real iteration
// matrices:
// those of the paper's scenes (dense) and of the N-link chain (dense and sparse, from the same
// declared pattern); and, for the other end of the range, saddle-point matrices without zeros
// (full mass matrix, full constraint Jacobian: "full"), where blocking pays. Factorization
// includes the assembly of S_t from its blocks, as in a step. CSV on stdout; scripts/bench.sh
// turns it into a chart.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/SparseLU>

#include "linear/iteration_matrix.hpp"
extern "C" {
#include "scenes/andrews.h"
#include "scenes/chain.h"
#include "scenes/slider_crank.h"
}

namespace {

struct Blocks {
    int n = 0, m = 0;
    ga::ModelMatrix M, J, K, C;
};

// Blocks of a dense scene at its initial state.
Blocks dense_blocks(int n, int m, ga_mass_fn mass, ga_jacobian_fn jac, void *user,
                    const double *q)
{
    Blocks b;
    b.n = n;
    b.m = m;
    b.M.set_dense(n, n);
    b.J.set_dense(m, n);
    b.K.set_dense(n, n);
    b.C.set_dense(n, n);
    for (auto *A : {&b.M, &b.J, &b.K, &b.C})
        A->allocate();
    mass(0.0, q, b.M.data(), user);
    jac(0.0, q, b.J.data(), user);
    return b;
}

// A saddle-point system without zero entries but its m x m block: M = I + 0.05 (1 1^T), a full
// Jacobian with m = n / 2.
Blocks full_blocks(int n)
{
    Blocks b;
    b.n = n;
    b.m = n / 2;
    b.M.set_dense(n, n);
    b.J.set_dense(b.m, n);
    b.K.set_dense(n, n);
    b.C.set_dense(n, n);
    for (auto *A : {&b.M, &b.J, &b.K, &b.C})
        A->allocate();
    b.M.as_dense().setConstant(0.05);
    b.M.as_dense().diagonal().array() += 1.0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < b.m; ++i)
            b.J.as_dense()(i, j) = std::cos(1.0 + 0.7 * i + 1.3 * j) + (i == j ? 2.0 : 0.0);
    return b;
}

// Blocks of the chain, as declared patterns (sparse) or dense matrices filled from them.
Blocks chain_blocks(const chain &c, bool sparse)
{
    Blocks b;
    b.n = 3 * c.links;
    b.m = 2 * c.links;
    std::vector<double> q(b.n), v(b.n);
    chain_initial(&c, q.data(), v.data());
    std::vector<ga::ModelMatrix *> mats = {&b.M, &b.J, &b.K, &b.C};
    for (int which = 0; which < 4; ++which) {
        const int rows = which == GA_MATRIX_JACOBIAN ? b.m : b.n;
        const int nnz = chain_pattern(&c, which, nullptr, nullptr);
        std::vector<int> r(nnz), cc(nnz);
        chain_pattern(&c, which, r.data(), cc.data());
        ga::ModelMatrix pattern;
        pattern.set_pattern(rows, b.n, r.data(), cc.data(), nnz);
        pattern.allocate();
        if (which == GA_MATRIX_MASS)
            chain_mass(0.0, q.data(), pattern.data(), const_cast<chain *>(&c));
        if (which == GA_MATRIX_JACOBIAN)
            chain_jacobian(0.0, q.data(), pattern.data(), const_cast<chain *>(&c));
        if (sparse) {
            *mats[which] = pattern;
        } else {
            mats[which]->set_dense(rows, b.n);
            mats[which]->allocate();
            for (int k = 0; k < nnz; ++k)
                mats[which]->as_dense()(r[k], cc[k]) += pattern.data()[k];
        }
    }
    return b;
}

double time_per_call(const std::function<void()> &f)
{
    using clk = std::chrono::steady_clock;
    double best = 1e300;
    int reps = 1;
    for (;;) {  // grow the repetitions until a block takes 20 ms
        const auto t0 = clk::now();
        for (int r = 0; r < reps; ++r)
            f();
        const double dt = std::chrono::duration<double>(clk::now() - t0).count();
        if (dt > 0.02) {
            best = dt / reps;
            break;
        }
        reps *= 2;
    }
    for (int block = 0; block < 4; ++block) {
        const auto t0 = clk::now();
        for (int r = 0; r < reps; ++r)
            f();
        best = std::min(best, std::chrono::duration<double>(clk::now() - t0).count() / reps);
    }
    return best;
}

void measure(const std::string &matrix, Blocks &b, const char *backend_name,
             std::unique_ptr<ga::LinearBackend> backend)
{
    ga::IterationMatrix S;
    S.setup(std::move(backend), b.n, b.m, b.M, b.J, b.K, b.C);
    ga::Params p = ga::params_from_rho_inf(0.7);
    const double h = 1e-3;
    if (!S.factorize_step(b.M, nullptr, nullptr, b.J, p, h, true)) {
        std::fprintf(stderr, "%s: singular\n", matrix.c_str());
        return;
    }
    ga::Vec r1 = ga::Vec::Ones(b.n), r2 = ga::Vec::Ones(b.m), x1(b.n), x2(b.m);
    const double tf = time_per_call([&] { S.factorize_step(b.M, nullptr, nullptr, b.J, p, h, true); });
    const double ts = time_per_call([&] { S.solve(r1, r2, x1, x2, p.beta * h * h); });
    std::printf("%s,%d,%s,%.4f,%.4f\n", matrix.c_str(), b.n + b.m, backend_name, 1e6 * tf,
                1e6 * ts);
    std::fflush(stdout);
}

// Eigen's SparseLU on the same scaled iteration matrix, assembled from the chain's patterns:
// analyzePattern once, factorize per call (as a step would), for the KLU comparison.
void measure_eigen_sparse(Blocks &b)
{
    const int n = b.n, m = b.m, N = n + m;
    ga::Params p = ga::params_from_rho_inf(0.7);
    const double cM = (1.0 - p.alpha_m) / (1.0 - p.alpha_f);
    std::vector<Eigen::Triplet<double>> t;
    for (int i = 0; i < n; ++i)
        t.emplace_back(i, i, 0.0);  // structural diagonal, as galpha's KLU path keeps it
    for (int k = 0; k < b.M.nnz(); ++k)
        t.emplace_back(b.M.row_index()[k], b.M.col_index()[k], cM * b.M.data()[k]);
    for (int k = 0; k < b.J.nnz(); ++k) {
        t.emplace_back(n + b.J.row_index()[k], b.J.col_index()[k], b.J.data()[k]);
        t.emplace_back(b.J.col_index()[k], n + b.J.row_index()[k], b.J.data()[k]);
    }
    Eigen::SparseMatrix<double> S(N, N);
    S.setFromTriplets(t.begin(), t.end());
    Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;
    lu.analyzePattern(S);
    lu.factorize(S);
    if (lu.info() != Eigen::Success) {
        std::fprintf(stderr, "eigen sparse: factorization failed\n");
        return;
    }
    ga::Vec rhs = ga::Vec::Ones(N), x(N);
    const double tf = time_per_call([&] { lu.factorize(S); });
    const double ts = time_per_call([&] { x = lu.solve(rhs); });
    std::printf("chain,%d,eigen_sparselu,%.4f,%.4f\n", N, 1e6 * tf, 1e6 * ts);
    std::fflush(stdout);
}

}  // namespace

int main()
{
    std::printf("matrix,size,backend,factorize_us,solve_us\n");
    slider_crank scp = slider_crank_paper();
    double qs[SC_N], vs[SC_N], q31[AN31_N], v31[AN31_N], v7[7] = {0};
    sc_initial(&scp, 1.5707963267948966, qs, vs);
    an31_from_angles(andrews_q0, v7, q31, v31);
    struct Dense {
        const char *name;
        Blocks b;
    } scenes[] = {
        {"andrews7", dense_blocks(AN7_N, AN7_M, an7_mass, an7_jacobian, nullptr, andrews_q0)},
        {"slider_crank", dense_blocks(SC_N, SC_M, sc_mass, sc_jacobian, &scp, qs)},
        {"andrews31", dense_blocks(AN31_N, AN31_M, an31_mass, an31_jacobian, nullptr, q31)},
    };
    for (auto &s : scenes) {
        measure(s.name, s.b, "eigen", ga::make_dense_backend(ga::DenseKind::Eigen));
        measure(s.name, s.b, "lapack", ga::make_dense_backend(ga::DenseKind::Lapack));
        measure(s.name, s.b, "unblocked", ga::make_dense_backend(ga::DenseKind::Unblocked));
    }
    for (int n : {8, 16, 24, 32, 48, 64, 96, 128}) {
        Blocks full = full_blocks(n);
        measure("full", full, "eigen", ga::make_dense_backend(ga::DenseKind::Eigen));
        measure("full", full, "lapack", ga::make_dense_backend(ga::DenseKind::Lapack));
        measure("full", full, "unblocked", ga::make_dense_backend(ga::DenseKind::Unblocked));
    }
    for (int links : {2, 4, 8, 16, 32, 64, 128, 256}) {
        const chain c = chain_make(links);
        Blocks dense = chain_blocks(c, false), sparse = chain_blocks(c, true);
        measure("chain", dense, "eigen", ga::make_dense_backend(ga::DenseKind::Eigen));
        measure("chain", dense, "lapack", ga::make_dense_backend(ga::DenseKind::Lapack));
        measure("chain", dense, "unblocked", ga::make_dense_backend(ga::DenseKind::Unblocked));
        measure("chain", sparse, "klu", ga::make_sparse_backend());
        measure_eigen_sparse(sparse);
    }
    return 0;
}
