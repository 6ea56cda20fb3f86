#include "klu_system.hpp"

#ifdef GALPHA_HAVE_KLU
#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace ga {

namespace {
// RCM is kept when it fills, and costs to factorize, at most this much more than AMD.
constexpr double kBandFillAllowance = 1.5;
// A refactorization with the old pivots is kept while its pivot ratio stays above this.
constexpr double kRefactorRcond = 1e-12;
// A full factorization whose L or U passes this many times the entries the ordering's
// Cholesky count expects is stopped, and the other ordering taken: the pivots the values call
// for undo the ordering (AMD's on the reduced index-2 system of a chain: 8x the count at 100
// links, 22x at 300, 70x at 1 000, growing like N^2). Measured otherwise: at most 1.1x.
constexpr double kFillBudget = 4.0;

// Subnormal numbers flushed to zero inside the numeric kernels of the LU, and the caller's two mode
// bits put back on the way out (no user code runs inside them; exception flags raised there
// stay raised). Factors of long chains hold entries that decay geometrically along the chain
// through every decade down to the subnormal range, where the processor is some 100 times
// slower: the stabilized index-2 system of a 10 000-link chain took 108 ms per step with
// them, 11 ms without. An entry below 2.2e-308 beside entries of order one changes nothing a
// solve can resolve.
class FlushSubnormals {
public:
#if defined(__SSE2__)
    FlushSubnormals() : saved_(_mm_getcsr() & kBits) { _mm_setcsr(_mm_getcsr() | kBits); }
    ~FlushSubnormals() { _mm_setcsr((_mm_getcsr() & ~kBits) | saved_); }

private:
    static constexpr unsigned kBits = 0x8040;  // MXCSR: flush to zero, denormals are zero
    unsigned saved_;
#else
    // other processors keep their mode (user-provided, so that no unused-variable warning)
    FlushSubnormals() {}
    ~FlushSubnormals() {}
#endif
};
}  // namespace

// Row k of L is the subtree of the elimination tree that the entries of row k reach (Davis,
// Direct Methods for Sparse Linear Systems, ch. 4): O(|L|) time, no factor stored.
CholeskyFill cholesky_fill(const std::vector<std::vector<int>> &adj, const std::vector<int> &order,
                           double limit)
{
    const int N = static_cast<int>(order.size());
    std::vector<int> position(N), parent(N, -1), ancestor(N, -1), mark(N, -1);
    std::vector<double> column(N, 0.0);  // entries of each column of L
    for (int k = 0; k < N; ++k)
        position[order[k]] = k;
    CholeskyFill fill;
    for (int k = 0; k < N && fill.entries <= limit; ++k) {
        // the elimination tree, built row by row (Liu's algorithm, path compression)
        for (int neighbour : adj[order[k]]) {
            for (int r = position[neighbour]; r < k;) {
                const int next = ancestor[r];
                ancestor[r] = k;
                if (next < 0) {
                    parent[r] = k;
                    break;
                }
                r = next;
            }
        }
        // row k of L: from each entry up the tree to the part already counted
        mark[k] = k;
        column[k] += 1.0;
        fill.entries += 1.0;
        for (int neighbour : adj[order[k]])
            for (int r = position[neighbour]; r < k && mark[r] != k; r = parent[r]) {
                mark[r] = k;
                column[r] += 1.0;
                fill.entries += 1.0;
            }
    }
    for (double c : column)
        fill.flops += c * c;
    return fill;
}

KluSystem::KluSystem()
{
    klu_defaults(&common_);
    // No block triangular form: galpha's saddle-point matrices are irreducible, and the
    // maximum transversal that looks for blocks took two thirds of a whole adaptive run on
    // the augmented index-2 system of a 3000-link chain (KLU then orders and pivots the
    // whole matrix; the chain's index-3 steps cost the same).
    common_.btf = 0;
    // Row scaling by the largest entry of each row, as KLU's default, but galpha's, kept from
    // one full factorization to the next (a refactorization keeps its pivots, which a new
    // scaling would not change): KLU is only given scaled matrices (klu_condest).
    common_.scale = -1;
}

KluSystem::~KluSystem()
{
    if (symbolic_)
        klu_free_symbolic(&symbolic_, &common_);
}

