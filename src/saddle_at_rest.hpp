// The model at rest (v = 0, qdd = 0) in the solver's layouts -- declared patterns stay
// sparse -- with a saddle-point factorization of its own, S = [cM M + cK K_t, Phi_q^T;
// Phi_q, 0], for the operating points of large models: the sparse static solve
// (static_saddle.cpp) and the modes nearest a shift (modes_near.cpp). Nothing dense n x n
// on the sparse path; the solver's matrices, scratch and factors stay as they were.
#pragma once

#include <memory>

#include "linear/backend.hpp"
#include "model.hpp"
#include "stepper.hpp"

namespace ga {

class SaddleAtRest {
public:
    // Layouts from the solver; the sparse backend when the solver takes it (or would at
    // setup) and K_t has a pattern, the dense one otherwise. Allocates; throws std::bad_alloc.
    SaddleAtRest(Stepper &kernel, double t);
    int n() const { return n_; }
    int m() const { return m_; }
    bool sparse() const { return sparse_; }
    Diagnostics &diag() { return kernel_.diag; }

    // Evaluations at q into the matrices below (and f, phi).
    ga_status force(const Vec &q);
    ga_status constraint(const Vec &q);
    ga_status jacobian(const Vec &q);
    ga_status mass(const Vec &q);
    // r = -f + Phi_q^T lambda from the f and Phi_q evaluated last (eq. 1 at rest)
    void residual(const Vec &lambda, Vec &r) const;
    // K_t at (q, lambda): the callback, or central differences of r grouped by K_t's pattern
    // (every column alone when it has none), on scratch of its own: f and Phi_q stay as they
    // were evaluated.
    ga_status stiffness(const Vec &q, const Vec &lambda);

    // S from the matrices as evaluated; false if it is singular.
    bool factorize(double cM, double cK);
    // [x; mu] = S^-1 [b; c] in place (length n + m)
    void solve(Vec &rhs) { backend_->solve(rhs); }
    // lambda with [M, Phi_q^T; Phi_q, 0] [a; lambda] = [f; 0] (refactorizes S with M): at an
    // equilibrium a = 0 and lambda balances f; false if that matrix is singular.
    bool balancing_multipliers(Vec &lambda);

    double max_abs_f() const;
    double max_abs_stiffness() const;
    double max_abs_constraint_force(const Vec &lambda) const;  // |Phi_q^T lambda|_inf

    ModelMatrix M, J, K;
    Vec f, phi;

private:
    ga_status residual_at(const Vec &q, const Vec &lambda, Vec &r);
    Stepper &kernel_;
    Model &model_;
    double t_;
    int n_, m_;
    bool sparse_ = false;
    Vec zero_, rp_, rm_, qq_, step_;
    ModelMatrix J_pert_;
    ColumnGroups groups_;
    std::unique_ptr<LinearBackend> backend_;
};

}  // namespace ga
