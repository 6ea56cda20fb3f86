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

}  // namespace ga
