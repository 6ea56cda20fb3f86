// The saddle-point systems of galpha and their solution:
//  - the iteration matrix S_t = [beta' M + gamma' C_t + K_t, Phi_q^T; Phi_q, 0] of Algorithm 1,
//    optionally in the scaled form S_t_bar = D_L S_t D_R of eqs. (9)-(10);
//  - the matrices of the consistent start, [M Phi_q^T; Phi_q 0] and [I Phi_q^T; Phi_q 0].
// Assembly and factorization are the backend's (dense or sparse, see backend.hpp).
#pragma once

#include "../params.hpp"
#include "backend.hpp"

namespace ga {

class IterationMatrix {
public:
    // active: m flags owned by the caller, fixed for the life of the matrix (null: no
    // constraint is ever inactive). J_low: the layout of a lower-left block of its own
    // (LinearBackend::setup).
    void setup(std::unique_ptr<LinearBackend> backend, int n, int m, const ModelMatrix &M,
               const ModelMatrix &J, const ModelMatrix &K, const ModelMatrix &C,
               const unsigned char *active = nullptr, const ModelMatrix *J_low = nullptr);
    bool ready() const { return backend_ != nullptr; }
    const char *backend_name() const { return backend_ ? backend_->name() : "none"; }
    const LinearBackend *backend() const { return backend_.get(); }

    // S_t at step size h, scaled by (10) when `scaled`. C and K may be null (neglected);
    // J_low, when given, is the lower-left block in place of J (SaddleBlocks).
    bool factorize_step(const ModelMatrix &M, const ModelMatrix *C, const ModelMatrix *K,
                        const ModelMatrix &J, const Params &p, double h, bool scaled,
                        const ModelMatrix *J_low = nullptr);
    // [sigma M, Phi_q^T; Phi_q, 0] (sigma balances the blocks; see init.cpp).
    bool factorize_kkt(const ModelMatrix &M, double sigma, const ModelMatrix &J);
    // [I, Phi_q^T; Phi_q, 0]: minimum-norm corrections.
    bool factorize_projection(const ModelMatrix &J);

    // Solves S [x1; x2] = -[r1; r2] (r2 of inactive constraints taken as 0, so their x2 is 0).
    // For the scaled step matrix this is eq. (9):
    // S_bar x_bar = -D_L r, x = D_R x_bar, i.e. x1 = dq and x2 = dlambda in natural units.
    // row_scale is beta h^2 of the step being solved (the factorization may be older).
    void solve(const Vec &r1, const Vec &r2, Vec &x1, Vec &x2, double row_scale = 1.0);

    double rcond() const { return backend_ ? backend_->rcond() : 0.0; }
    // The next factorization picks its pivots afresh (LinearBackend::forget_pivots).
    void forget_pivots()
    {
        if (backend_)
            backend_->forget_pivots();
    }
    // LinearBackend::save_pivots etc.; a matrix not set up keeps nothing
    void save_pivots(double *out) const
    {
        if (backend_)
            backend_->save_pivots(out);
    }
    bool pivots_loadable(const double *in) const
    {
        return backend_ ? backend_->pivots_loadable(in) : pivot_block_header_ok(in);
    }
    void load_pivots(const double *in)
    {
        if (backend_)
            backend_->load_pivots(in);
    }
    // LinearBackend::reserve_factors
    void reserve_factors()
    {
        if (backend_)
            backend_->reserve_factors();
    }

private:
    int n_ = 0, m_ = 0;
    std::unique_ptr<LinearBackend> backend_;
    const unsigned char *active_ = nullptr;
    Vec rhs_;
};

// beta h^2: the row scaling of eq. (10) at step size h (1 when unscaled).
inline double step_row_scale(const Params &p, double h, bool scaled)
{
    return scaled ? p.beta * h * h : 1.0;
}

}  // namespace ga
