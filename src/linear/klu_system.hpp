// A square sparse matrix whose pattern is fixed once: ordered at setup by SuiteSparse KLU's
// analysis (its AMD ordering, or reverse Cuthill-McKee when that fills little more), then
// factorized by FixedPivotLU -- pivots chosen by partial pivoting at the first factorization,
// refactorizations and solves with the same pivots afterwards, no allocation. If a
// refactorization comes out poorly conditioned (pivots chosen for other values), the matrix
// is factorized afresh with new pivots (this rare path allocates). KLU also estimates the
// condition number on demand. Shared by the sparse saddle-point backend and the sparse
// stabilized index-2 system.
#pragma once

#ifdef GALPHA_HAVE_KLU
#include <klu.h>

#include "backend.hpp"
#include "fixed_pivot_lu.hpp"

#include <utility>
#include <vector>

namespace ga {

// The Cholesky factor L of P A P^T, for the symmetric pattern A given as neighbour lists (no
// diagonal) and the ordering `order` (order[k]: the row and column placed k-th): its entries
// (diagonal included) and the operations to compute it, the sum of the squared column
// counts. What an ordering costs before pivoting (the measure AMD minimizes), counted exactly
// for any ordering. Counting stops once the entries pass `limit` (both counts are then too
// low, the entries above the limit).
struct CholeskyFill {
    double entries = 0.0, flops = 0.0;
};
CholeskyFill cholesky_fill(const std::vector<std::vector<int>> &adj, const std::vector<int> &order,
                           double limit);

class KluSystem {
public:
    KluSystem();
    ~KluSystem();
    KluSystem(const KluSystem &) = delete;
    KluSystem &operator=(const KluSystem &) = delete;

    // Which ordering the LU starts from: the one chosen by fill (Auto), or one forced (tests).
    enum class Ordering { Auto, Amd, Band };
    // The pattern: (row, column) of every structural entry of the N x N matrix, duplicates
    // allowed. A system `like` set up with the same pattern gives its orderings and choice,
    // which are then not computed again. Throws std::bad_alloc.
    void setup(int N, std::vector<std::pair<int, int>> entries, Ordering start = Ordering::Auto,
               const KluSystem *like = nullptr);
    // Position of entry (row, col) of the pattern in values() (setup time only).
    int slot(int row, int col) const;
    // The entries, in the order of the pattern: the caller assembles them before factorize().
    std::vector<double> &values() { return values_; }

    // false if singular or numerically singular. Throws std::bad_alloc.
    bool factorize();
    // The next factorize() is a full one (new pivots and row scaling) instead of a
    // refactorization with the pivots of an earlier matrix.
    void forget_pivots();
    // The LU's workspace and the storage of its factors, for the fill of the ordering: the
    // first factorization then allocates only if it fills more. Throws std::bad_alloc.
    void reserve_factors();
    void solve(double *rhs);  // in place, length N
    void solve_transpose(double *rhs);  // A^T x = rhs, in place
    // the same with b and x in two blocks (FixedPivotLU::solve_blocks)
    void solve_blocks(const double *b1, double c1, const double *b2, double c2, int n1,
                      double *x1, double *x2, double div2);
    // Reciprocal 1-norm condition estimate of the matrix factorized last, rows scaled as
    // factorized (KLU factorizes it once more for klu_condest: on demand, never in a step;
    // allocates). 0 if singular, or if memory ran out.
    double rcond_estimate() const noexcept;
    const char *ordering() const { return names_[in_use_]; }  // "AMD" or "RCM", in use now
    // The Cholesky factor of S + S^T in AMD's ordering and in RCM's (the count of the latter
    // stops above 1.5 times the former's entries): what the choice was made on.
    const CholeskyFill &amd_fill() const { return amd_fill_; }
    const CholeskyFill &rcm_fill() const { return rcm_fill_; }
    // Factorizations with new pivots so far (the others were refactorizations).
    int full_factorizations() const { return full_factorizations_; }

    // What the next factorize() keeps from the last full one (backend.hpp, pivot_state_size):
    // [pivots kept (0/1), N, ordering in use, ordering switched, pivot row of each column
    // (N), row scaling (N)]. Every factorization's numbers come from a refactorization with
    // these (after a full one too), so a solver that loads them factorizes the next matrix
    // bit for bit as the one that saved them.
    void save_pivots(double *out) const;
    bool pivots_loadable(const double *in) const;  // saved by a system of this pattern
    void load_pivots(const double *in);            // never allocates

private:
    std::vector<std::vector<int>> symmetric_adjacency() const;
    std::vector<int> reverse_cuthill_mckee(const std::vector<std::vector<int>> &adj) const;

    int N_ = 0;
    mutable std::vector<char> seen_;  // pivots_loadable's marks, sized at setup: no allocation
    std::vector<int> colptr_, rowind_;
    std::vector<double> values_;
    std::vector<double> row_scale_;  // D: 1 / the largest entry of each row at the last full
                                     // factorization
    mutable klu_common common_;  // klu_condest writes its result here
    // KLU's analysis in the ordering in use (for klu_condest); rebuilt on demand after a
    // switch of ordering, which happens in a step
    mutable klu_symbolic *symbolic_ = nullptr;
    mutable bool symbolic_stale_ = false;
    FixedPivotLU lu_;     // the factors, with the pivots of the last full factorization
    double rcond_ = 0.0;  // min |U_ii| / max |U_ii| (as klu_rcond): decides singularity
    CholeskyFill amd_fill_, rcm_fill_;
    // The two orderings (AMD's, the band), their names and the entries of L (and of U) their
    // Cholesky counts expect; the LU uses in_use_, and the other once if pivoting makes the
    // first fill far beyond its count (factorize()).
    std::vector<int> orders_[2];
    const char *names_[2] = {"AMD", "RCM"};
    double expected_[2] = {0.0, 0.0};
    int in_use_ = 0;
    int chosen_ = 0;  // in_use_ as setup chose it (what a system `like` this one takes)
    bool switched_ = false;
    int full_factorizations_ = 0;
    // Pivots loaded from a checkpoint: the next factorize() builds their structure first.
    bool loaded_ = false;
    std::vector<int> loaded_rows_;
};

}  // namespace ga
#endif
