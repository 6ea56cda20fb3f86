// First-order states y' = g(t, q, v, y) in the step of Algorithm 1 (docs/algorithms.md sec. 11):
// the generalized-alpha of Jansen, Whiting and Hulbert in the paper's non-weighted form,
//     (1 - alpha_m1) w_{n+1} + alpha_m1 w_n = (1 - alpha_f1) y'_{n+1} + alpha_f1 y'_n,
//     y_{n+1} = y_n + h ((1 - gamma1) w_n + gamma1 w_{n+1}),   y'_{n+1} = g(t_{n+1}, ...),
// with y the Newton unknown beside q and lambda. dy is eliminated from the Newton system
// (sec. 11, "Solve"): with H = c1 I - g_y,
//     dy = H^-1 (-r^y + g_q dq + gamma' g_v dw),
// and the mechanical system keeps its form with K_t - f_y H^-1 g_q, C_t - f_y H^-1 g_v and
// r^q + f_y H^-1 r^y, so that its solvers and its scaling (eq. 10) stay as they are.
#include <algorithm>
#include <cmath>
#include <limits>

#include "linear/assemble.hpp"
#include "solver.hpp"

namespace ga {

// Transactional: everything is allocated before anything changes.
void Solver::set_first_order(int r)
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
    y_started_ = false;
    invalidate_jacobian();
}

// The w the step starts from (as a_n for q): after ga_init the corrected start of sec. 11,
// w_0 = y'_0 + (alpha_m1 - alpha_f1) h y''_0, or y'_0 without it; after a change of h, w_n
// rescaled to the new h, w_n <- y'_n + (h / h_last) (w_n - y'_n), as a_n is (sec. 1.2).
void Solver::first_order_start(double h)
{
    const State &s = accepted_;
    w_start_ = &s.w;
    if (fresh_start_ && corrected_start) {
        w_start_ = &w_n_;  // first_order_starting_values filled it
    } else if (fresh_start_) {
        w_start_ = &s.ydot;
    } else if (rescale_a && s.h_last > 0.0 && h != s.h_last) {
        w_n_ = s.ydot + (h / s.h_last) * (s.w - s.ydot);
        w_start_ = &w_n_;
    }
}

// h y''_0 by a central difference of g along the Taylor polynomial of the start at t0 -+ h
// (the h^2 y''_0 / 2 left out of y cancels in the difference); w_n_ = y'_0 + delta h y''_0.
// qdd_start_ is the start's consistent qdd.
ga_status Solver::first_order_starting_values(double h)
{
    const State &s = accepted_;
    State &x = trial_;  // scratch: the step has not started
    for (int side = 0; side < 2; ++side) {
        const double sh = side == 0 ? h : -h;
        x.q = s.q + sh * s.v + (0.5 * sh * sh) * *qdd_start_;
        x.v = s.v + sh * *qdd_start_;
        x.y = s.y + sh * s.ydot;
        Vec &out = side == 0 ? hry_ : dy_;
        if (auto st = model.rate(s.t + sh, x.q, x.v, x.y, out)) {
            diag.append(" (corrected starting values of the first-order states, h = %g)", h);
            return st;
        }
    }
    const double delta = params1.alpha_m - params1.alpha_f;
    w_n_ = s.ydot + (0.5 * delta) * (hry_ - dy_);
    return GA_OK;
}

// Predictor: w_{n+1} = w_n, so that y'_{n+1} = (w_n - alpha_f1 y'_n) / (1 - alpha_f1) and
// y_{n+1} = y_n + h w_n (the ConstantA predictor of q).
void Solver::predict_first_order(double h)
{
    const State &s = accepted_;
    State &x = trial_;
    const FirstOrderParams &p = params1;
    const Vec &w_n = *w_start_;
    x.ydot = (w_n - p.alpha_f * s.ydot) / (1.0 - p.alpha_f);
    x.y = s.y + h * w_n;
}

// The coupling blocks at the iterate x (f_, rate_ from the residual there), H = c1 I - g_y
// and its LU, H^-1 g_q, H^-1 g_v, and K_t, C_t with the coupling folded in (Keff_, Ceff_)
// when the forces depend on y. Without coupling_exact the fold is left out, and the update of
// y leaves out g_q, g_v.
ga_status Solver::first_order_matrix(double t, const State &x, double h, bool tangents_K,
                                     bool tangents_C)
{
    if (auto st = model.coupling(t, x.q, x.v, x.y, f_, rate_, blocks_))
        return st;
    const double c1 = first_order_newton_coefficient(params1, h);
    H_ = -blocks_.g_y;
    H_.diagonal().array() += c1;
    H_lu_.compute(H_);
    // The pivots' spread as the test of singularity: Eigen's rcond() allocates.
    const auto pivots = H_lu_.matrixLU().diagonal().cwiseAbs();
    const double spread = pivots.minCoeff() / pivots.maxCoeff();
    if (!(spread > std::numeric_limits<double>::epsilon()))
        return diag.fail(GA_ERR_SINGULAR,
                         "the first-order block H = c1 I - g_y (c1 = %g) is singular (pivot "
                         "ratio %.3g) in the step from t = %.17g with h = %g",
                         c1, spread, accepted_.t, h);
    c1_matrix_ = c1;
    coupling_in_matrix_ = coupling_exact && model.cb.force_y != nullptr;
    // (without coupling_exact, H^-1 g_q and H^-1 g_v still give the convergence test its scale)
    Hg_q_ = H_lu_.solve(blocks_.g_q);
    Hg_v_ = H_lu_.solve(blocks_.g_v);
    Hg_q_norm_ = Hg_q_.cwiseAbs().rowwise().sum().maxCoeff();
    Hg_v_norm_ = Hg_v_.cwiseAbs().rowwise().sum().maxCoeff();
    if (!coupling_in_matrix_)
        return GA_OK;
    // Keff = K - f_y H^-1 g_q, Ceff = C - f_y H^-1 g_v: rank-r updates, column by column.
    const int r1 = r();
    for (int pass = 0; pass < 2; ++pass) {
        ModelMatrix &E = pass == 0 ? Keff_ : Ceff_;
        const bool with = pass == 0 ? tangents_K : tangents_C;
        const Mat &G = pass == 0 ? Hg_q_ : Hg_v_;
        E.set_zero();
        if (with)
            add_block(E.data(), n_, 0, 0, 1.0, pass == 0 ? K_ : C_);
        auto e = E.as_dense();
        for (int j = 0; j < n_; ++j)
            for (int k = 0; k < r1; ++k)
                e.col(j) -= G(k, j) * blocks_.f_y.col(k);
    }
    return GA_OK;
}