void KluSystem::setup(int N, std::vector<std::pair<int, int>> entries, Ordering start,
                      const KluSystem *like)
{
    N_ = N;
    seen_.assign(static_cast<std::size_t>(N), 0);
    // Compressed columns by counting (a sort of all entries was half of ga_init on a long
    // chain); then each column's rows sorted and without duplicates.
    colptr_.assign(N + 1, 0);
    for (const auto &e : entries)
        ++colptr_[e.second + 1];
    for (int j = 0; j < N; ++j)
        colptr_[j + 1] += colptr_[j];
    rowind_.resize(entries.size());
    {
        std::vector<int> next(colptr_.begin(), colptr_.end() - 1);
        for (const auto &e : entries)
            rowind_[next[e.second]++] = e.first;
    }
    std::vector<std::pair<int, int>>().swap(entries);  // freed before the factors' storage
    int kept = 0;
    for (int j = 0; j < N; ++j) {
        const auto first = rowind_.begin() + colptr_[j], last = rowind_.begin() + colptr_[j + 1];
        std::sort(first, last);
        const auto end = std::unique(first, last);
        colptr_[j] = kept;
        kept = static_cast<int>(std::copy(first, end, rowind_.begin() + kept) - rowind_.begin());
    }
    colptr_[N] = kept;
    rowind_.resize(kept);
    rowind_.shrink_to_fit();
    values_.assign(rowind_.size(), 0.0);
    loaded_rows_.assign(N, 0);
    loaded_ = false;
    row_scale_.assign(N, 1.0);
    switched_ = false;
    if (like && like->N_ == N && start == Ordering::Auto && like->colptr_ == colptr_ &&
        like->rowind_ == rowind_) {
        // the same pattern: the same orderings, counts and choice, as computed for `like`
        orders_[0] = like->orders_[0];
        orders_[1] = like->orders_[1];
        amd_fill_ = like->amd_fill_;
        rcm_fill_ = like->rcm_fill_;
        expected_[0] = like->expected_[0];
        expected_[1] = like->expected_[1];
        in_use_ = chosen_ = like->chosen_;
        symbolic_ = klu_analyze_given(N, colptr_.data(), rowind_.data(), orders_[in_use_].data(),
                                      orders_[in_use_].data(), &common_);
        if (!symbolic_)
            throw std::bad_alloc();
        return;
    }
    // Two orderings: KLU's AMD (least fill) and reverse Cuthill-McKee (a band). For
    // mechanism-like sparsity both fill about the same, and the band keeps KLU's pivoting in
    // saddle-point systems local (with AMD's ordering the stabilized index-2 system of a
    // 1 000-link chain filled until a step took many seconds; docs/design-notes.md):
    // take the band unless it fills much more or costs many more operations to factorize (a
    // mesh in two or three dimensions, where the band is wide and fills solid: 3 to 6 times
    // slower refactorizations on 100 x 100 to 200 x 200 grids). Both orderings are measured
    // alike (cholesky_fill): KLU estimates the fill of its own ordering only. The count is
    // that of diagonal pivots; where pivoting undoes the ordering taken, the first full
    // factorization finds out and takes the other one (factorize(), kFillBudget).
    symbolic_ = klu_analyze(N, colptr_.data(), rowind_.data(), &common_);
    if (!symbolic_)
        throw std::bad_alloc();
    orders_[0].assign(symbolic_->Q, symbolic_->Q + N);  // AMD's, rows and columns alike
    {
        const std::vector<std::vector<int>> adj = symmetric_adjacency();  // freed before
        amd_fill_ = cholesky_fill(adj, orders_[0], std::numeric_limits<double>::infinity());
        orders_[1] = reverse_cuthill_mckee(adj);
        rcm_fill_ = cholesky_fill(adj, orders_[1], kBandFillAllowance * amd_fill_.entries);
    }
    expected_[0] = amd_fill_.entries;
    expected_[1] = rcm_fill_.entries;  // a lower bound where the count stopped
    const bool band = rcm_fill_.entries <= kBandFillAllowance * amd_fill_.entries &&
                      rcm_fill_.flops <= kBandFillAllowance * amd_fill_.flops;
    in_use_ = chosen_ = start == Ordering::Band || (start == Ordering::Auto && band) ? 1 : 0;
    if (in_use_ == 1) {
        klu_free_symbolic(&symbolic_, &common_);
        symbolic_ = klu_analyze_given(N, colptr_.data(), rowind_.data(), orders_[1].data(),
                                      orders_[1].data(), &common_);
        if (!symbolic_)
            throw std::bad_alloc();
    }
}

void KluSystem::reserve_factors()
{
    lu_.reserve(N_, static_cast<int>(rowind_.size()), expected_[in_use_]);
}

