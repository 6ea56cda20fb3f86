// Consistent initial values (docs/algorithms.md sec. 3): positions and velocities onto the
// constraint manifold by minimum-norm corrections, then qdd0 and lambda0 from the
// saddle-point system with the acceleration-level constraint, and a0 = qdd0 (eq. 3).
#include <algorithm>
#include <cmath>
#include <limits>

#include "redundancy.hpp"
#include "stepper.hpp"

namespace ga {

namespace {
constexpr int kMaxProjectionIterations = 50;
const double kEps = std::numeric_limits<double>::epsilon();

// Largest |entry| in the rows whose flag is set (all rows when active is null): a constraint
// dropped as redundant takes no part in the scaling.
double max_abs(const ModelMatrix &A, const unsigned char *active = nullptr)
{
    if (!active)
        return A.size() ? Eigen::Map<const Vec>(A.data(), A.size()).cwiseAbs().maxCoeff() : 0.0;
    double m = 0.0;
    for (Eigen::Index k = 0; k < A.size(); ++k) {
        const int row = A.dense() ? static_cast<int>(k % A.rows()) : A.row_index()[k];
        if (active[row])
            m = std::max(m, std::fabs(A.data()[k]));
    }
    return m;
}

Eigen::Index argmax_abs(const Vec &x)
{
    Eigen::Index i = 0;
    if (x.size() > 0)
        x.cwiseAbs().maxCoeff(&i);
    return i;
}
}  // namespace

// A failed ga_init leaves the solver as it was, its state and the constraints in use included:
// GA_REDUNDANT_DROP selects them at the new q0 before the rest can fail, and the old state
// stepped on without a constraint it needed (issue 17).
ga_status Stepper::init(double t0, const double *q0, const double *v0)
{
    if (r() > 0 && !initialized_)  // (r is fixed once the solver is set up)
        return diag.fail(GA_ERR_STATE, "%d first-order states declared: the first start "
                         "needs their initial values (ga_init_y)", r());
    return undoing_a_first_setup([&] {
        if (auto st = setup())
            return st;
        trial_.y = accepted_.y;  // a restart keeps the first-order states it holds
        const std::vector<unsigned char> active_before = active_;
        const ga_status st = start(t0, q0, v0);
        if (st)
            restore_active(active_before);
        return st;
    });
}

ga_status Stepper::init_y(double t0, const double *q0, const double *v0, const double *y0)
{
    return undoing_a_first_setup([&] {
        if (auto st = setup())
            return st;
        trial_.y = Eigen::Map<const Vec>(y0, r());
        if (!all_finite(trial_.y))
            return diag.fail(GA_ERR_ARG, "y0 contains NaN or Inf");
        const std::vector<unsigned char> active_before = active_;
        const ga_status st = start(t0, q0, v0);
        if (st)
            restore_active(active_before);
        return st;
    });
}

// Puts back the constraints in use (in place: the linear algebra holds their address).
void Stepper::restore_active(const std::vector<unsigned char> &before)
{
    if (before != active_) {
        std::copy(before.begin(), before.end(), active_.begin());
        invalidate_jacobian();  // the matrices' active rows change back
    }
}

ga_status Stepper::start(double t0, const double *q0, const double *v0)
{
    // The arguments first: a refused restart leaves the kept matrix and pivots as they were.
    if (!all_finite(q0, nq_) || !all_finite(v0, nv_))
        return diag.fail(GA_ERR_ARG, "q0 or v0 contains NaN or Inf");
    if (const Eigen::Index bad = model.space.invalid_rotation(q0); bad >= 0)
        return diag.fail(GA_ERR_ARG,
                         "q0[%ld..] is not a rotation (a unit quaternion, or an orthonormal "
                         "matrix with det 1, within 1e-6)",
                         static_cast<long>(bad));
    invalidate_jacobian();
    jacobian_valid_ = false;
    // A restart (after a jump in q or v) is a new solver with the same options and patterns:
    // no pivots from the run before, so that it repeats what a new solver does, bit for bit.
    forget_pivots();
    State &x = trial_;
    x.t = t0;
    x.h_last = 0.0;
    x.sliver_span = 0.0;
    x.q = Eigen::Map<const Vec>(q0, nq_);
    x.v = Eigen::Map<const Vec>(v0, nv_);
    if (!model.space.euclidean())
        model.space.normalize_rotations(x.q.data(), ConfigurationSpace::kInitExact);

    if (redundancy == GA_REDUNDANT_DROP && m_ > 0)
        if (auto st = select_active_constraints(t0, x.q))
            return st;
    if (m_ > 0) {
        if (auto st = project_positions(t0, x.q))
            return st;
        if (auto st = project_velocities(t0, x.q, x.v))
            return st;
    }

    if (r() > 0)
        model.y_now = &x.y;  // start() callers put y0 into trial_.y
    if (auto st = doors_->on_start(x))  // first: differences leave the matrices at a perturbed p
        return st;
    if (auto st = consistent_accelerations(t0, x.q, x.v, x.qdd, x.lambda)) {
        diag.append(" (consistent initial accelerations at t0 = %.17g)", t0);
        return st;
    }
    if (r() > 0) {  // y'_0 = g(t0, q0, v0, y0); w_0 = y'_0 as a_0 = qdd_0
        if (auto st = model.rate(t0, x.q, x.v, x.y, x.ydot)) {
            diag.append(" (initial rates of the first-order states at t0 = %.17g)", t0);
            return st;
        }
        x.w = x.ydot;
        x.w_prev = x.w;
    }
    x.a = x.qdd;  // eq. (3): a_0 = qdd_0
    x.a_prev = x.a;
    x.c = x.qdd;
    x.c_count = 1;

    accepted_.swap(trial_);
    doors_->on_started();
    ++state_id_;
    initialized_ = true;
    previous_valid_ = false;
    start_pending_ = true;  // corrected starting values need the h of the first step
    if (formulation == GA_INDEX2_STABILIZED)
        prefactor_index2();
    return GA_OK;
}

// [M Phi_q^T; Phi_q 0] [qdd; lambda] = [f; -(Phi_qq(v,v) + 2 Phi_qt v + Phi_tt)] at (t, q, v),
// with the step's matrix S_ and scratch. Leaves M_, f_, J_ at q.
ga_status Stepper::consistent_accelerations(double t, const Vec &q, const Vec &v, Vec &qdd,
                                           Vec &lambda)
{
    SaddleWorkspace w{S_, M_, J_, f_, c_, rq_};
    w.mass_given = model.constant_mass && mass_valid_;  // evaluated once (evaluate_mass)
    const ga_status st = acceleration_level(t, q, v, w, qdd, lambda);
    jacobian_valid_ = false;  // S_ holds another matrix now
    if (w.mass_evaluated)
        mass_valid_ = model.constant_mass;
    if (st == GA_ERR_SINGULAR)
        explain_singular_saddle_point();
    return st;
}

// The saddle-point solve of the consistent start and of consistent output (docs/algorithms.md
// sec. 3.3, 8) in the workspace w. The first block row is multiplied by
// sigma = max|Phi_q| / max|M| (active constraints) so that both blocks have the same size;
// the unknown in the second block is then sigma lambda.
ga_status Stepper::acceleration_level(double t, const Vec &q, const Vec &v, SaddleWorkspace &w,
                                     Vec &qdd, Vec &lambda)
{
    ga_status st = GA_OK;
    if (!w.mass_given) {
        st = model.mass(t, q, w.M);
        w.mass_evaluated = !st;
    }
    if (!st)
        st = model.force(t, q, v, w.f);
    if (!st)
        st = model.jacobian(t, q, w.J);
    if (!st)
        st = model.constraint_accel(t, q, v, w.c);
    if (st)
        return st;
    if (m_ == 0 && w.M.diagonal()) {
        // M qdd = f with M diagonal: no factorization (the sparse path's saddle-point matrix
        // has the pattern of the step's, a lattice's K_t and its fill: most of its ga_init)
        qdd.setZero();
        const std::vector<int> &rows = w.M.row_index();
        for (int k = 0; k < w.M.nnz(); ++k)  // (repeated entries add up)
            qdd[rows[k]] += w.M.data()[k];
        for (int i = 0; i < nv_; ++i) {
            if (!(qdd[i] != 0.0))
                return diag.fail(GA_ERR_SINGULAR,
                                 "the mass matrix M (diagonal) is singular at t = %.17g: "
                                 "M[%d][%d] = %g",
                                 t, i, i, qdd[i]);
            qdd[i] = w.f[i] / qdd[i];
        }
        w.sigma = 1.0;
        if (!all_finite(qdd))
            return diag.fail(GA_ERR_NONFINITE,
                             "consistent accelerations are not finite at t = %.17g", t);
        return GA_OK;
    }
    double sigma = 1.0;
    const double mmax = max_abs(w.M), jmax = max_abs(w.J, active_ptr());
    if (mmax > 0.0 && jmax > 0.0)
        sigma = jmax / mmax;
    count(counters, GA_COUNT_FACTORIZATIONS);
    if (!w.K.factorize_kkt(w.M, sigma, w.J))
        return diag.fail(GA_ERR_SINGULAR,
                         "saddle-point matrix [M Phi_q^T; Phi_q 0] is singular at t = %.17g "
                         "(rcond = %.3g)",
                         t, w.K.rcond());
    w.sigma = sigma;
    w.r = -sigma * w.f;
    w.K.solve(w.r, w.c, qdd, lambda);
    if (m_ > 0)
        lambda /= sigma;
    if (!all_finite(qdd) || !all_finite(lambda))
        return diag.fail(GA_ERR_NONFINITE, "consistent accelerations or multipliers are not "
                         "finite at t = %.17g", t);
    return GA_OK;
}

// GA_REDUNDANT_DROP: the constraints that depend on the ones before them are dropped
// (redundancy.hpp).
ga_status Stepper::select_active_constraints(double t, const Vec &q)
{
    if (auto st = model.jacobian(t, q, J_))
        return st;
    if (independent_in_order(J_, nv_, m_, active_.data()) < 0)
        return diag.fail(GA_ERR_ARG,
                         "dropping redundant constraints of a dense Phi_q takes a dense "
                         "Gram-Schmidt, and n m = %.0f is too large for it (declare the "
                         "pattern of Phi_q)",
                         static_cast<double>(nv_) * m_);
    invalidate_jacobian();  // the matrices change with the set of active constraints
    return GA_OK;
}

// Why [M Phi_q^T; Phi_q 0] is singular, appended to the message: either Phi_q has lower rank
// than m (redundant constraints: the ones that depend on the constraints before them are
// named -- those GA_REDUNDANT_DROP would drop), or M is singular on the null space of Phi_q
// (a massless coordinate that no constraint fixes). ga_init only (it allocates).
void Stepper::explain_singular_saddle_point()
{
    // A row of zeros is no redundancy to drop but a constraint degenerate at this q (the
    // square of a distance that is zero, a Jacobian callback that left the row out).
    Vec row_max = Vec::Zero(m_);
    for (Eigen::Index k = 0; k < J_.size(); ++k) {
        const int row = J_.dense() ? static_cast<int>(k % J_.rows()) : J_.row_index()[k];
        row_max[row] = std::max(row_max[row], std::fabs(J_.data()[k]));
    }
    for (int i = 0; i < m_; ++i)
        if (constraint_active(i) && row_max[i] == 0.0) {
            diag.append(": constraint %d has a zero gradient at this q (its row of Phi_q is "
                        "zero: ga_check_derivatives checks Phi_q against Phi)", i);
            return;
        }
    std::vector<unsigned char> independent(m_);
    const int rank = m_ > 0 ? independent_in_order(J_, nv_, m_, independent.data()) : -1;
    if (rank < 0) {
        diag.append(": redundant constraints, or M singular on the null space of Phi_q");
        return;
    }
    if (redundancy == GA_REDUNDANT_DROP) {  // the dependent ones are out of the matrix already
        diag.append(": with the %d redundant constraints dropped, M is singular on the null "
                    "space of Phi_q (a coordinate without mass that no constraint fixes)",
                    m_ - rank);
        return;
    }
    if (rank == m_) {
        diag.append(": Phi_q has full rank %d, so M is singular on the null space of Phi_q (a "
                    "coordinate without mass that no constraint fixes)",
                    m_);
        return;
    }
    constexpr int kListed = 8;
    diag.append(": Phi_q has rank %d < m = %d, redundant constraints (GA_REDUNDANT_DROP "
                "drops them); these depend on the ones before them:",
                rank, m_);
    for (int i = 0, listed = 0; i < m_ && listed < kListed; ++i)
        if (!independent[i]) {
            diag.append(" %d", i);
            ++listed;
        }
    if (m_ - rank > kListed)
        diag.append(" ... (%d in all)", m_ - rank);
}

// Corrected starting values for the first step of size h (docs/algorithms.md sec. 3.4-3.5):
// a_0 = qdd_0 + delta_alpha h qddd_0, with h qddd_0 from a central difference of consistent
// accelerations at t0 -+ h; in the index-3 formulation also v_0 + dv, the normal-direction
// velocity offset that lets the first step absorb its own position error
// l_0 = h^3 (1 - 6 beta - 3 delta_alpha)/6 qddd_0 instead of passing it to a_1 and lambda.
// Without them lambda carries an O(h) transient (index 3) or an O(delta_alpha h) one (index 2).
ga_status Stepper::starting_values(const State &from, double h)
{
    const State &s = from;
    const Params &p = params;
    const double delta_alpha = p.alpha_m - p.alpha_f;
    // h qddd_0 = (qdd(t0 + h) - qdd(t0 - h)) / 2 along the Taylor polynomial of the start
    State &x = trial_;  // scratch: the step has not started
    for (int side = 0; side < 2; ++side) {
        const double sh = side == 0 ? h : -h;
        model.space.taylor(s.q, s.v, *qdd_start_, sh, x.q);
        x.v = s.v + sh * *qdd_start_;
        if (r() > 0) {  // the forces at t0 -+ h see y there (to first order: see first_order.cpp)
            y_tmp_ = s.y + sh * s.ydot;
            model.y_now = &y_tmp_;
        }
        Vec &out = side == 0 ? x.a : x.a_prev;
        if (auto st = consistent_accelerations(s.t + sh, x.q, x.v, out, lambda_tmp_)) {
            diag.append(" (corrected starting values for the first step, h = %g)", h);
            return st;
        }
    }
    model.y_now = &s.y;
    qdd_tmp_ = 0.5 * (x.a - x.a_prev);  // h qddd_0
    a_n_ = *qdd_start_ + delta_alpha * qdd_tmp_;
    a_start_ = &a_n_;
    if (formulation == GA_INDEX3 && m_ > 0) {
        // [M Phi_q^T; Phi_q 0] [dv; dlambda] = [0; Phi_q l_0 / h] at the start
        if (auto st = consistent_accelerations(s.t, s.q, s.v, x.qdd, x.lambda))
            return st;
        dq_ = ((1.0 - 6.0 * p.beta - 3.0 * delta_alpha) / 6.0 * h) * qdd_tmp_;  // l_0 / h
        phi_.setZero();
        J_.multiply_add(-1.0, dq_, phi_);
        rq_.setZero();
        S_.solve(rq_, phi_, dw_, dlambda_);
        v_n_ = s.v + dw_;
        v_start_ = &v_n_;
    }
    return GA_OK;
}

ga_status Stepper::project_positions(double t, Vec &q)
{
    if (auto st = model.constraint(t, q, phi_))
        return st;
    double norm = phi_.lpNorm<Eigen::Infinity>();
    if (norm <= init_tol)
        return GA_OK;
    if (init_mode == GA_INIT_REFUSE)
        return diag.fail(GA_ERR_INCONSISTENT,
                         "q0 violates the constraints: |Phi(q0)|_inf = %.3g (constraint %ld) > "
                         "init_tol = %.3g, and projection is off (GA_INIT_REFUSE)",
                         norm, static_cast<long>(argmax_abs(phi_)), init_tol);
    // Gauss-Newton for the minimum-norm correction:
    // [I Phi_q^T; Phi_q 0] [dq; mu] = -[0; Phi], until round-off.
    const double norm0 = norm;
    rq_.setZero();
    for (int it = 0; it < kMaxProjectionIterations; ++it) {
        if (auto st = model.jacobian(t, q, J_))
            return st;
        count(counters, GA_COUNT_FACTORIZATIONS);
        if (!S_.factorize_projection(J_))
            return diag.fail(GA_ERR_SINGULAR,
                             "cannot project q0: Phi_q is rank deficient (rcond of "
                             "[I Phi_q^T; Phi_q 0] = %.3g) at projection iteration %d",
                             S_.rcond(), it + 1);
        S_.solve(rq_, phi_, dq_, dlambda_);
        model.space.increment(q, dq_);
        if (auto st = model.constraint(t, q, phi_))
            return st;
        const double previous = norm;
        norm = phi_.lpNorm<Eigen::Infinity>();
        if (!std::isfinite(norm) || norm > 1e6 * std::max(norm0, init_tol))
            break;  // diverging
        const bool roundoff = dq_.lpNorm<Eigen::Infinity>() <=
                              16.0 * kEps * std::max(model.space.max_magnitude(q), 1.0);
        if (norm <= init_tol && (norm == 0.0 || roundoff || norm > 0.5 * previous))
            return GA_OK;
    }
    return diag.fail(GA_ERR_INCONSISTENT,
                     "projection of q0 onto Phi(q, t0) = 0 failed: |Phi|_inf = %.3g after the "
                     "Gauss-Newton iterations (init_tol = %.3g, |Phi(q0)|_inf = %.3g)",
                     norm, init_tol, norm0);
}

// v <- v + dv, the minimum-norm correction with Phi_q v + Phi_t = 0, from J_ = Phi_q(q),
// c_ = Phi_t and phi_ = Phi_q v + Phi_t (linear: one correction, plus one pass of refinement
// for round-off). Leaves phi_ at the corrected v.
ga_status Stepper::correct_velocities(Vec &v, const char *what)
{
    count(counters, GA_COUNT_FACTORIZATIONS);
    if (!S_.factorize_projection(J_))
        return diag.fail(GA_ERR_SINGULAR,
                         "cannot project %s: Phi_q is rank deficient (rcond of "
                         "[I Phi_q^T; Phi_q 0] = %.3g)",
                         what, S_.rcond());
    jacobian_valid_ = false;  // S_ holds another matrix now
    rq_.setZero();
    for (int pass = 0; pass < 2; ++pass) {
        S_.solve(rq_, phi_, dq_, dlambda_);
        v += dq_;
        phi_ = c_;
        J_.multiply_add(1.0, v, phi_);
    }
    return GA_OK;
}

ga_status Stepper::project_velocities(double t, const Vec &q, Vec &v)
{
    // Velocity constraint w = Phi_q v + Phi_t.
    if (auto st = model.jacobian(t, q, J_))
        return st;
    if (auto st = model.constraint_dt(t, q, c_))
        return st;
    phi_ = c_;
    J_.multiply_add(1.0, v, phi_);
    const double norm0 = phi_.lpNorm<Eigen::Infinity>();
    if (norm0 <= init_tol)
        return GA_OK;
    if (init_mode == GA_INIT_REFUSE)
        return diag.fail(GA_ERR_INCONSISTENT,
                         "v0 violates the velocity constraints: |Phi_q v0 + Phi_t|_inf = %.3g "
                         "(constraint %ld) > init_tol = %.3g, and projection is off "
                         "(GA_INIT_REFUSE)",
                         norm0, static_cast<long>(argmax_abs(phi_)), init_tol);
    if (auto st = correct_velocities(v, "v0"))
        return st;
    const double norm = phi_.lpNorm<Eigen::Infinity>();
    if (!(norm <= init_tol))
        return diag.fail(GA_ERR_INCONSISTENT,
                         "projection of v0 failed: |Phi_q v + Phi_t|_inf = %.3g > init_tol = "
                         "%.3g",
                         norm, init_tol);
    return GA_OK;
}

}  // namespace ga
