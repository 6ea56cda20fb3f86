// Sparse backend: S in compressed-column form with a pattern fixed at setup (the union of the
// declared patterns of M, C_t, K_t and Phi_q, and the diagonal of the top-left block), every
// block entry mapped once to its slot, factorized by KLU (klu_system.hpp).
#include "backend.hpp"

#ifdef GALPHA_HAVE_KLU
#include <algorithm>
#include <utility>
#include <vector>

#include "klu_system.hpp"

namespace ga {

namespace {

class SparseBackend final : public LinearBackend {
public:
    void setup(int n, int m, const ModelMatrix &M, const ModelMatrix &J, const ModelMatrix &K,
               const ModelMatrix &C, bool with_inactive, const ModelMatrix *J_low) override
    {
        n_ = n;
        m_ = m;
        // (row, col) of every structural entry
        std::vector<std::pair<int, int>> entries;
        auto collect = [&](const ModelMatrix &A) {  // top-left block
            for (int k = 0; k < A.nnz(); ++k)
                entries.emplace_back(A.row_index()[k], A.col_index()[k]);
        };
        for (int i = 0; i < n; ++i)
            entries.emplace_back(i, i);
        collect(M);
        collect(K);
        collect(C);
        for (int k = 0; k < J.nnz(); ++k) {
            entries.emplace_back(n + J.row_index()[k], J.col_index()[k]);  // Phi_q
            entries.emplace_back(J.col_index()[k], n + J.row_index()[k]);  // Phi_q^T
        }
        if (J_low)  // Phi_q T: J's pattern with whole rotation column blocks
            for (int k = 0; k < J_low->nnz(); ++k)
                entries.emplace_back(n + J_low->row_index()[k], J_low->col_index()[k]);
        if (with_inactive)
            for (int i = 0; i < m; ++i)
                entries.emplace_back(n + i, n + i);
        const auto *like = dynamic_cast<const SparseBackend *>(like_);
        S_.setup(n + m, std::move(entries), KluSystem::Ordering::Auto, like ? &like->S_ : nullptr);
        like_ = nullptr;
        J_rows_ = J.row_index();
        auto map = [&](const ModelMatrix &A, bool phi_q_transposed, int row0) {
            std::vector<int> out(A.nnz());
            for (int k = 0; k < A.nnz(); ++k) {
                const int i = A.row_index()[k], j = A.col_index()[k];
                out[k] = phi_q_transposed ? S_.slot(j, n + i) : S_.slot(i + row0, j);
            }
            return out;
        };
        map_M_ = map(M, false, 0);
        map_K_ = map(K, false, 0);
        map_C_ = map(C, false, 0);
        map_J_ = map(J, false, n);  // Phi_q entry (i, j) at (n + i, j)
        map_JT_ = map(J, true, 0);  // and at (j, n + i)
        map_low_.clear();
        low_rows_.clear();
        if (J_low) {
            map_low_ = map(*J_low, false, n);
            low_rows_ = J_low->row_index();
        }
        diag_.resize(n);
        for (int i = 0; i < n; ++i)
            diag_[i] = S_.slot(i, i);
        // The slots of the top-left block, where M, C_t, K_t (or I) add up; the constraint
        // blocks are written, not added, unless Phi_q's pattern repeats an entry.
        // (marked in a pass over S's slots, not sorted: a sort of every block entry was a
        // tenth of ga_init on a long chain)
        std::vector<unsigned char> marked(S_.values().size(), 0);
        for (const std::vector<int> *m : {&diag_, &map_M_, &map_K_, &map_C_})
            for (const int slot : *m)
                marked[slot] = 1;
        top_left_.clear();
        for (int slot = 0; slot < static_cast<int>(marked.size()); ++slot)
            if (marked[slot])
                top_left_.push_back(slot);
        std::fill(marked.begin(), marked.end(), 0);
        j_written_ = !J_low;  // (a lower block of its own: S is zeroed and added up)
        for (const int slot : map_J_) {
            j_written_ = j_written_ && !marked[slot];
            marked[slot] = 1;
        }
        lower_diag_.clear();
        if (with_inactive)
            for (int i = 0; i < m; ++i)
                lower_diag_.push_back(S_.slot(n + i, n + i));
    }