// Before the mechanical solve: hry_ = H^-1 r^y, and r^q += f_y H^-1 r^y where the matrix
// holds the fold.
void Solver::eliminate_first_order_rhs()
{
    hry_ = H_lu_.solve(ry_);
    if (coupling_in_matrix_)
        for (int k = 0; k < r(); ++k)
            rq_ += hry_[k] * blocks_.f_y.col(k);
}

// After it: dy = -H^-1 r^y + H^-1 g_q dq + gamma' H^-1 g_v dw; y += dy, y' += c1 dy (c1 of
// this step's h: the relation between them is exact, whatever matrix is kept).
void Solver::update_first_order(const NewtonCoefficients &c, double h, const Vec &dw, State &x,
                                UpdateSizes &size)
{
    dy_ = -hry_;
    if (coupling_exact) {
        dy_.noalias() += Hg_q_ * dq_;
        dy_.noalias() += c.gamma_prime * (Hg_v_ * dw);
    }
    const double c1 = first_order_newton_coefficient(params1, h);
    x.y += dy_;
    x.ydot += c1 * dy_;
    // The scale y is measured against: |y|, and the y that a change of q by its own size
    // makes through the coupling, |H^-1 g_q| |q| + gamma' |H^-1 g_v| |q|: a state that starts
    // from 0 (a current at rest) converges to the accuracy of q instead of to a relative
    // accuracy its round-off, carried over from q, never reaches.
    const double through_q = (Hg_q_norm_ + c.gamma_prime * Hg_v_norm_) * size.q;
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
void Solver::finish_first_order(State &x)
{
    const FirstOrderParams &p = params1;
    const Vec &w_n = *w_start_;
    x.w = (p.alpha_f * accepted_.ydot - p.alpha_m * w_n + (1.0 - p.alpha_f) * x.ydot) /
          (1.0 - p.alpha_m);
    x.w_prev = w_n;
}

// The local error of y (adaptive steps): with w_n = y'(t_n + delta h) + kappa h^2 y''' in the
// steady state of the w recursion, y_{n+1} - y(t_{n+1}) = C_y h^3 y''' + O(h^4),
//     kappa = ((1 - alpha_f1) - (1 - alpha_m1)(1 + delta)^2 - alpha_m1 delta^2) / 2,
//     C_y = ((1 - gamma1) delta^2 + gamma1 (1 + delta)^2) / 2 + kappa - 1/6
// (0.084 at rho_inf = 0.9, 1/3 at 0; checked against the scheme run on y' = cos t), with y'''
// from the divided differences of w over the last two steps, as e_v is from those of a
// (control.cpp; none in the first step). The sum of the squared weighted errors.
double Solver::first_order_error_sum(double h, double scale)
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
        const double wk = scale * (control.atol + control.rtol * std::max(std::fabs(s.y[k]),
                                                                         std::fabs(x.y[k])));
        sum += (e / wk) * (e / wk);
    }
    return sum;
}

// Cubic Hermite from y, y' at both ends of the last step, and its derivative.
ga_status Solver::interpolate_y(double t, double *y, double *ydot)
{
    if (!previous_valid_)
        return diag.fail(GA_ERR_STATE, "dense output: no step since ga_init or ga_set_state");
    const State &a = previous_, &b = accepted_;
    const double h = b.t - a.t;
    const double slack = 1e-12 * std::max(std::fabs(b.t), 1.0);
    if (!(t >= a.t - slack && t <= b.t + slack))
        return diag.fail(GA_ERR_ARG, "dense output: t = %.17g is outside the last step [%.17g, "
                         "%.17g]", t, a.t, b.t);
    const double th = std::clamp((t - a.t) / h, 0.0, 1.0);
    for (int k = 0; k < r(); ++k) {
        const double y0 = a.y[k], y1 = b.y[k], d0 = h * a.ydot[k], d1 = h * b.ydot[k];
        if (y)
            y[k] = ((2 * th - 3) * th * th + 1) * y0 + ((th - 2) * th + 1) * th * d0 +
                   (3 - 2 * th) * th * th * y1 + (th - 1) * th * th * d1;
        if (ydot)
            ydot[k] = ((6 * th - 6) * th * (y0 - y1) + ((3 * th - 4) * th + 1) * d0 +
                       (3 * th - 2) * th * d1) /
                      h;
    }
    return GA_OK;
}

}  // namespace ga
