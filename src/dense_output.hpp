// ga::DenseOutput: the last step as a curve (ga_interpolate, ga_interpolate_y, the event
// search): where t lies in it, q and v there by cubic Hermite interpolation from both ends
// (q through the configuration space), the steps' own qdd and lambda linear over it, and the
// first-order states. It reads the solver's previous and accepted states, which the commit
// swaps (the references stay); accelerations and multipliers consistent with the
// interpolated (q, v) are the solver's (output.cpp), which solves for them.
#pragma once

#include "configuration_space.hpp"
#include "diagnostics.hpp"
#include "state.hpp"

namespace ga {

class DenseOutput {
public:
    DenseOutput(const State &previous, const State &accepted, const bool &valid,
                const ConfigurationSpace &space)
        : a_(previous), b_(accepted), valid_(valid), space_(space)
    {
    }

    // t's fraction th of the last step h, or why there is no such place
    ga_status place(double t, double &th, double &h, Diagnostics &diag) const;
    // third-order local accuracy: q from q, v at both ends; v from v, qdd
    void positions(double th, double h, Vec &q) const;
    void velocities(double th, double h, Vec &v) const;
    // the steps' own accelerations and multipliers, linear over the step
    void accelerations(double th, double *qdd) const;
    void multipliers(double th, double *lambda) const;
    // y and y' (either may be null) from y, y' at both ends
    void first_order_states(double th, double h, double *y, double *ydot) const;

private:
    const State &a_, &b_;
    const bool &valid_;  // a step since ga_init or ga_set_state
    const ConfigurationSpace &space_;
};

}  // namespace ga
