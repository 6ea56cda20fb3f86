// ga::StepOutput: the door through which the services after a commit (events, the step hook)
// see the step -- the accepted state and the dense output over the last step, as ga_get_*
// and ga_interpolate give them, and the user's callbacks. They neither step nor undo: a
// service that fails returns its status, and the transaction (transaction.cpp) undoes the
// step and asks each service to put back its own work.
#pragma once

#include "galpha.h"

namespace ga {

class Model;

class StepOutput {
public:
    // the accepted state: t, q, v, and the first-order states y (empty when r = 0)
    virtual double time() const = 0;
    virtual const double *positions() const = 0;
    virtual const double *velocities() const = 0;
    virtual const double *first_order_states() const = 0;
    // lambda at the accepted state as ga_get_lambda gives it (m entries)
    virtual ga_status multipliers(double *lambda) = 0;
    // q, v and lambda at t inside the last step, as ga_interpolate (lambda may be null); y there
    virtual ga_status interpolate_at(double t, double *q, double *v, double *lambda) = 0;
    virtual ga_status interpolate_y_at(double t, double *y) = 0;
    virtual Model &callbacks() = 0;

protected:
    ~StepOutput() = default;
};

}  // namespace ga
