// The iteration matrix of the stabilized index-2 formulation (ALGORITHMS.md sec. 2; Arnold &
// Hante 2017), in the scaling of eq. (10) extended to the extra multiplier. Unknowns
// (d, lambda_bar, eta_bar) = (dq, beta h^2 dlambda, h deta), with B = Phi_q(q_n):
//
//   [ cM M + gamma h C + beta h^2 K   Phi_q^T   (cM M + gamma h C) B^T ] [d         ]
//   [ Phi_q                           0         0                      ] [lambda_bar]
//   [ Phi_q                           0         Phi_q B^T              ] [eta_bar   ]
//
//   = -[ beta h^2 r^q ; Phi ; (beta h / gamma) (Phi_q v + Phi_t) ]
//
// (the curvature term d(Phi_q v)/dq of the third row is neglected, as gena does by default).
// Dense: (n + 2m)^2, Eigen LU.
#pragma once

#include <Eigen/LU>

#include "../matrix.hpp"
#include "../params.hpp"

namespace ga {

class Index2Matrix {
public:
    void setup(int n, int m);
    bool factorize(const ModelMatrix &M, const ModelMatrix *C, const ModelMatrix *K,
                   const ModelMatrix &J, const Mat &B, const Params &p, double h);
    // Solves for (d, dlambda, eta_bar) in natural units of d and lambda.
    void solve(const Vec &rq, const Vec &phi, const Vec &phi_v, const Params &p, double h,
               Vec &d, Vec &dlambda, Vec &eta_bar);
    double rcond() const { return pivot_ratio_; }

private:
    int n_ = 0, m_ = 0;
    Mat S_, A_;
    Eigen::PartialPivLU<Mat> lu_;
    Vec rhs_, x_;
    double pivot_ratio_ = 0.0;
};

}  // namespace ga
