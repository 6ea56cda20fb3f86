#include "iteration_matrix.hpp"

namespace ga {

void IterationMatrix::setup(std::unique_ptr<LinearBackend> backend, int n, int m,
                            const ModelMatrix &M, const ModelMatrix &J, const ModelMatrix &K,
                            const ModelMatrix &C, const unsigned char *active,
                            const ModelMatrix *J_low)
{
    n_ = n;
    m_ = m;
    active_ = active;
    rhs_.setZero(n + m);
    backend->setup(n, m, M, J, K, C, active != nullptr, J_low);
    backend_ = std::move(backend);
}

bool IterationMatrix::factorize_step(const ModelMatrix &M, const ModelMatrix *C,
                                     const ModelMatrix *K, const ModelMatrix &J, const Params &p,
                                     double h, bool scaled, const ModelMatrix *J_low)
{
    SaddleBlocks b;
    b.M = &M;
    b.C = C;
    b.K = K;
    b.J = &J;
    b.J_low = J_low;
    b.active = active_;
    if (scaled) {
        // D_L S_t D_R with D_L = diag(beta h^2 I, I), D_R = diag(I, I/(beta h^2)) (eq. 10):
        // the first block row is multiplied by beta h^2, the Phi_q^T block by
        // beta h^2 / (beta h^2) = 1, so every block is O(1) as h -> 0.
        b.cM = (1.0 - p.alpha_m) / (1.0 - p.alpha_f);  // beta h^2 * beta'
        b.cC = p.gamma * h;                            // beta h^2 * gamma'
        b.cK = p.beta * h * h;                         // beta h^2 * 1
    } else {
        const NewtonCoefficients c = newton_coefficients(p, h);
        b.cM = c.beta_prime;
        b.cC = c.gamma_prime;
        b.cK = 1.0;
    }
    return backend_->factorize(b);
}

bool IterationMatrix::factorize_kkt(const ModelMatrix &M, double sigma, const ModelMatrix &J)
{
    SaddleBlocks b;
    b.M = &M;
    b.cM = sigma;
    b.J = &J;
    b.active = active_;
    return backend_->factorize(b);
}

bool IterationMatrix::factorize_projection(const ModelMatrix &J)
{
    SaddleBlocks b;  // M = null: identity
    b.J = &J;
    b.active = active_;
    return backend_->factorize(b);
}

void IterationMatrix::solve(const Vec &r1, const Vec &r2, Vec &x1, Vec &x2, double row_scale)
{
    // D_L r in, D_R x_bar out, straight from and into the caller's vectors where the backend
    // can (the sparse LU): no pass over an n + m vector each way
    if (!active_ && backend_->solve_blocks(r1, -row_scale, r2, -1.0, x1, x2, row_scale))
        return;
    rhs_.head(n_) = -row_scale * r1;  // D_L r
    if (m_ > 0) {
        rhs_.tail(m_) = -r2;
        if (active_)
            for (int i = 0; i < m_; ++i)
                if (!active_[i])
                    rhs_[n_ + i] = 0.0;
    }
    backend_->solve(rhs_);
    x1 = rhs_.head(n_);
    if (m_ > 0)
        x2 = rhs_.tail(m_) / row_scale;  // D_R x_bar
}

}  // namespace ga
