// ga::StepController: the step sizes of adaptive mode (docs/algorithms.md sec. 1.2), from
// numbers alone -- the error norm the step estimated, the step sizes, the distance to t_stop.
// It reads no state and calls nothing: the solver's adaptive loop asks it and attempts.
// Its options and state are part of the solver's checkpoint (h_next, err_prev, grew).
#pragma once

#include <vector>

namespace ga {

class StepController {
public:
    double rtol = 1e-6, atol = 1e-6;
    // Per-coordinate absolute tolerances (ga_set_tolerances_vector), or empty: atol for all.
    std::vector<double> atol_q_each, atol_v_each, atol_y_each;
    double atol_q(int i) const { return atol_q_each.empty() ? atol : atol_q_each[i]; }
    double atol_v(int i) const { return atol_v_each.empty() ? atol : atol_v_each[i]; }
    double atol_y(int k) const { return atol_y_each.empty() ? atol : atol_y_each[k]; }
    double h_min = 0.0, h_max = 0.0, h_init = 0.0;  // 0: automatic / unlimited
    // controller state (part of the checkpoint)
    double h_next = 0.0, err_prev = 0.0;  // err_prev 0: none (step_controller.cpp)
    bool grew = false;
    double err_last = 0.0;  // error norm of the last accepted step

    // The factor on the error test's weights (tolerance calibration): the local error
    // tolerance is calibration() (atol + rtol |y|).
    double calibration() const;
    // A new run's controller: no proposal, no base for a prediction.
    void reset()
    {
        h_next = 0.0;
        err_prev = 0.0;
        grew = false;
    }

    // The first step's size, from the weighted RMS norms of qdd and v at the start (weights
    // calibration() (atol + rtol |q_i|)) and the time left to t_stop.
    double first_step(double acc, double vel, double remaining) const;
    // The smallest step at t: the user's minimum, but never below what moves t.
    double minimum_step(double t) const;
    // A proposal within [h_min, h_max].
    double bounded(double h, double h_min) const;
    // The attempt's size approaching t_stop (no sliver of a last step); land: it ends on t_stop.
    double approach(double h, double remaining, bool rejected, bool &land) const;
    // After the step of size h (planned h_planned) was accepted with error norm err: the next
    // proposal. h_prev is the accepted step before it.
    void accept(double err, double h, double h_planned, double h_prev, bool land, bool rejected);
    // The next attempt after a rejected error (err > 1) and after a recoverable failure.
    static double after_rejection(double h, double err);
    static double after_failure(double h);
};

}  // namespace ga
