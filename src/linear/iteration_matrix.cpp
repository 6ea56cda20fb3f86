#include "iteration_matrix.hpp"

namespace ga {

void IterationMatrix::allocate(int n, int m)
{
    n_ = n;
    m_ = m;
    S_.setZero(n + m, n + m);
    rhs_.setZero(n + m);
    lu_.allocate(n + m);
}

void IterationMatrix::set_constraint_blocks(const Mat &Phi_q)
{
    if (m_ == 0)
        return;
    S_.topRightCorner(n_, m_) = Phi_q.transpose();
    S_.bottomLeftCorner(m_, n_) = Phi_q;
    S_.bottomRightCorner(m_, m_).setZero();
}

bool IterationMatrix::factorize_step(const Mat &M, const Mat *C, const Mat *K, const Mat &Phi_q,
                                     const Params &p, double h, bool scaled)
{
    double cM, cC, cK;
    if (scaled) {
        // D_L S_t D_R with D_L = diag(beta h^2 I, I), D_R = diag(I, I/(beta h^2)) (eq. 10):
        // the first block row is multiplied by beta h^2, the Phi_q^T block by
        // beta h^2 / (beta h^2) = 1, so every block is O(1) as h -> 0.
        cM = (1.0 - p.alpha_m) / (1.0 - p.alpha_f);  // beta h^2 * beta'
        cC = p.gamma * h;                            // beta h^2 * gamma'
        cK = p.beta * h * h;                         // beta h^2 * 1
        row_scale_ = p.beta * h * h;
    } else {
        const NewtonCoefficients c = newton_coefficients(p, h);
        cM = c.beta_prime;
        cC = c.gamma_prime;
        cK = 1.0;
        row_scale_ = 1.0;
    }
    auto A = S_.topLeftCorner(n_, n_);
    A = cM * M;
    if (C)
        A += cC * (*C);
    if (K)
        A += cK * (*K);
    set_constraint_blocks(Phi_q);
    return lu_.factorize(S_);
}

bool IterationMatrix::factorize_kkt(const Mat &M, double sigma, const Mat &Phi_q)
{
    row_scale_ = 1.0;
    S_.topLeftCorner(n_, n_) = sigma * M;
    set_constraint_blocks(Phi_q);
    return lu_.factorize(S_);
}

bool IterationMatrix::factorize_projection(const Mat &Phi_q)
{
    row_scale_ = 1.0;
    S_.topLeftCorner(n_, n_).setIdentity();
    set_constraint_blocks(Phi_q);
    return lu_.factorize(S_);
}

void IterationMatrix::solve(const Vec &r1, const Vec &r2, Vec &x1, Vec &x2)
{
    rhs_.head(n_) = -row_scale_ * r1;  // D_L r
    if (m_ > 0)
        rhs_.tail(m_) = -r2;
    lu_.solve(rhs_);
    x1 = rhs_.head(n_);
    if (m_ > 0)
        x2 = rhs_.tail(m_) / row_scale_;  // D_R x_bar
}

}  // namespace ga
