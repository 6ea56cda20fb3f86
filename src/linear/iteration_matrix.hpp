// The saddle-point matrices of galpha and their solution:
//  - the iteration matrix S_t = [beta' M + gamma' C_t + K_t, Phi_q^T; Phi_q, 0] of Algorithm 1,
//    optionally in the scaled form S_t_bar = D_L S_t D_R of eqs. (9)-(10);
//  - the matrices of the consistent start, [M Phi_q^T; Phi_q 0] and [I Phi_q^T; Phi_q 0].
#pragma once

#include "../params.hpp"
#include "dense_lu.hpp"

namespace ga {

class IterationMatrix {
public:
    void allocate(int n, int m);

    // S_t at step size h, scaled by (10) when `scaled`. C and K may be null (neglected).
    bool factorize_step(const Mat &M, const Mat *C, const Mat *K, const Mat &Phi_q,
                        const Params &p, double h, bool scaled);
    // [sigma M, Phi_q^T; Phi_q, 0] (sigma balances the blocks; see init.cpp).
    bool factorize_kkt(const Mat &M, double sigma, const Mat &Phi_q);
    // [I, Phi_q^T; Phi_q, 0]: minimum-norm corrections.
    bool factorize_projection(const Mat &Phi_q);

    // Solves S [x1; x2] = -[r1; r2]. For the scaled step matrix this is eq. (9):
    // S_bar x_bar = -D_L r, x = D_R x_bar, i.e. x1 = dq and x2 = dlambda in natural units.
    void solve(const Vec &r1, const Vec &r2, Vec &x1, Vec &x2);

    double rcond() const { return lu_.rcond(); }

private:
    void set_constraint_blocks(const Mat &Phi_q);

    int n_ = 0, m_ = 0;
    Mat S_;
    DenseLU lu_;
    Vec rhs_;
    double row_scale_ = 1.0;  // beta h^2 for the scaled step matrix, 1 otherwise
};

}  // namespace ga