int KluSystem::slot(int row, int col) const
{
    const auto first = rowind_.begin() + colptr_[col];
    const auto last = rowind_.begin() + colptr_[col + 1];
    return static_cast<int>(std::lower_bound(first, last, row) - rowind_.begin());
}

void KluSystem::forget_pivots()
{
    lu_.clear();
    loaded_ = false;
}

void KluSystem::save_pivots(double *out) const
{
    const bool kept = loaded_ || lu_.ready();
    out[0] = kept ? 1.0 : 0.0;
    out[1] = N_;
    out[2] = in_use_;
    out[3] = switched_ ? 1.0 : 0.0;
    const int *rows = loaded_ ? loaded_rows_.data() : lu_.pivot_rows().data();
    for (int k = 0; k < N_; ++k) {
        out[4 + k] = kept ? rows[k] : 0.0;
        out[4 + N_ + k] = row_scale_[k];
    }
}

bool KluSystem::pivots_loadable(const double *in) const
{
    if (!pivot_block_header_ok(in))
        return false;
    if (in[0] == 0.0 || in[1] != N_)
        return true;  // loads as "pivots afresh"
    std::vector<char> &seen = seen_;  // (restores must not run out of memory half way)
    std::fill(seen.begin(), seen.end(), 0);
    for (int k = 0; k < N_; ++k) {
        const double r = in[4 + k], d = in[4 + N_ + k];
        if (!(d > 0.0) || !std::isfinite(d))
            return false;
        if (!(r >= 0.0 && r < N_) || r != std::floor(r) || seen[static_cast<int>(r)])
            return false;
        seen[static_cast<int>(r)] = 1;
    }
    return true;
}

void KluSystem::load_pivots(const double *in)
{
    if (in[0] == 0.0 || in[1] != N_) {
        forget_pivots();
        return;
    }
    lu_.clear();
    loaded_ = true;
    const int ordering = static_cast<int>(in[2]);
    if (ordering != in_use_)
        symbolic_stale_ = true;
    in_use_ = ordering;
    switched_ = in[3] != 0.0;
    for (int k = 0; k < N_; ++k) {
        loaded_rows_[k] = static_cast<int>(in[4 + k]);
        row_scale_[k] = in[4 + N_ + k];
    }
}

bool KluSystem::factorize()
{
    if (loaded_) {
        // Pivots from a checkpoint: the structure of their factors (the values do not matter,
        // the refactorization below computes them). Rows that do not fit: pivots afresh.
        loaded_ = false;
        const FlushSubnormals flush;
        const int *order = orders_[in_use_].data();
        if (lu_.factorize(N_, colptr_.data(), rowind_.data(), values_.data(), row_scale_.data(),
                          order, order, expected_[in_use_], 0.0, loaded_rows_.data()) !=
            FixedPivotLU::Outcome::Factorized)
            lu_.clear();
    }
    if (lu_.ready()) {
        const FlushSubnormals flush;
        const double ratio = lu_.refactor(values_.data());  // rows scaled as it reads them
        if (ratio > kRefactorRcond) {
            rcond_ = ratio;
            return true;
        }
        lu_.clear();  // pivots no longer fit: start afresh
    }
    // A full factorization picks new pivots: new scale factors first.
    std::fill(row_scale_.begin(), row_scale_.end(), 0.0);
    for (std::size_t k = 0; k < values_.size(); ++k)
        row_scale_[rowind_[k]] = std::max(row_scale_[rowind_[k]], std::abs(values_[k]));
    for (double &r : row_scale_)
        r = r > 0.0 ? 1.0 / r : 1.0;
    ++full_factorizations_;
    const FlushSubnormals flush;
    auto factorize_in = [this](int which, double budget) {
        const int *order = orders_[which].data();
        return lu_.factorize(N_, colptr_.data(), rowind_.data(), values_.data(),
                             row_scale_.data(), order, order, expected_[which], budget);
    };
    auto outcome = factorize_in(in_use_, switched_ ? 0.0 : kFillBudget * expected_[in_use_]);
    if (outcome == FixedPivotLU::Outcome::OverBudget) {
        // Pivoting undid this ordering: the other one, for good (this allocates its storage).
        in_use_ = 1 - in_use_;
        switched_ = true;
        symbolic_stale_ = true;
        outcome = factorize_in(in_use_, 0.0);
    }
    if (outcome != FixedPivotLU::Outcome::Factorized) {
        rcond_ = 0.0;
        return false;  // singular
    }
    // The numbers once more, as a refactorization computes them (its sums run in another
    // order): then pivots saved in a checkpoint reproduce them bit for bit.
    rcond_ = lu_.refactor(values_.data());
    return rcond_ >= std::numeric_limits<double>::epsilon();
}

