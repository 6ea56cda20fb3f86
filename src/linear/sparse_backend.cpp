// Sparse backend: S in compressed-column form with a pattern fixed at setup (the union of the
// declared patterns of M, C_t, K_t and Phi_q, and the diagonal of the top-left block), every
// block entry mapped once to its slot, and SuiteSparse KLU: symbolic analysis at setup, a
// numeric factorization the first time, then klu_refactor -- same pivot order, no allocation.
// If a refactorization comes out poorly conditioned (pivots chosen for other values), the
// matrix is factorized afresh with new pivots (this rare path allocates).
#include "backend.hpp"

#ifdef GALPHA_HAVE_KLU
#include <klu.h>

#include <algorithm>
#include <limits>
#include <utility>
#include <vector>

namespace ga {

namespace {

class SparseBackend final : public LinearBackend {
public:
    SparseBackend() { klu_defaults(&common_); }
    ~SparseBackend() override
    {
        if (numeric_)
            klu_free_numeric(&numeric_, &common_);
        if (symbolic_)
            klu_free_symbolic(&symbolic_, &common_);
    }

    void setup(int n, int m, const ModelMatrix &M, const ModelMatrix &J, const ModelMatrix &K,
               const ModelMatrix &C) override
    {
        n_ = n;
        m_ = m;
        const int N = n + m;
        // (col, row) of every structural entry
        std::vector<std::pair<int, int>> entries;
        auto collect = [&](const ModelMatrix &A) {  // top-left block
            for (int k = 0; k < A.nnz(); ++k)
                entries.emplace_back(A.col_index()[k], A.row_index()[k]);
        };
        for (int i = 0; i < n; ++i)
            entries.emplace_back(i, i);
        collect(M);
        collect(K);
        collect(C);
        for (int k = 0; k < J.nnz(); ++k) {
            entries.emplace_back(J.col_index()[k], n + J.row_index()[k]);  // Phi_q
            entries.emplace_back(n + J.row_index()[k], J.col_index()[k]);  // Phi_q^T
        }
        std::sort(entries.begin(), entries.end());
        entries.erase(std::unique(entries.begin(), entries.end()), entries.end());
        colptr_.assign(N + 1, 0);
        rowind_.resize(entries.size());
        for (std::size_t k = 0; k < entries.size(); ++k) {
            ++colptr_[entries[k].first + 1];
            rowind_[k] = entries[k].second;
        }
        for (int j = 0; j < N; ++j)
            colptr_[j + 1] += colptr_[j];
        values_.assign(entries.size(), 0.0);
        auto slot = [&](int i, int j) {
            const auto first = rowind_.begin() + colptr_[j];
            const auto last = rowind_.begin() + colptr_[j + 1];
            return static_cast<int>(std::lower_bound(first, last, i) - rowind_.begin());
        };
        auto map = [&](const ModelMatrix &A, bool phi_q_transposed, int row0) {
            std::vector<int> out(A.nnz());
            for (int k = 0; k < A.nnz(); ++k) {
                const int i = A.row_index()[k], j = A.col_index()[k];
                out[k] = phi_q_transposed ? slot(j, n + i) : slot(i + row0, j);
            }
            return out;
        };
        map_M_ = map(M, false, 0);
        map_K_ = map(K, false, 0);
        map_C_ = map(C, false, 0);
        map_J_ = map(J, false, n);  // Phi_q entry (i, j) at (n + i, j)
        map_JT_ = map(J, true, 0);  // and at (j, n + i)
        diag_.resize(n);
        for (int i = 0; i < n; ++i)
            diag_[i] = slot(i, i);
        // Two orderings: KLU's AMD (least fill) and reverse Cuthill-McKee (a band, so the
        // triangular solves walk memory in order). For mechanism-like sparsity both fill about
        // the same, and the band is several times faster once the factors leave the cache:
        // take the band unless it fills much more.
        symbolic_ = klu_analyze(N, colptr_.data(), rowind_.data(), &common_);
        if (!symbolic_)
            throw std::bad_alloc();
        std::vector<int> order = reverse_cuthill_mckee(N);
        klu_symbolic *banded = klu_analyze_given(N, colptr_.data(), rowind_.data(),
                                                 order.data(), order.data(), &common_);
        if (banded && banded->lnz + banded->unz <= kBandFillAllowance *
                                                       (symbolic_->lnz + symbolic_->unz)) {
            klu_free_symbolic(&symbolic_, &common_);
            symbolic_ = banded;
            ordering_ = "RCM";
        } else if (banded) {
            klu_free_symbolic(&banded, &common_);
        }
    }

