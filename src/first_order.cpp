// First-order states y' = g(t, q, v, y) in the step of Algorithm 1 (docs/algorithms.md sec. 9):
// the generalized-alpha of Jansen, Whiting and Hulbert in the paper's non-weighted form,
//     (1 - alpha_m1) w_{n+1} + alpha_m1 w_n = (1 - alpha_f1) y'_{n+1} + alpha_f1 y'_n,
//     y_{n+1} = y_n + h ((1 - gamma1) w_n + gamma1 w_{n+1}),   y'_{n+1} = g(t_{n+1}, ...),
// with y the Newton unknown beside q and lambda. The Newton system is solved by block
// elimination onto y (sec. 9, "Solve"): with the mechanical solve x = Sol(r) (S x = -r, the
// step's own, dense or sparse, either formulation) and its responses Z = Sol(f_y) to the
// columns of f_y, the r x r Schur complement C = c1 I - g_y + G Z (G x = g_q dq + gamma' g_v dw)
// gives dy = C^-1 (-r^y + G x0) and the mechanical update x0 - Z dy. The mechanical matrix,
// its scaling (eq. 10) and its factorization stay exactly as they are without the states.
#include <algorithm>
#include <cmath>
#include <limits>

#include "stepper.hpp"

namespace ga {

// Transactional: everything is allocated before anything changes.
void Stepper::set_first_order(int r)
{
    State fresh[3];
    for (State &x : fresh)
        x.allocate_first_order(r);
    Vec recipe_y = Vec::Zero(r), recipe_ydot = Vec::Zero(r), out_y = Vec::Zero(r);
    State *states[3] = {&accepted_, &trial_, &previous_};
    for (int k = 0; k < 3; ++k) {
        states[k]->y.swap(fresh[k].y);
        states[k]->ydot.swap(fresh[k].ydot);
        states[k]->w.swap(fresh[k].w);
        states[k]->w_prev.swap(fresh[k].w_prev);
    }
    recipe_.y.swap(recipe_y);
    recipe_.ydot.swap(recipe_ydot);
    out_y_.swap(out_y);
    model.set_first_order_count(r);
    invalidate_jacobian();
}

// The w (and y') the step starts from, as a_n (and qdd_n) for q: after a fresh start those of
// first_order_starting_values; after a change of h, w_n rescaled to the new h,
// w_n <- y'_n + (h / h_last) (w_n - y'_n), as a_n is (sec. 1.2).
void Stepper::first_order_start(const State &from, double h)
{
    const State &s = from;
    w_start_ = &s.w;
    ydot_start_ = &s.ydot;
    if (fresh_start_) {
        w_start_ = &w_n_;  // first_order_starting_values filled them
        ydot_start_ = &ydot_n_;
    } else if (rescale_a && s.h_last > 0.0 && h != s.h_last) {
        w_n_ = s.ydot + (h / s.h_last) * (s.w - s.ydot);
        w_start_ = &w_n_;
    }
}

// The start of a fresh step's recursion for y. h y''_0 by a central difference of g along the
// Taylor polynomial of the start at t0 -+ h (the h^2 y''_0 / 2 left out of y cancels in the
// difference); w_0 = y'_0 + delta h y''_0 with the corrected start (sec. 9), y'_0 without.
// A state whose rate changes by more than itself within the step, |h y''_0| > |y'_0|, does not
// follow its start over the step -- a stiff one off its equilibrium, tau' = (u - tau) / T with
// h / T = 1e4: its y'_0 = 6 / T carried into the step put tau 3 755 off -- and starts the
// recursion from rest instead, w_0 = y'_0 = 0 in the step: its first step is then implicit in
// y' alone, monotone, and what it drops, h |y'_0| < h^2 |y''_0|, is within the step's local
// error where y is smooth (sec. 9, "Stiff start"). Rates that overflow along the polynomial
// (a stiff nonlinear g) count as such for every state. Fixed steps only: an adaptive step's
// error control shrinks h until the start is followed. qdd_start_ is the start's qdd.
ga_status Stepper::first_order_starting_values(const State &from, double h)
{
    const State &s = from;
    State &x = trial_;  // scratch: the step has not started
    bool overflow = false;
    for (int side = 0; side < 2 && !overflow; ++side) {
        const double sh = side == 0 ? h : -h;
        model.space.taylor(s.q, s.v, *qdd_start_, sh, x.q);
        x.v = s.v + sh * *qdd_start_;
        x.y = s.y + sh * s.ydot;
        Vec &out = side == 0 ? gx_ : dy_;
        if (auto st = model.rate(s.t + sh, x.q, x.v, x.y, out)) {
            if (st == GA_ERR_NONFINITE && all_finite(x.y)) {
                overflow = true;
                diag.clear();
                continue;
            }
            diag.append(" (starting values of the first-order states, h = %g)", h);
            return st;
        }
    }
    const double delta = params1.alpha_m - params1.alpha_f;
    for (int k = 0; k < r(); ++k) {
        const double h_ydd = overflow ? 0.0 : 0.5 * (gx_[k] - dy_[k]);  // h y''_0
        // (adaptive steps resolve such a start by their error control instead)
        const bool follows =
            adaptive_attempt_ || (!overflow && !(std::fabs(h_ydd) > std::fabs(s.ydot[k])));
        ydot_n_[k] = follows ? s.ydot[k] : 0.0;
        w_n_[k] = !follows ? 0.0 : corrected_start ? s.ydot[k] + delta * h_ydd : s.ydot[k];
    }
    return GA_OK;
}

// Predictor: w_{n+1} = w_n, so that y'_{n+1} = (w_n - alpha_f1 y'_n) / (1 - alpha_f1) and
// y_{n+1} = y_n + h w_n (the ConstantA predictor of q).
void Stepper::predict_first_order(double h)
{
    const State &s = accepted_;
    State &x = trial_;
    const FirstOrderParams &p = params1;
    const Vec &w_n = *w_start_;
    x.ydot = (w_n - p.alpha_f * *ydot_start_) / (1.0 - p.alpha_f);
    x.y = s.y + h * w_n;
}

// The coupling blocks at the iterate x where the iteration matrix is built (f_, rate_ from the
// residual there); the Schur complement follows at the first solve with that matrix.
ga_status Stepper::first_order_matrix(double t, const State &x, bool central)
{
    if (auto st = model.coupling(t, x.q, x.v, x.y, f_, rate_, blocks_, central))
        return st;
    if (!model.space.euclidean()) {
        // Newton's dq moves q by T(xi) dq (sec. 14): g_q T for the matrix and G x; at the
        // accepted state xi = 0
        g_q_step_ = blocks_.g_q;
        if (&x == &trial_)
            model.space.right_multiply_tangent(xi_, g_q_step_.data(), r(), r());
    }
    schur_valid_ = false;
    return GA_OK;
}

// G x = g_q x_q + gamma' g_v x_w into out (r), with g_q (T on a group) as the step sees it.
namespace {
void apply_G(const Mat &g_q, const Mat &g_v, double gamma_prime, const Vec &xq, const Vec &xw,
             Vec &out)
{
    out.noalias() = g_q * xq;
    out.noalias() += gamma_prime * (g_v * xw);
}
}  // namespace

// Z = Sol(f_y) column by column with the mechanical solve of this step (as kept: the kept
// factorization, the row scale of h, in index 2 this step's B), C = c1 I - g_y + G Z and its LU.
// Without coupling_exact, Z = 0 and G = 0: C = c1 I - g_y. Also the norms of C^-1 g_q, C^-1 g_v
// for the convergence test's scale of y.
ga_status Stepper::first_order_schur(double h, const NewtonCoefficients &c)
{
    const int r1 = r();
    const bool index2 = formulation == GA_INDEX2_STABILIZED;
    const double c1 = first_order_newton_coefficient(params1, h);
    C1_ = -blocks_.g_y;
    C1_.diagonal().array() += c1;
    for (int k = 0; k < r1 && forces_see_y(); ++k) {
        z_rhs_ = blocks_.f_y.col(k);
        if (index2)
            S2_.solve(z_rhs_, z_zero_, z_zero_, params, h, B_, z_d_, z_w_, z_l_, z_e_);
        else
            S_.solve(z_rhs_, z_zero_, z_d_, z_l_, step_row_scale(params, h, scaling));
        Zq_.col(k) = z_d_;
        Zw_.col(k) = index2 ? z_w_ : z_d_;
        Zl_.col(k) = z_l_;
        if (index2)
            Ze_.col(k) = z_e_;
        apply_G(coupling_q_step(), blocks_.g_v, c.gamma_prime, z_d_, index2 ? z_w_ : z_d_, z_y_);
        C1_.col(k) += z_y_;
    }
    C1_lu_.compute(C1_);
    // The pivots' spread as the test of singularity: Eigen's rcond() allocates.
    const auto pivots = C1_lu_.matrixLU().diagonal().cwiseAbs();
    const double spread = pivots.minCoeff() / pivots.maxCoeff();
    if (!(spread > std::numeric_limits<double>::epsilon()))
        return diag.fail(GA_ERR_SINGULAR,
                         "the first-order block c1 I - g_y + G Z (c1 = %g) is singular (pivot "
                         "ratio %.3g) in the step from t = %.17g with h = %g",
                         c1, spread, accepted_.t, h);
    Cg_ = C1_lu_.solve(coupling_q_step());  // into storage of its own: no temporary
    Cg_q_norm_ = Cg_.cwiseAbs().rowwise().sum().maxCoeff();
    Cg_ = C1_lu_.solve(blocks_.g_v);
    Cg_v_norm_ = Cg_.cwiseAbs().rowwise().sum().maxCoeff();
    schur_valid_ = true;
    schur_h_ = h;
    return GA_OK;
}

// After the mechanical solve x0 = Sol(r^q, ...) in dq_, dw_, dlambda_, deta_:
// dy = C^-1 (-r^y + G x0), and the mechanical update x0 - Z dy.
void Stepper::first_order_correction(const NewtonCoefficients &c, Vec &dw)
{
    const bool index2 = formulation == GA_INDEX2_STABILIZED;
    z_y_ = -ry_;
    if (coupling_exact) {
        apply_G(coupling_q_step(), blocks_.g_v, c.gamma_prime, dq_, dw, gx_);
        z_y_ += gx_;
    }
    dy_ = C1_lu_.solve(z_y_);
    if (!forces_see_y())
        return;
    dq_.noalias() -= Zq_ * dy_;
    dlambda_.noalias() -= Zl_ * dy_;
    if (index2) {
        dw.noalias() -= Zw_ * dy_;
        deta_.noalias() -= Ze_ * dy_;
    }
}

// y += dy, y' += c1 dy (c1 of this step's h: the relation between them is exact, whatever
// matrix is kept), and what the stopping test reads.
void Stepper::update_first_order(const NewtonCoefficients &c, double h, State &x,
                                UpdateSizes &size)
{
    const double c1 = first_order_newton_coefficient(params1, h);
    x.y += dy_;
    x.ydot += c1 * dy_;
    // The scale y is measured against: |y|, and the y that a change of q by its own size
    // makes through the coupling, |C^-1 g_q| |q| + gamma' |C^-1 g_v| |q|: a state that starts
    // from 0 (a current at rest) converges to the accuracy of q instead of to a relative
    // accuracy its round-off, carried over from q, never reaches.
    const double through_q = (Cg_q_norm_ + c.gamma_prime * Cg_v_norm_) * size.q;
    size.dy = dy_.cwiseAbs().maxCoeff();
    size.y = x.y.cwiseAbs().maxCoeff() + through_q;
    size.ydot = x.ydot.cwiseAbs().maxCoeff() + c1 * through_q;
    size.c1 = c1;
    const bool finite = all_finite(dy_) && all_finite(x.y) && all_finite(x.ydot);
    size.increments_finite = size.increments_finite && all_finite(dy_);
    size.iterate_finite = size.iterate_finite && finite;
}

// The step's last line for y: w_{n+1} from the converged y'_{n+1}; w_n kept for the error
// estimate of the next step.
void Stepper::finish_first_order(State &x)
{
    const FirstOrderParams &p = params1;
    const Vec &w_n = *w_start_;
    x.w = (p.alpha_f * *ydot_start_ - p.alpha_m * w_n + (1.0 - p.alpha_f) * x.ydot) /
          (1.0 - p.alpha_m);
    x.w_prev = w_n;
}

// The local error of y (adaptive steps): with w_n = y'(t_n + delta h) + kappa h^2 y''' in the
// steady state of the w recursion, y_{n+1} - y(t_{n+1}) = C_y h^3 y''' + O(h^4),
//     kappa = ((1 - alpha_f1) - (1 - alpha_m1)(1 + delta)^2 - alpha_m1 delta^2) / 2,
//     C_y = ((1 - gamma1) delta^2 + gamma1 (1 + delta)^2) / 2 + kappa - 1/6
// (0.084 at rho_inf = 0.9, 1/3 at 0; checked against the scheme run on y' = cos t), with y'''
// from the divided differences of w over the last two steps, as e_v is from those of a
// (error_estimate.cpp; none in the first step). The sum of the squared weighted errors.
double Stepper::first_order_error_sum(double h, double scale, const StepController &control)
{
    const State &s = accepted_, &x = trial_;
    if (!(s.h_last > 0.0))
        return 0.0;
    const FirstOrderParams &p = params1;
    const double d = p.alpha_m - p.alpha_f;
    const double kappa =
        ((1.0 - p.alpha_f) - (1.0 - p.alpha_m) * (1.0 + d) * (1.0 + d) - p.alpha_m * d * d) / 2;
    const double cy =
        ((1.0 - p.gamma) * d * d + p.gamma * (1.0 + d) * (1.0 + d)) / 2 + kappa - 1.0 / 6.0;
    const Vec &w_n = *w_start_;
    const double c = cy * h * h * h / (0.5 * (h + s.h_last));
    double sum = 0.0;
    for (int k = 0; k < r(); ++k) {
        const double e = c * ((x.w[k] - w_n[k]) / h - (s.w[k] - s.w_prev[k]) / s.h_last);
        const double wk = scale * (control.atol_y(k) + control.rtol * std::max(std::fabs(s.y[k]),
                                                                              std::fabs(x.y[k])));
        sum += (e / wk) * (e / wk);
    }
    return sum;
}

// Cubic Hermite from y, y' at both ends of the last step, and its derivative.
ga_status Stepper::interpolate_y(double t, double *y, double *ydot)
{
    double th = 0.0, h = 0.0;
    if (auto st = dense_.place(t, th, h, diag))
        return st;
    dense_.first_order_states(th, h, y, ydot);
    return GA_OK;
}

}  // namespace ga