    bool factorize(const SaddleBlocks &b) override
    {
        std::vector<double> &values = S_.values();
        if (j_written_) {  // zero only what is added to (a quarter of S for a chain)
            for (int s : top_left_)
                values[s] = 0.0;
            for (int s : lower_diag_)
                values[s] = 0.0;
        } else {
            std::fill(values.begin(), values.end(), 0.0);
        }
        auto scatter = [&](const ModelMatrix &A, const std::vector<int> &map, double c) {
            const double *v = A.data();
            for (std::size_t k = 0; k < map.size(); ++k)
                values[map[k]] += c * v[k];
        };
        if (b.M)
            scatter(*b.M, map_M_, b.cM);
        else
            for (int s : diag_)
                values[s] = 1.0;
        if (b.C)
            scatter(*b.C, map_C_, b.cC);
        if (b.K)
            scatter(*b.K, map_K_, b.cK);
        if (m_ > 0 && j_written_) {
            const double *v = b.J->data();
            for (std::size_t k = 0; k < map_J_.size(); ++k)
                values[map_J_[k]] = values[map_JT_[k]] = v[k];
        } else if (m_ > 0) {
            if (b.J_low && !map_low_.empty())
                scatter(*b.J_low, map_low_, 1.0);
            else
                scatter(*b.J, map_J_, 1.0);
            scatter(*b.J, map_JT_, 1.0);
        }
        if (m_ > 0) {
            if (b.active && !lower_diag_.empty()) {
                for (std::size_t k = 0; k < map_J_.size(); ++k)
                    if (!b.active[J_rows_[k]])
                        values[map_J_[k]] = values[map_JT_[k]] = 0.0;
                for (std::size_t k = 0; k < map_low_.size(); ++k)
                    if (!b.active[low_rows_[k]])
                        values[map_low_[k]] = 0.0;
                for (int i = 0; i < m_; ++i)
                    if (!b.active[i])
                        values[lower_diag_[i]] = 1.0;
            }
        }
        return S_.factorize();
    }

    void solve(Vec &rhs) override { S_.solve(rhs.data()); }
    bool solve_blocks(const Vec &b1, double c1, const Vec &b2, double c2, Vec &x1, Vec &x2,
                      double div2) override
    {
        S_.solve_blocks(b1.data(), c1, b2.data(), c2, n_, x1.data(), x2.data(), div2);
        return true;
    }

    double rcond() const override { return S_.rcond_estimate(); }
    const char *name() const override { return "sparse KLU"; }
    void forget_pivots() override { S_.forget_pivots(); }
    void reserve_factors() override { S_.reserve_factors(); }
    void save_pivots(double *out) const override { S_.save_pivots(out); }
    bool pivots_loadable(const double *in) const override { return S_.pivots_loadable(in); }
    void load_pivots(const double *in) override { S_.load_pivots(in); }
    void analysis_from(const LinearBackend *like) override { like_ = like; }

private:
    int n_ = 0, m_ = 0;
    const LinearBackend *like_ = nullptr;  // analysis_from, until setup
    KluSystem S_;
    std::vector<int> map_M_, map_K_, map_C_, map_J_, map_JT_, diag_, lower_diag_, top_left_;
    bool j_written_ = false;  // no slot of Phi_q twice in its pattern
    std::vector<int> J_rows_;  // row of each Phi_q entry
    std::vector<int> map_low_, low_rows_;  // the lower block's own layout (setup's J_low)
};

}  // namespace

std::unique_ptr<LinearBackend> make_sparse_backend() { return std::make_unique<SparseBackend>(); }

}  // namespace ga

#else

namespace ga {
std::unique_ptr<LinearBackend> make_sparse_backend() { return nullptr; }
}  // namespace ga

#endif
