// The step-size controller of adaptive mode (docs/algorithms.md sec. 1.2, 9).
#include "step_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ga {

namespace {
const double kEps = std::numeric_limits<double>::epsilon();
// Tolerance calibration (docs/algorithms.md sec. 7): the local error test is against
// kCalibration sqrt(rtol) times the weights atol + rtol |y|, i.e. a tolerance ~ tol^(3/2). An
// order-2 method whose steps keep the local error at tol' ends with a global error
// ~ tol'^(2/3); controlled so, it ends ~ tol, from 1e-3 to 1e-8 (docs/design-notes.md,
// "Tolerance proportionality").
constexpr double kCalibration = 0.5;
// ... but a local tolerance is never asked below this, relative: round-off. At rtol 1e-10 the
// calibration asked 5e-16, and index-3 steps of the pendulum shrank below their minimum.
constexpr double kMinLocalTolerance = 1e-14;
constexpr double kSafety = 0.9;
constexpr double kMaxGrowth = 2.0, kMinShrink = 0.2;
constexpr double kFailureShrink = 0.25;
}  // namespace

double StepController::calibration() const
{
    return std::max(kCalibration * std::sqrt(std::min(rtol, 1.0)), kMinLocalTolerance / rtol);
}

// Unless the user gave one: half the step over which the acceleration alone moves q by the
// position tolerance, (h^2 / 2) |qdd|_w = 1 (each coordinate against its own weight, so that a
// long chain is not measured by its largest coordinate); the controller grows it quickly.
double StepController::first_step(double acc, double vel, double remaining) const
{
    return h_init > 0.0 ? h_init
           : acc > 0.0  ? 0.5 * std::sqrt(2.0 / acc)
           : vel > 0.0  ? 1.0 / vel
                        : 1e-3 * remaining;
}

// At t = -1e300 with h_max = 1 a step of 1 was accepted with t unchanged (and its checkpoint
// refused).
double StepController::minimum_step(double t) const
{
    return std::max(h_min, 16.0 * kEps * std::max(std::fabs(t), 1.0));
}

// A proposal below the minimum is tried at the minimum: only a step that fails there fails
// the call (an initial estimate of 3e-6 under h_min = 1e-4 failed before any try).
double StepController::bounded(double h, double h_minimum) const
{
    h = std::max(h, h_minimum);
    if (h_max > 0.0)
        h = std::min(h, h_max);
    return h;
}

// Up to 1.5 h take it all (the error test decides), up to 2 h split it in two equal steps.
// After a rejection only the clamp to t_stop applies (else the stretch would undo the shrink).
// Stretched, a step stays within h_max.
double StepController::approach(double h, double remaining, bool rejected, bool &land) const
{
    land = false;
    const double stretch = rejected     ? 1.0
                           : h_max > 0.0 ? std::min(1.5, std::max(1.0, h_max / h))
                                         : 1.5;
    if (h * stretch >= remaining) {
        land = true;
        return remaining;
    }
    if (!rejected && h * 2.0 > remaining)
        return 0.5 * remaining;
    return h;
}

// Predictive controller (Gustafsson, as in Radau5 and SciPy's Radau; k = 3 for a local error
// O(h^3)): the elementary proposal s err^(-1/k), reduced when the error grew faster than the
// step size explains,
//     fac = s min(1, (h / h_prev) (err_prev / err)^(1/k)) err^(-1/k),
// growth at most 2, none right after a rejection or on two consecutive steps (sec. 1.2). No
// dead band for small growth: it kept the estimates well below the tolerance and cost accuracy
// for the same work (design-notes.md, "Step-size control"). The first step's estimate has no
// velocity part (no a history) and is blind to a start from rest: no base for a prediction
// (err_prev = 0: none). A step shortened to land on t_stop (down to a sliver, when t_stop was
// that close) was not the controller's choice: no prediction from it, and unless its error
// asks for less, the next step takes the one planned.
void StepController::accept(double err, double h, double h_planned, double h_prev, bool land,
                            bool rejected)
{
    const bool shortened = land && h < h_planned;
    const double e = std::max(err, 1e-10);
    double fac = kSafety * std::pow(e, -1.0 / 3.0);
    if (!shortened && err_prev > 0.0 && h_prev > 0.0)
        fac *= std::min(1.0, (h / h_prev) * std::cbrt(err_prev / e));
    fac = std::clamp(fac, kMinShrink, kMaxGrowth);
    if (fac > 1.0 && (rejected || grew))
        fac = 1.0;
    grew = fac > 1.0;
    if (!shortened)  // nor a base for the next prediction
        err_prev = h_prev > 0.0 ? e : 0.0;
    h_next = shortened && fac >= 1.0 ? h_planned : h * fac;
    if (h_max > 0.0)
        h_next = std::min(h_next, h_max);
}

double StepController::after_rejection(double h, double err)
{
    return h * std::max(kMinShrink, kSafety * std::pow(err, -1.0 / 3.0));
}

double StepController::after_failure(double h) { return h * kFailureShrink; }

}  // namespace ga
