// Dense output over the last step (dense_output.hpp).
#include "dense_output.hpp"

#include <algorithm>
#include <cmath>

namespace ga {

namespace {
struct Hermite {
    double h00, h10, h01, h11;
};
Hermite hermite_basis(double th)
{
    return {(2 * th - 3) * th * th + 1, ((th - 2) * th + 1) * th, (3 - 2 * th) * th * th,
            (th - 1) * th * th};
}
}  // namespace

ga_status DenseOutput::place(double t, double &th, double &h, Diagnostics &diag) const
{
    if (!valid_)
        return diag.fail(GA_ERR_STATE, "dense output: no step since ga_init or ga_set_state");
    const State &a = a_, &b = b_;
    h = b.t - a.t;
    const double slack = 1e-12 * std::max(std::fabs(b.t), 1.0);
    if (!(t >= a.t - slack && t <= b.t + slack))
        return diag.fail(GA_ERR_ARG, "dense output: t = %.17g is outside the last step [%.17g, "
                         "%.17g]", t, a.t, b.t);
    th = std::clamp((t - a.t) / h, 0.0, 1.0);
    return GA_OK;
}

void DenseOutput::positions(double th, double h, Vec &q) const
{
    const Hermite c = hermite_basis(th);
    space_.hermite(a_.q, a_.v, b_.q, b_.v, h, c.h00, c.h10, c.h01, c.h11, q);
}

void DenseOutput::velocities(double th, double h, Vec &v) const
{
    const Hermite c = hermite_basis(th);
    v = c.h00 * a_.v + (c.h10 * h) * a_.qdd + c.h01 * b_.v + (c.h11 * h) * b_.qdd;
}

void DenseOutput::accelerations(double th, double *qdd) const
{
    Eigen::Map<Vec>(qdd, b_.qdd.size()) = (1.0 - th) * a_.qdd + th * b_.qdd;
}

void DenseOutput::multipliers(double th, double *lambda) const
{
    Eigen::Map<Vec>(lambda, b_.lambda.size()) = (1.0 - th) * a_.lambda + th * b_.lambda;
}

void DenseOutput::first_order_states(double th, double h, double *y, double *ydot) const
{
    const State &a = a_, &b = b_;
    for (Eigen::Index k = 0; k < b.y.size(); ++k) {
        const double y0 = a.y[k], y1 = b.y[k], d0 = h * a.ydot[k], d1 = h * b.ydot[k];
        if (y)
            y[k] = ((2 * th - 3) * th * th + 1) * y0 + ((th - 2) * th + 1) * th * d0 +
                   (3 - 2 * th) * th * th * y1 + (th - 1) * th * th * d1;
        if (ydot)
            ydot[k] = ((6 * th - 6) * th * (y0 - y1) + ((3 * th - 4) * th + 1) * d0 +
                       (3 * th - 2) * th * d1) /
                      h;
    }
}

}  // namespace ga