    bool factorize(const SaddleBlocks &b) override
    {
        std::fill(values_.begin(), values_.end(), 0.0);
        auto scatter = [&](const ModelMatrix &A, const std::vector<int> &map, double c) {
            const double *v = A.data();
            for (std::size_t k = 0; k < map.size(); ++k)
                values_[map[k]] += c * v[k];
        };
        if (b.M)
            scatter(*b.M, map_M_, b.cM);
        else
            for (int s : diag_)
                values_[s] = 1.0;
        if (b.C)
            scatter(*b.C, map_C_, b.cC);
        if (b.K)
            scatter(*b.K, map_K_, b.cK);
        if (m_ > 0) {
            scatter(*b.J, map_J_, 1.0);
            scatter(*b.J, map_JT_, 1.0);
        }
        if (numeric_) {
            const int ok = klu_refactor(colptr_.data(), rowind_.data(), values_.data(), symbolic_,
                                        numeric_, &common_);
            if (ok && klu_rcond(symbolic_, numeric_, &common_) && common_.rcond > kRefactorRcond) {
                rcond_ = common_.rcond;
                return true;
            }
            klu_free_numeric(&numeric_, &common_);  // pivots no longer fit: start afresh
        }
        numeric_ = klu_factor(colptr_.data(), rowind_.data(), values_.data(), symbolic_, &common_);
        if (!numeric_) {
            if (common_.status == KLU_OUT_OF_MEMORY)
                throw std::bad_alloc();
            rcond_ = 0.0;
            return false;  // singular
        }
        klu_rcond(symbolic_, numeric_, &common_);
        rcond_ = common_.rcond;
        return rcond_ >= std::numeric_limits<double>::epsilon();
    }

    void solve(Vec &rhs) override
    {
        klu_solve(symbolic_, numeric_, n_ + m_, 1, rhs.data(), &common_);
    }

    double rcond() const override { return rcond_; }
    const char *name() const override { return "sparse KLU"; }

private:
    // Reverse Cuthill-McKee on the pattern of S + S^T, from a pseudo-peripheral start in every
    // connected component.
    std::vector<int> reverse_cuthill_mckee(int N) const
    {
        std::vector<std::vector<int>> adj(N);
        for (int j = 0; j < N; ++j)
            for (int p = colptr_[j]; p < colptr_[j + 1]; ++p)
                if (rowind_[p] != j) {
                    adj[j].push_back(rowind_[p]);
                    adj[rowind_[p]].push_back(j);
                }
        for (auto &a : adj) {
            std::sort(a.begin(), a.end());
            a.erase(std::unique(a.begin(), a.end()), a.end());
        }
        std::vector<int> order, level(N, -1);
        order.reserve(N);
        auto bfs = [&](int root, std::vector<int> &out) {  // Cuthill-McKee from root
            std::fill(level.begin(), level.end(), -1);
            out.clear();
            out.push_back(root);
            level[root] = 0;
            for (std::size_t k = 0; k < out.size(); ++k) {
                std::vector<int> next;
                for (int v : adj[out[k]])
                    if (level[v] < 0) {
                        level[v] = level[out[k]] + 1;
                        next.push_back(v);
                    }
                std::sort(next.begin(), next.end(), [&](int a, int b) {
                    return adj[a].size() < adj[b].size();
                });
                out.insert(out.end(), next.begin(), next.end());
            }
        };
        std::vector<char> done(N, 0);
        std::vector<int> comp;
        for (int s = 0; s < N; ++s) {
            if (done[s])
                continue;
            // pseudo-peripheral node: repeat BFS from the farthest node while the depth grows
            int root = s, depth = -1;
            for (int tries = 0; tries < 4; ++tries) {
                bfs(root, comp);
                const int far = comp.back();
                if (level[far] <= depth)
                    break;
                depth = level[far];
                root = far;
            }
            bfs(root, comp);
            for (int v : comp)
                done[v] = 1;
            order.insert(order.end(), comp.begin(), comp.end());
        }
        std::reverse(order.begin(), order.end());
        return order;
    }

    static constexpr double kBandFillAllowance = 1.5;
    const char *ordering_ = "AMD";
    // A refactorization with the old pivots is kept while its pivot ratio stays above this.
    static constexpr double kRefactorRcond = 1e-12;
    int n_ = 0, m_ = 0;
    std::vector<int> colptr_, rowind_, map_M_, map_K_, map_C_, map_J_, map_JT_, diag_;
    std::vector<double> values_;
    klu_common common_;
    klu_symbolic *symbolic_ = nullptr;
    klu_numeric *numeric_ = nullptr;
    double rcond_ = 0.0;
};

}  // namespace

std::unique_ptr<LinearBackend> make_sparse_backend() { return std::make_unique<SparseBackend>(); }

}  // namespace ga

#else

namespace ga {
std::unique_ptr<LinearBackend> make_sparse_backend() { return nullptr; }
}  // namespace ga

#endif
