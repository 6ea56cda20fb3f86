// The index-3 step's check of its own resolution (docs/algorithms.md sec. 12). Index 3 holds
// Phi(q) = 0 at every step and leaves the velocity constraint Phi_q v + Phi_t = 0 to the
// discretization: O(h^2) where the motion is resolved. Where it is not -- a link turning by
// more than about 0.1 rad per step at rho_inf = 0.9, 0.2 at 0.8, 0.3 at 0.7 -- the step map
// itself grows a mode that turns the velocities away from the constraints and pumps energy
// into the motion (design-notes.md, "Index 3 and fast rotation"), every Newton iteration
// converging. That is what this check sees, at the cost of one Phi_t.
#include <algorithm>
#include <cmath>
#include <limits>

#include "stepper.hpp"

namespace ga {

namespace {
constexpr double kNewtonFloorUlps = 64.0;  // the Newton test's round-off floor of q (newton.cpp)
}

// After the step's Newton iteration converged: trial_ holds the step, J_ Phi_q at the last
// iterate but one (within Newton's tolerance of q_{n+1}); tol: that iteration's tolerance.
ga_status Stepper::check_velocity_constraint(double h, double tol)
{
    velocity_residual_ = 0.0;
    if (formulation != GA_INDEX3 || m_ == 0 || !(max_velocity_residual < kNoCheck))
        return GA_OK;
    const State &s = accepted_, &x = trial_;
    Vec &residual = check_residual_, &scale = check_scale_, &phi_t = check_phi_t_;
    if (auto st = model.constraint_dt(x.t, x.q, phi_t, true)) {
        diag.append(" (velocity constraint of the step from t = %.17g with h = %g)", s.t, h);
        return st;
    }
    // Each row against its gradient times the largest speed of the model, the step's mean
    // velocity included where v passes through zero (a pendulum's turning point). (Against
    // the speeds of its own coordinates only, a link that starts to fall from the horizontal
    // measured an O(h^2) residual against the second-order motion along the link: 0.22.)
    double top = 0.0, q_max = 0.0;
    for (int j = 0; j < nv_; ++j) {
        top = std::max(top, std::fabs(x.v[j]) + model.space.distance(x.q, s.q, j) / h);
        q_max = std::max(q_max, model.space.magnitude(x.q, j));
    }
    // Newton leaves q within tol |q| (its floor: 64 ulps), and v = gamma' times that off
    // (eq. 6): noise that grows as h shrinks, not the step map's mode. Counted as noise, a
    // step from rest at rtol 1e-9 (|v| ~ h |qdd|) was refused down to h = 4e-15.
    const double noise =
        newton_coefficients(params, h).gamma_prime *
        std::max(tol, kNewtonFloorUlps * std::numeric_limits<double>::epsilon()) * q_max;
    residual = phi_t;
    scale.setZero();
    J_.multiply_add_row_abs_sums(x.v, residual, scale);  // Phi_q v + Phi_t, sum_j |Phi_q,ij|
    int worst = -1;
    for (int i = 0; i < m_; ++i) {
        const double row = scale[i];
        scale[i] = top * row + std::fabs(phi_t[i]);
        if (!constraint_active(i) || !(scale[i] > 0.0))
            continue;
        const double ratio = std::max(0.0, std::fabs(residual[i]) - noise * row) / scale[i];
        if (ratio > velocity_residual_ || !(ratio == ratio)) {
            velocity_residual_ = ratio;
            worst = i;
        }
    }
    if (!(velocity_residual_ > max_velocity_residual))
        return GA_OK;
    return diag.fail(GA_ERR_UNRESOLVED,
                     "the step from t = %.17g with h = %g is not resolved: its velocities "
                     "violate the velocity constraint %d by %.3g of their size (index 3 holds "
                     "it only to O(h^2); above %g the step map of index 3 is unstable for "
                     "this motion): take a smaller h or the stabilized index-2 formulation "
                     "(ga_set_formulation)",
                     s.t, h, worst, velocity_residual_, max_velocity_residual);
}

}  // namespace ga
