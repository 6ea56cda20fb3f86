// ga_check_derivatives (derivative_check.cpp): the model's derivative callbacks at one state
// against central differences, with the parameters of the sensitivities' set.
#pragma once

#include "sensitivity.hpp"
#include "stepper.hpp"

namespace ga {

ga_status check_derivatives(Stepper &kernel, const Sensitivities &sens, double t, const double *q,
                            const double *v, const double *qdd, const double *lambda,
                            const double *y, double tol, double *worst);

}  // namespace ga
