#include "index2_matrix.hpp"

#include <limits>

namespace ga {

namespace {
void add_block(Eigen::Ref<Mat> target, double c, const ModelMatrix &A)
{
    if (A.dense()) {
        target += c * A.as_dense();
        return;
    }
    for (int k = 0; k < A.nnz(); ++k)
        target(A.row_index()[k], A.col_index()[k]) += c * A.data()[k];
}
}  // namespace

void Index2Matrix::setup(int n, int m)
{
    n_ = n;
    m_ = m;
    const int N = n + 2 * m;
    S_.setZero(N, N);
    A_.setZero(n, n);
    lu_ = Eigen::PartialPivLU<Mat>(N);
    rhs_.setZero(N);
    x_.setZero(N);
}

bool Index2Matrix::factorize(const ModelMatrix &M, const ModelMatrix *C, const ModelMatrix *K,
                             const ModelMatrix &J, const Mat &B, const Params &p, double h)
{
    const int n = n_, m = m_;
    const double cM = (1.0 - p.alpha_m) / (1.0 - p.alpha_f);
    S_.setZero();
    A_.setZero();
    add_block(A_, cM, M);  // cM M + gamma h C: also the block that multiplies B^T
    if (C)
        add_block(A_, p.gamma * h, *C);
    S_.block(0, n + m, n, m).noalias() = A_ * B.transpose();
    auto top_left = S_.topLeftCorner(n, n);
    top_left = A_;
    if (K)
        add_block(top_left, p.beta * h * h, *K);
    auto Jd = S_.block(n, 0, m, n);
    add_block(Jd, 1.0, J);
    S_.block(0, n, n, m) = Jd.transpose();
    S_.block(n + m, 0, m, n) = Jd;
    S_.block(n + m, n + m, m, m).noalias() = Jd * B.transpose();
    lu_.compute(S_);
    const auto U = lu_.matrixLU().diagonal().cwiseAbs();
    const double umax = U.maxCoeff();
    pivot_ratio_ = umax > 0.0 ? U.minCoeff() / umax : 0.0;
    return pivot_ratio_ >= (n + 2 * m) * std::numeric_limits<double>::epsilon();
}

void Index2Matrix::solve(const Vec &rq, const Vec &phi, const Vec &phi_v, const Params &p,
                         double h, Vec &d, Vec &dlambda, Vec &eta_bar)
{
    const int n = n_, m = m_;
    const double bh2 = p.beta * h * h;
    rhs_.head(n) = -bh2 * rq;
    rhs_.segment(n, m) = -phi;
    rhs_.tail(m) = -(p.beta * h / p.gamma) * phi_v;
    x_.noalias() = lu_.solve(rhs_);
    d = x_.head(n);
    dlambda = x_.segment(n, m) / bh2;
    eta_bar = x_.tail(m);
}

}  // namespace ga