double KluSystem::rcond_estimate() const noexcept
{
    if (!lu_.ready() || rcond_ <= 0.0)
        return 0.0;
    // The matrix factorized last, its rows scaled as they were for that: klu_condest needs
    // KLU's own factors of it, made here on demand (never in a step), with pivots of KLU's
    // choice. This allocates; out of memory there is no estimate (0), as for a singular
    // matrix. (KLU's prototypes are not const-correct.)
    std::vector<double> scaled;
    try {
        scaled = values_;
    } catch (const std::bad_alloc &) {
        return 0.0;
    }
    for (std::size_t k = 0; k < scaled.size(); ++k)
        scaled[k] *= row_scale_[rowind_[k]];
    int *colptr = const_cast<int *>(colptr_.data()), *rowind = const_cast<int *>(rowind_.data());
    if (symbolic_stale_) {  // the LU switched ordering: KLU's analysis follows
        int *order = const_cast<int *>(orders_[in_use_].data());
        klu_symbolic *now = klu_analyze_given(N_, colptr, rowind, order, order, &common_);
        if (!now)
            return 0.0;
        klu_free_symbolic(&symbolic_, &common_);
        symbolic_ = now;
        symbolic_stale_ = false;
    }
    klu_numeric *numeric = klu_factor(colptr, rowind, scaled.data(), symbolic_, &common_);
    if (!numeric)
        return 0.0;
    const int ok = klu_condest(colptr, scaled.data(), symbolic_, numeric, &common_);
    klu_free_numeric(&numeric, &common_);
    if (!ok || !(common_.condest > 0.0))
        return 0.0;
    return 1.0 / common_.condest;
}

void KluSystem::solve(double *rhs)
{
    const FlushSubnormals flush;
    lu_.solve(rhs);  // (D S) x = D b: lu_ scales b
}

void KluSystem::solve_transpose(double *rhs)
{
    const FlushSubnormals flush;
    lu_.solve_transpose(rhs);
}

void KluSystem::solve_blocks(const double *b1, double c1, const double *b2, double c2, int n1,
                             double *x1, double *x2, double div2)
{
    const FlushSubnormals flush;
    lu_.solve_blocks(b1, c1, b2, c2, n1, x1, x2, div2);
}

// The pattern of S + S^T without the diagonal, as sorted neighbour lists.
std::vector<std::vector<int>> KluSystem::symmetric_adjacency() const
{
    std::vector<std::vector<int>> adj(N_);
    {
        std::vector<int> degree(N_, 0);  // with duplicates: each list allocated once
        for (int j = 0; j < N_; ++j)
            for (int p = colptr_[j]; p < colptr_[j + 1]; ++p)
                if (rowind_[p] != j) {
                    ++degree[j];
                    ++degree[rowind_[p]];
                }
        for (int j = 0; j < N_; ++j)
            adj[j].reserve(degree[j]);
    }
    for (int j = 0; j < N_; ++j)
        for (int p = colptr_[j]; p < colptr_[j + 1]; ++p)
            if (rowind_[p] != j) {
                adj[j].push_back(rowind_[p]);
                adj[rowind_[p]].push_back(j);
            }
    for (auto &a : adj) {
        std::sort(a.begin(), a.end());
        a.erase(std::unique(a.begin(), a.end()), a.end());
    }
    return adj;
}

// Reverse Cuthill-McKee on the pattern of S + S^T, from a pseudo-peripheral start in every
// connected component.
std::vector<int> KluSystem::reverse_cuthill_mckee(const std::vector<std::vector<int>> &adj) const
{
    const int N = N_;
    std::vector<int> order, level(N, -1), next;
    order.reserve(N);
    // Cuthill-McKee from root. Only the levels the last search set are cleared: clearing all
    // N of them for every search made the ordering quadratic in the number of connected
    // components (10^6 coordinates in pairs: 100 s).
    auto bfs = [&](int root, std::vector<int> &out) {
        for (int v : out)
            level[v] = -1;
        out.clear();
        out.push_back(root);
        level[root] = 0;
        for (std::size_t k = 0; k < out.size(); ++k) {
            next.clear();
            for (int v : adj[out[k]])
                if (level[v] < 0) {
                    level[v] = level[out[k]] + 1;
                    next.push_back(v);
                }
            std::sort(next.begin(), next.end(),
                      [&](int a, int b) { return adj[a].size() < adj[b].size(); });
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

}  // namespace ga
#endif
