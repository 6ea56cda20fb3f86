#include "params.hpp"

#include <cmath>

namespace ga {

Params params_from_rho_inf(double rho_inf)
{
    Params p{};
    p.alpha_m = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0);          // eq. (24)
    p.alpha_f = rho_inf / (rho_inf + 1.0);                        // eq. (24)
    p.gamma = 0.5 + p.alpha_f - p.alpha_m;                        // eq. (20)
    p.beta = 0.25 * (p.gamma + 0.5) * (p.gamma + 0.5);            // eq. (24)
    return p;
}

const char *check_params(const Params &p)
{
    if (!std::isfinite(p.alpha_m) || !std::isfinite(p.alpha_f) || !std::isfinite(p.beta) ||
        !std::isfinite(p.gamma))
        return "parameters must be finite";
    // Second order (eq. 20): the local error is O(h^3) only on this line.
    const double gamma_order2 = 0.5 + p.alpha_f - p.alpha_m;
    if (std::fabs(p.gamma - gamma_order2) > 1e-12 * (1.0 + std::fabs(gamma_order2)))
        return "gamma != 1/2 + alpha_f - alpha_m: the order-2 condition (eq. 20) is violated";
    // Zero stability: the roots of rho(zeta) (eq. 21) are 1 and -alpha_m/(1 - alpha_m).
    if (p.alpha_m > 0.5)
        return "alpha_m > 1/2 is not zero-stable (root -alpha_m/(1-alpha_m) of eq. 21 "
               "outside the unit disc)";
    // Strict stability at infinity (eq. 23, Lemma 1).
    if (!(p.alpha_m < p.alpha_f))
        return "alpha_m >= alpha_f: not strictly stable at infinity (eq. 23 needs "
               "alpha_m < alpha_f < 1/2)";
    if (!(p.alpha_f < 0.5))
        return "alpha_f >= 1/2: not strictly stable at infinity (eq. 23 needs "
               "alpha_m < alpha_f < 1/2); use ga_set_rho_inf(s, 1) for the undamped limit";
    if (!(p.beta > 0.25 + 0.5 * (p.alpha_f - p.alpha_m)))
        return "beta <= 1/4 + (alpha_f - alpha_m)/2: not strictly stable at infinity (eq. 23)";
    return nullptr;
}

NewtonCoefficients newton_coefficients(const Params &p, double h)
{
    NewtonCoefficients c{};
    c.beta_prime = (1.0 - p.alpha_m) / (h * h * p.beta * (1.0 - p.alpha_f));  // eq. (6)
    c.gamma_prime = p.gamma / (h * p.beta);                                  // eq. (6)
    return c;
}

// gamma: second order iff gamma = 1/2 + alpha_f - alpha_m (w lags y' by (alpha_m - alpha_f) h);
// the stiff-limit roots -(1 - gamma)/gamma and -alpha_f/(1 - alpha_f) both equal -rho_inf.
FirstOrderParams first_order_params_from_rho_inf(double rho_inf)
{
    FirstOrderParams p{};
    p.alpha_m = (3.0 * rho_inf - 1.0) / (2.0 * (rho_inf + 1.0));
    p.alpha_f = rho_inf / (rho_inf + 1.0);
    p.gamma = 0.5 + p.alpha_f - p.alpha_m;  // = 1 / (1 + rho_inf)
    return p;
}

double first_order_newton_coefficient(const FirstOrderParams &p, double h)
{
    return (1.0 - p.alpha_m) / (h * p.gamma * (1.0 - p.alpha_f));
}

}  // namespace ga
