// The iteration matrix of the stabilized index-2 formulation (docs/algorithms.md sec. 2; Arnold &
// Hante 2017), in the scaling of eq. (10) extended to the extra multiplier. Unknowns
// (d, lambda_bar, eta_bar) = (dq, beta h^2 dlambda, h deta), with B = Phi_q(q_n) and
// A = cM M + gamma h C:
//
//   [ A + beta h^2 K   Phi_q^T   A B^T       ] [d         ]
//   [ Phi_q            0         0           ] [lambda_bar]
//   [ Phi_q            0         Phi_q B^T   ] [eta_bar   ]
//
//   = -[ beta h^2 r^q ; Phi ; (beta h / gamma) (Phi_q v + Phi_t) ]
//
// plus, unless tangents are neglected, the curvature of the velocity constraint in the third
// row's first block, (beta h / gamma) Z with Z = d(Phi_q v + Phi_t)/dq (docs/algorithms.md sec. 2.2;
// gena leaves it out by default, and Newton then contracts only like h |v| / length: on
// Andrews' mechanism, h = 5e-5, 3.5 instead of 2.5 iterations per step).
// Dense: (n + 2m)^2, Eigen LU. Sparse (declared patterns, KLU): the same matrix, the products
// A B^T and Phi_q B^T on patterns fixed at setup -- unless they would hold many more entries
// (a coordinate in many constraints makes Phi_q B^T dense in them); then the Newmark increment
// w = d + B^T eta_bar becomes an unknown of its own and every block is one of the user's
// sparse matrices:
//
//   [ beta h^2 K   A       Phi_q^T   0     ] [d         ]   [ -beta h^2 r^q          ]
//   [ -I           I       0         -B^T  ] [w         ] = [ 0                      ]
//   [ Phi_q        0       0         0     ] [lambda_bar]   [ -Phi                   ]
//   [ (bh/g) Z     Phi_q   0         0     ] [eta_bar   ]   [ -(beta h / gamma) Phi_v ]
//
// (eliminating w gives the first system back).
#pragma once

#include <memory>

#include "../matrix.hpp"
#include "../params.hpp"
#include "backend.hpp"

namespace ga {

class Index2Matrix {
public:
    Index2Matrix();
    ~Index2Matrix();
    Index2Matrix(Index2Matrix &&) noexcept;
    Index2Matrix &operator=(Index2Matrix &&) noexcept;

    // Allocates everything (patterns of M, J, K, C: their layouts; B has J's). J_low (sparse
    // on a group space; else null): the layout of Phi_q T(xi), which the position constraint's
    // rows and the curvature Z then have (K comes in K_t T's layout). active: m flags owned by
    // the caller (null: every constraint active); an inactive constraint's rows and columns
    // (lambda_bar and eta_bar) are those of the identity, its right-hand side 0. dense_kind:
    // the dense LU (Lapack counts as Eigen). amd_first (tests): the sparse LU starts from AMD's
    // ordering even where the band would be chosen. Throws std::bad_alloc.
    void setup(int n, int m, bool sparse, DenseKind dense_kind, const ModelMatrix &M,
               const ModelMatrix &J, const ModelMatrix &K, const ModelMatrix &C,
               const ModelMatrix *J_low, const unsigned char *active, bool amd_first = false);
    bool ready() const { return dense_ || sparse_; }
    void reset();  // not set up, as constructed
    bool sparse() const { return sparse_ != nullptr; }
    // sparse, in the reduced (n + 2m) form (else the augmented one, or dense)
    bool sparse_reduced() const;
    // false if singular or numerically singular. Z (layout of J) may be null: left out.
    // J_low, when given, is the position constraint's row block in place of J: Phi_q T(xi)
    // on a group space, where Phi_q^T and the velocity rows keep J (K and Z come with their T
    // already; sparse: in the layouts of setup's J_low and K).
    bool factorize(const ModelMatrix &M, const ModelMatrix *C, const ModelMatrix *K,
                   const ModelMatrix &J, const ModelMatrix &B, const ModelMatrix *Z,
                   const Params &p, double h, const ModelMatrix *J_low = nullptr);
    // (d, dlambda, eta_bar) in natural units of d and lambda, and the Newmark part of the
    // update, w = d + B^T eta_bar.
    void solve(const Vec &rq, const Vec &phi, const Vec &phi_v, const Params &p, double h,
               const ModelMatrix &B, Vec &d, Vec &w, Vec &dlambda, Vec &eta_bar);
    double rcond() const;
    const char *name() const;
    const char *ordering() const;  // sparse: the ordering in use ("AMD", "RCM"); else ""
    // The next factorization picks its pivots afresh (LinearBackend::forget_pivots).
    void forget_pivots();
    void reserve_factors();  // LinearBackend::reserve_factors
    // LinearBackend::save_pivots etc. (the sparse system's; a dense one keeps nothing)
    void save_pivots(double *out) const;
    bool pivots_loadable(const double *in) const;
    void load_pivots(const double *in);

private:
    struct Dense;
    struct Sparse;
    static std::unique_ptr<Sparse> setup_sparse(int n, int m, const ModelMatrix &M,
                                                const ModelMatrix &J, const ModelMatrix &K,
                                                const ModelMatrix &C, const ModelMatrix &J_low,
                                                bool with_inactive, bool amd_first);
    const unsigned char *active_ = nullptr;
    std::unique_ptr<Dense> dense_;
    std::unique_ptr<Sparse> sparse_;
};

}  // namespace ga
