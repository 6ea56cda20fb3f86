// What the solver reports besides its state: accelerations and multipliers consistent with
// (q, v) (docs/algorithms.md sec. 8), at the last accepted step or at any t inside it, and dense
// output of q and v over the last step.
//
// Index-3 multipliers and accelerations carry eps |q| / (beta h^2) of round-off (paper, sec.
// 3.3) and, in adaptive runs, a transient after every change of h (docs/algorithms.md sec. 1.4).
// Solved from the acceleration-level saddle-point system at the step's (q, v) they are as
// accurate as q and v. The solve has its own matrix and scratch: reading the output must not
// change what the next step reuses, so that a run does not depend on what was read.
#include <algorithm>
#include <cmath>

#include "stepper.hpp"

namespace ga {

void Stepper::setup_output()
{
    if (O_.ready() || !workspace_ready_)
        return;
    auto backend = sparse_backend_ ? make_sparse_backend() : make_dense_backend(DenseKind::Auto);
    backend->analysis_from(S_.backend());  // the same pattern: its ordering, not a second one
    setup_step_matrix(O_, std::move(backend));
    out_M_.copy_layout(M_);
    out_J_.copy_layout(J_);
    out_f_.setZero(nv_);
    out_c_.setZero(m_);
    out_r_.setZero(nv_);
    out_qdd_.setZero(nv_);
    out_lambda_.setZero(m_);
    O_.reserve_factors();
}

// qdd, lambda from the acceleration-level equations at (t, q, v) into out_qdd_, out_lambda_.
ga_status Stepper::consistent_output(double t, const Vec &q, const Vec &v, const char *purpose)
{
    if (!O_.ready())
        return diag.fail(GA_ERR_INTERNAL, "the workspace of consistent output was not set up");
    SaddleWorkspace w{O_, out_M_, out_J_, out_f_, out_c_, out_r_};
    if (model.constant_mass && mass_valid_ && !out_mass_valid_) {  // evaluated once for all
        Eigen::Map<Vec>(out_M_.data(), out_M_.size()) = Eigen::Map<const Vec>(M_.data(), M_.size());
        out_mass_valid_ = true;
    }
    w.mass_given = model.constant_mass && out_mass_valid_;
    const ga_status st = acceleration_level(t, q, v, w, out_qdd_, out_lambda_);
    out_sigma_ = w.sigma;
    if (w.mass_evaluated)
        out_mass_valid_ = model.constant_mass;
    if (st)
        diag.append(" (consistent accelerations and multipliers for %s at t = %.17g)", purpose, t);
    return st;
}

ga_status Stepper::output_state(double *qdd, double *lambda)
{
    const State &x = accepted_;
    if (output != GA_OUTPUT_CONSISTENT) {
        if (qdd)
            Eigen::Map<Vec>(qdd, nv_) = x.qdd;
        if (lambda && m_ > 0)
            Eigen::Map<Vec>(lambda, m_) = x.lambda;
        return GA_OK;
    }
    if (output_for_ != state_id_) {
        model.y_now = &x.y;
        if (auto st = consistent_output(x.t, x.q, x.v))
            return st;
        output_for_ = state_id_;
    }
    if (qdd)
        Eigen::Map<Vec>(qdd, nv_) = out_qdd_;
    if (lambda && m_ > 0)
        Eigen::Map<Vec>(lambda, m_) = out_lambda_;
    return GA_OK;
}

// Dense output (dense_output.hpp), with GA_OUTPUT_CONSISTENT's accelerations and multipliers
// solved at the interpolated (q, v).
ga_status Stepper::interpolate(double t, double *q, double *v, double *qdd, double *lambda)
{
    double th = 0.0, h = 0.0;
    if (auto st = dense_.place(t, th, h, diag))
        return st;
    const bool consistent = output == GA_OUTPUT_CONSISTENT && (qdd || (lambda && m_ > 0));
    if (consistent || q)
        dense_.positions(th, h, out_q_);
    if (consistent || v)
        dense_.velocities(th, h, out_v_);
    if (q)
        Eigen::Map<Vec>(q, nq_) = out_q_;
    if (v)
        Eigen::Map<Vec>(v, nv_) = out_v_;
    if (consistent) {
        if (r() > 0) {  // the forces at t see y there
            if (auto st = interpolate_y(t, out_y_.data(), nullptr))
                return st;
            model.y_now = &out_y_;
        }
        if (auto st = consistent_output(t, out_q_, out_v_))
            return st;
        output_for_ = -1;  // out_qdd_, out_lambda_ now hold values at t
        if (qdd)
            Eigen::Map<Vec>(qdd, nv_) = out_qdd_;
        if (lambda && m_ > 0)
            Eigen::Map<Vec>(lambda, m_) = out_lambda_;
        return GA_OK;
    }
    // the step's own values, linear over the step
    if (qdd)
        dense_.accelerations(th, qdd);
    if (lambda && m_ > 0)
        dense_.multipliers(th, lambda);
    return GA_OK;
}

}  // namespace ga
