// Method parameters of the generalized-alpha scheme: Chung-Hulbert choice from rho_inf
// (eq. 24 with eq. 20), validation against eqs. (20) and (23), and the Newton coefficients (6).
#pragma once

namespace ga {

struct Params {
    double alpha_m;
    double alpha_f;
    double beta;
    double gamma;
};

// Eq. (24) with gamma from eq. (20). rho_inf must lie in [0, 1] (checked by the caller).
Params params_from_rho_inf(double rho_inf);

// nullptr when p is acceptable, otherwise a static sentence naming the broken condition.
const char *check_params(const Params &p);

// beta' = (1 - alpha_m) / (h^2 beta (1 - alpha_f)),  gamma' = gamma / (h beta)   (eq. 6)
struct NewtonCoefficients {
    double beta_prime;
    double gamma_prime;
};
NewtonCoefficients newton_coefficients(const Params &p, double h);

// First-order states y' = g (docs/algorithms.md sec. 9): the generalized-alpha of Jansen,
// Whiting and Hulbert in the paper's non-weighted form, an auxiliary w for y' as a is for q'',
//     (1 - alpha_m) w_{n+1} + alpha_m w_n = (1 - alpha_f) y'_{n+1} + alpha_f y'_n,
//     y_{n+1} = y_n + h ((1 - gamma) w_n + gamma w_{n+1}),
// with parameters from the same rho_inf, so that the stiff limit has the double root -rho_inf.
struct FirstOrderParams {
    double alpha_m;
    double alpha_f;
    double gamma;
};
FirstOrderParams first_order_params_from_rho_inf(double rho_inf);
// d y'_{n+1} / d y_{n+1} = (1 - alpha_m) / (h gamma (1 - alpha_f)): the Newton coefficient
// of the first-order rows, as gamma' is of the velocities (eq. 6).
double first_order_newton_coefficient(const FirstOrderParams &p, double h);

}  // namespace ga
