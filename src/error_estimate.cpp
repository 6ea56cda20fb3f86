// Adaptive mode's local error estimate of a step (docs/algorithms.md sec. 1), against the
// step-size controller's tolerances; the adaptive loop is the transaction's (transaction.cpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "stepper.hpp"

namespace ga {

namespace {
const double kEps = std::numeric_limits<double>::epsilon();
// How far the index-3 estimate from a may lie above the one from consistent accelerations
// before it counts: a's benign oscillation along the constraints (sec. 1.5c) stays below.
constexpr double kTransientAllowance = 10.0;
constexpr double kRoundoffUlps = 64.0;
// The index-3 estimate solves with the step's own factorization where it was made within this
// relative distance of q_{n+1}: 1e-3 halved Andrews' factorizations and left its steps as they
// were; 1e-2 cost it 13 % more steps (measured: design-notes.md, "The cost of the index-3
// estimate").
constexpr double kFactorizedNearby = 1e-3;

// The constants of (a) and (b): e_q = c_q (a_{n+1} - a_n), e_v = c_v h^3 qddd'
struct EstimateCoefficients {
    double cq, cv;
};
EstimateCoefficients estimate_coefficients(const Params &p, double h)
{
    const double da = p.alpha_m - p.alpha_f;
    return {h * h * (p.beta + 0.5 * da - 1.0 / 6.0),
            1.0 / 12.0 - da * da + da * (p.alpha_m - 0.5)};
}

}  // namespace

// Index 3 with constraints and a multiplier transient damped at least as fast as at the default
// rho_inf = 0.9 (its double root -alpha_f / (1 - alpha_f), sec. 1.4): the error estimate
// differences consistent accelerations. Closer to 1 the transient, amplified up to about
// 1 / (e (1 - rho_inf)) by the double root, moves q and v by more than the smooth estimate
// sees, and differences of a, which carry it, keep the error at the tolerance
// (design-notes.md, "Tolerance proportionality").
bool Stepper::consistent_estimate() const
{
    constexpr double kMaxRoot = 0.9;
    const double alpha_f = params.alpha_f;
    return formulation == GA_INDEX3 && m_ > 0 && alpha_f <= kMaxRoot * (1.0 - alpha_f) * (1.0 + 1e-12);
}

// Weighted RMS norm of the local error estimates of the step just computed (trial_ from
// accepted_ with a_n), over positions and velocities; multipliers are not part of it, as in
// index-aware DAE codes (sec. 1.5d).
//   positions (sec. 1.5a): e_q = h^2 (beta + delta_alpha/2 - 1/6) (a_{n+1} - a_n)
//   velocities (sec. 1.5b): e_v = C_v h^3 qdddd with C_v = 1/12 - delta_alpha^2
//       + delta_alpha (alpha_m - 1/2), qdddd from the divided differences of a over the last
//       two steps (not available in the first step, where e_v = 0)
// With constraints both estimates are projected onto the tangent space of the constraints,
// null(Phi_q), along the directions constraint forces act in, M^-1 Phi_q^T (the M-orthogonal
// projection): exact and numerical solution both satisfy the constraints, so their difference
// has no such component to leading order.
// In index 3 the differences are those of the accelerations consistent with each step's
// (q, v) instead of a (sec. 1.5c): a carries, besides the multipliers' transient after every
// change of h, a step-to-step oscillation along the constraints that the projection does not
// remove and that made index-3 steps three times shorter than index-2 ones for the same error.
// But the transient, grown by changes of h, also moves q and v where c does not see it: the
// error is the larger of the estimate from c and a tenth of that from a (sec. 1.5c).
ga_status Stepper::error_norm(double h, double t_end, const StepController &control,
                             double &err)
{
    const Params &p = params;
    const State &s = accepted_;
    State &x = trial_;
    const auto [cq, cv] = estimate_coefficients(p, h);
    Vec &eq = dq_, &ev = dw_;  // scratch
    if (consistent_estimate()) {
        output_for_ = -1;
        estimate_is_output_ = false;
        // ... where its Phi_q is that of q_{n+1} closely enough: a matrix kept from earlier
        // steps projects onto the null space of an older Phi_q, and Andrews' mechanism (1e3
        // rad/s) then took 13 % more steps with its accelerations' errors spread 6 times wider
        // over the tolerances (docs/design-notes.md).
        double moved = 0.0;
        for (int i = 0; i < nv_ && jacobian_valid_; ++i)
            moved = std::max(moved, model.space.distance(x.q, recipe_.q, i) /
                                        (model.space.magnitude(x.q, i) + 1.0));
        if (jacobian_valid_ && moved <= kFactorizedNearby) {
            // With the step's own factorization (the accelerations need only be consistent
            // to the estimate's accuracy): the step's qdd corrected onto the acceleration-level
            // constraint along S_11^-1 Phi_q^T, S_11 = beta' M + gamma' C_t + K_t ~ beta' M,
            // instead of a saddle-point matrix of M factorized for it at every step (a third
            // of an adaptive run's work on the slider-crank: design-notes.md, "The cost of
            // the index-3 estimate").
            if (auto st = model.constraint_accel(t_end, x.q, x.v, c_)) {
                diag.append(" (consistent accelerations for the error estimate at t = %.17g)",
                            t_end);
                return st;
            }
            J_.multiply_add(1.0, x.qdd, c_);  // Phi_q qdd + the acceleration term
            rq_.setZero();
            S_.solve(rq_, c_, guard_q_, lambda_tmp_, step_row_scale(p, h, scaling));
            x.c = x.qdd + guard_q_;
        } else {
            // Into the output's workspace: when the step is accepted they are its output.
            const Vec *y_before = model.y_now;
            model.y_now = &x.y;
            const ga_status st = consistent_output(t_end, x.q, x.v, "the error estimate");
            model.y_now = y_before;
            if (st)
                return st;
            x.c = out_qdd_;
            estimate_is_output_ = true;
        }
        x.c_prev = s.c;
        x.c_dt = h;
        const bool sliver = x.sliver_span > 0.0;  // too close to difference twice
        x.c_count = sliver ? 1 : std::min(s.c_count + 1, 2);
        if (s.c_count >= 1)
            eq = cq * (x.c - s.c);
        else  // after a fixed step: no consistent accelerations at its start
            eq = cq * (x.a - *a_start_);
        if (s.c_count >= 2 && !sliver)
            ev = (cv * h * h * h / (0.5 * (h + s.c_dt))) *
                 ((x.c - s.c) / h - (s.c - s.c_prev) / s.c_dt);
        else
            ev.setZero();
        // The same from a (below): a transient of the multipliers that grows with each
        // change of h moves q and v unseen by c; it shows in a (sec. 1.5c).
        Vec &gq = guard_q_, &gv = guard_v_;
        estimate_from_a(h, gq, gv);
        // Index-3 a is known only to eps |q| / (beta h^2) (paper sec. 3.3; 64 ulps, as the
        // Newton test's floors): what the estimate from a makes of that round-off widens its
        // weights (as atol does; subtracted instead, the error jumped between 0 and O(1) and
        // the predictive controller shrank the steps without end).
        const double q_max =
            std::max(model.space.max_magnitude(s.q), model.space.max_magnitude(x.q));
        const auto a_noise = [&](double step) {
            return kRoundoffUlps * kEps * q_max / (p.beta * step * step);
        };
        const double noise_q = std::fabs(cq) * 2.0 * a_noise(h);
        const double noise_v = s.h_last > 0.0 ? std::fabs(cv) * h * h * h / (0.5 * (h + s.h_last)) *
                                                    2.0 * (a_noise(h) / h + a_noise(s.h_last) / s.h_last)
                                              : 0.0;
        // After a Newton iteration that diverged before it converged, the projection's
        // premise (both solutions on the constraints, and close) may not hold: it can end at
        // another root, and index 3 leaves v free of the velocity constraint (a long chain's
        // link turned by whole turns at 2e6 rad/s passed the projected estimate). Then the
        // estimate from a counts unprojected too.
        const double err_unprojected =
            convergence_.diverged()
                ? weighted_error_norm(s, x, gq, gv, h, control, noise_q, noise_v)
                : 0.0;
        if (!estimate_is_output_) {
            // Onto null(Phi_q) with the step's factorization too: e - x with
            // S [x; y] = [0; Phi_q e] (along S_11^-1 Phi_q^T, as above)
            for (Vec *e : {&eq, &ev, &gq, &gv}) {
                rq_.setZero();
                phi_.setZero();
                J_.multiply_add(-1.0, *e, phi_);
                S_.solve(rq_, phi_, qdd_tmp_, lambda_tmp_, step_row_scale(p, h, scaling));
                *e -= qdd_tmp_;
            }
        } else {
            // The projection with O_, factorized at the step's end for the accelerations:
            // [sigma M Phi_q^T; Phi_q 0] [x; y] = [sigma M e; 0]
            for (Vec *e : {&eq, &ev, &gq, &gv}) {
                rq_.setZero();
                out_M_.multiply_add(-out_sigma_, *e, rq_);
                phi_.setZero();
                O_.solve(rq_, phi_, *e, lambda_tmp_);
            }
        }
        const double err_a =
            std::max(err_unprojected,
                     weighted_error_norm(s, x, gq, gv, h, control, noise_q, noise_v));
        err = std::max(weighted_error_norm(s, x, eq, ev, h, control), err_a / kTransientAllowance);
        return GA_OK;
    }
    estimate_from_a(h, eq, ev);
    if (m_ > 0 && P_.ready()) {
        count(counters, GA_COUNT_FACTORIZATIONS);  // counted like every other
        if (P_.factorize_kkt(M_, 1.0, J_))
            for (Vec *e : {&eq, &ev}) {
                // [M Phi_q^T; Phi_q 0] [x; y] = [M e; 0]: x = e - M^-1 Phi_q^T y, Phi_q x = 0
                rq_.setZero();
                M_.multiply_add(-1.0, *e, rq_);
                phi_.setZero();
                P_.solve(rq_, phi_, *e, lambda_tmp_);
            }
    }
    err = weighted_error_norm(s, x, eq, ev, h, control);
    return GA_OK;
}

void Stepper::estimate_from_a(double h, Vec &e_q, Vec &e_v) const
{
    const State &s = accepted_, &x = trial_;
    const auto [cq, cv] = estimate_coefficients(params, h);
    const Vec &a_n = *a_start_;
    e_q = cq * (x.a - a_n);
    if (s.h_last > 0.0)
        e_v = (cv * h * h * h / (0.5 * (h + s.h_last))) *
              ((x.a - a_n) / h - (s.a - s.a_prev) / s.h_last);
    else
        e_v.setZero();
}

double Stepper::weighted_error_norm(const State &s, const State &x, const Vec &eq,
                                    const Vec &ev, double h, const StepController &control,
                                    double noise_q, double noise_v)
{
    const double rtol = control.rtol;
    const double scale = control.calibration();
    double sum = 0.0;
    for (int i = 0; i < nv_; ++i) {
        const double wq =
            scale * (control.atol_q(i) + rtol * std::max(model.space.magnitude(s.q, i),
                                            model.space.magnitude(x.q, i))) +
            noise_q;
        const double wv =
            scale * (control.atol_v(i) + rtol * std::max(std::fabs(s.v[i]), std::fabs(x.v[i]))) +
            noise_v;
        sum += (eq[i] / wq) * (eq[i] / wq) + (ev[i] / wv) * (ev[i] / wv);
    }
    if (r() > 0)
        return std::sqrt((sum + first_order_error_sum(h, scale, control)) / (2.0 * nv_ + r()));
    return std::sqrt(sum / (2.0 * nv_));
}

}  // namespace ga
