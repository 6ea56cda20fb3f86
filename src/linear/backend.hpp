// Linear algebra behind the iteration matrix: one interface, a dense and a sparse backend.
//
// Every matrix galpha factorizes has the saddle-point form
//     S = [ cM M + cC C + cK K   Phi_q^T ]      (or I in the top-left block: projections)
//         [ Phi_q                0       ]
// The backend knows the layout of the blocks once (setup), assembles S in place from them
// (factorize) and solves with the factors (solve). Neither allocates after setup.
// Constraints can be inactive (redundant ones dropped, see solver.hpp): row and column n + i
// of an inactive constraint i are replaced by those of the identity, so its multiplier is
// whatever the right-hand side says (the callers pass 0).
#pragma once

#include <cstddef>
#include <memory>

#include "../matrix.hpp"

namespace ga {

// What a factorization keeps for the next one, which a checkpoint carries so that a restored
// solver factorizes bit for bit as the one it came from (the sparse LU: its pivots, ordering
// and row scaling, KluSystem::save_pivots; a dense LU keeps nothing): a block of
// pivot_state_size(N) doubles for a system of at most N unknowns, [kept (0/1), N, ordering
// (0/1), switched (0/1), ...]. A block with nothing kept, or from a system of another size,
// loads as "choose pivots afresh".
inline std::size_t pivot_state_size(int N) { return 4 + 2 * static_cast<std::size_t>(N); }
inline bool pivot_block_header_ok(const double *in)
{
    const auto flag = [](double x) { return x == 0.0 || x == 1.0; };
    return flag(in[0]) && flag(in[2]) && flag(in[3]) && in[1] >= 0.0 && in[1] < 2147483647.0 &&
           in[1] == static_cast<double>(static_cast<long>(in[1]));
}

struct SaddleBlocks {
    const ModelMatrix *M = nullptr;  // null: identity in the top-left block
    double cM = 1.0;
    const ModelMatrix *C = nullptr;  // null: neglected
    double cC = 0.0;
    const ModelMatrix *K = nullptr;  // null: neglected
    double cK = 0.0;
    const ModelMatrix *J = nullptr;
    // The lower-left block where it is not J: Phi_q T(xi) on a group space, where the
    // upper-right block stays Phi_q^T (docs/algorithms.md sec. 14); sparse: in the layout
    // given at setup
    const ModelMatrix *J_low = nullptr;
    const unsigned char *active = nullptr;  // m flags; null: every constraint active
};

class LinearBackend {
public:
    virtual ~LinearBackend() = default;
    // Layouts of the blocks (patterns for the sparse backend); allocates everything.
    // with_inactive: constraints may be made inactive (the sparse pattern needs the diagonal
    // of the lower-right block then). J_low (sparse): the layout of the lower-left block when
    // it is not J's (Phi_q T on a group space, whose pattern holds J's); factorize then takes
    // it from SaddleBlocks::J_low, or J where that is null.
    virtual void setup(int n, int m, const ModelMatrix &M, const ModelMatrix &J,
                       const ModelMatrix &K, const ModelMatrix &C, bool with_inactive,
                       const ModelMatrix *J_low = nullptr) = 0;
    // A backend set up already whose analysis (fill-reducing ordering) the next setup may
    // take over if its pattern turns out the same; it must outlive that setup.
    virtual void analysis_from(const LinearBackend *like) { (void)like; }
    // Assemble and factorize; false if singular or numerically singular.
    virtual bool factorize(const SaddleBlocks &b) = 0;
    virtual void solve(Vec &rhs) = 0;  // in place, length n + m
    // [x1; x2 * div2] = S^{-1} [c1 b1; c2 b2] without a vector of length n + m in between
    // (b1, x1 of length n; b2, x2 of m; b is read whole before x is written, so they may be
    // the same vectors). false: not offered, use solve().
    virtual bool solve_blocks(const Vec &b1, double c1, const Vec &b2, double c2, Vec &x1,
                              Vec &x2, double div2)
    {
        (void)b1, (void)c1, (void)b2, (void)c2, (void)x1, (void)x2, (void)div2;
        return false;
    }
    // Reciprocal condition estimate of the last factorization (dense: condition.hpp, 1-norm;
    // sparse: KLU's klu_condest, 1-norm, on a factorization made for it).
    virtual double rcond() const = 0;
    virtual const char *name() const = 0;
    // The next factorization chooses its pivots (and the sparse row scaling) afresh, as in a
    // new solver; a dense LU does so at every factorization anyway.
    virtual void forget_pivots() {}
    // The pivot state (see pivot_state_size): written into a zeroed block, checked, taken
    // over (load never allocates).
    virtual void save_pivots(double *out) const { (void)out; }
    virtual bool pivots_loadable(const double *in) const { return pivot_block_header_ok(in); }
    virtual void load_pivots(const double *in) { (void)in; }
    // Allocates now the storage of the factors that factorize() would otherwise allocate in
    // its first call (the sparse LU: from the fill of the ordering). Called once all setups
    // are done, so that it never adds to the peak of their temporary memory.
    virtual void reserve_factors() {}
};

// Auto: per factorization, the unblocked kernel for small or mostly-zero S, Eigen's otherwise.
enum class DenseKind { Lapack, Eigen, Unblocked, Auto };
std::unique_ptr<LinearBackend> make_dense_backend(DenseKind kind);
// nullptr when galpha was built without KLU.
std::unique_ptr<LinearBackend> make_sparse_backend();

}  // namespace ga
