// The first-order generalized-alpha parameters (src/params.cpp, docs/algorithms.md sec. 9),
// checked by stepping the scheme they define: on y' = mu y its amplification matrix has
// spectral radius rho_inf in the stiff limit (the trapezoidal rule, rho_inf = 1, keeps 1) and
// roots 1 and -alpha_m/(1 - alpha_m) at h mu = 0; the solution converges at order 2 on
// y' = -2 y and on y' = -y^2 (exact solutions e^(-2t) and 1/(1 + t)); and the Newton
// coefficient d y'/d y makes Newton's method on the nonlinear one converge quadratically; the
// auxiliary w is of order 2 only from a corrected start.
// The scheme is written out here from its two defining equations, independently of the
// solver (which does not integrate first-order states yet).
#include <cmath>
#include <complex>
#include <cstdarg>
#include <cstddef>
#include <csetjmp>
#include <cstdio>

extern "C" {
#include <cmocka.h>
}

#include <Eigen/Dense>

#include "params.hpp"

namespace {

const double kRhos[] = {0.0, 0.5, 0.9, 1.0};

// Spectral radius of the scheme's amplification matrix on y' = mu y at z = h mu, in the
// variables (y, h w): from (1 - am) w1 + am w0 = (1 - af) mu y1 + af mu y0 and
// y1 = y0 + h ((1 - g) w0 + g w1).
double spectral_radius(const ga::FirstOrderParams &p, double z)
{
    const double am = p.alpha_m, af = p.alpha_f, g = p.gamma;
    // y1 (1 - g (1 - af) z / (1 - am)) = y0 (1 + g af z / (1 - am)) + hw0 ((1 - g) - g am / (1 - am))
    const double d = 1.0 - g * (1.0 - af) * z / (1.0 - am);
    const double a11 = (1.0 + g * af * z / (1.0 - am)) / d;
    const double a12 = ((1.0 - g) - g * am / (1.0 - am)) / d;
    // h w1 = ((1 - af) z y1 + af z y0 - am h w0) / (1 - am)
    const double a21 = ((1.0 - af) * z * a11 + af * z) / (1.0 - am);
    const double a22 = ((1.0 - af) * z * a12 - am) / (1.0 - am);
    const double tr = a11 + a22, det = a11 * a22 - a12 * a21;
    const std::complex<double> s = std::sqrt(std::complex<double>(tr * tr - 4.0 * det, 0.0));
    return std::max(std::abs(0.5 * (tr + s)), std::abs(0.5 * (tr - s)));
}

void stiff_limit_is_rho_inf(void **)
{
    for (const double rho : kRhos) {
        const ga::FirstOrderParams p = ga::first_order_params_from_rho_inf(rho);
        const double r = spectral_radius(p, -1e12);
        std::printf("    rho_inf %.1f: spectral radius %.8f at h mu = -1e12\n", rho, r);
        // a double root -rho_inf split by O(1 / sqrt(|h mu|))
        assert_true(std::fabs(r - rho) < 1e-5);
        // and no larger anywhere on the negative axis (A-stability there); at rho_inf = 1 the
        // root -1 is double, and the eigenvalues of the computed matrix carry sqrt(eps) of it
        for (double z = -1e-3; z > -1e9; z *= 1.7)
            assert_true(spectral_radius(p, z) <= 1.0 + 1e-7);
    }
}

void parameters_satisfy_their_conditions(void **)
{
    for (const double rho : kRhos) {
        const ga::FirstOrderParams p = ga::first_order_params_from_rho_inf(rho);
        const ga::Params second = ga::params_from_rho_inf(rho);
        assert_true(std::fabs(p.gamma - 1.0 / (1.0 + rho)) < 1e-15);
        assert_true(std::fabs(p.gamma - (0.5 + p.alpha_f - p.alpha_m)) < 1e-15);
        assert_true(p.alpha_f == second.alpha_f);
        // zero stability: the root -alpha_m/(1 - alpha_m) of h mu = 0 inside the unit disc
        assert_true(std::fabs(p.alpha_m / (1.0 - p.alpha_m)) <= 1.0 + 1e-15);
        assert_true(std::fabs(spectral_radius(p, 0.0) - 1.0) < 1e-12);
    }
}

// y' = f(y) over [0, 1] with N steps; Newton on y'_{n+1} with the scheme's coefficient.
// Returns |y_N - exact|; *worst_iters: the most Newton iterations of a step to 1e-14.
// w_0 = y'_0, or with `corrected` y'_0 + (alpha_m - alpha_f) h y''_0 (y'' = f_y f), and then
// *w_error: the largest |w_n - y'(t_n + (alpha_m - alpha_f) h)| of the exact solution yd_exact.
template <class F, class Fy>
double integrate(const ga::FirstOrderParams &p, int N, double y0, double exact, F f, Fy fy,
                 int *worst_iters, bool corrected = false, double (*yd_exact)(double) = nullptr,
                 double *w_error = nullptr)
{
    const double h = 1.0 / N, c = ga::first_order_newton_coefficient(p, h);
    const double lag = p.alpha_m - p.alpha_f;
    double y = y0, yd = f(y0), w = corrected ? yd + lag * h * fy(y0) * yd : yd;
    *worst_iters = 0;
    if (w_error)
        *w_error = 0.0;
    for (int n = 0; n < N; ++n) {
        double yd1 = yd, y1 = y, w1 = w;  // predictor: y' constant
        int it = 0;
        for (; it < 20; ++it) {
            w1 = ((1.0 - p.alpha_f) * yd1 + p.alpha_f * yd - p.alpha_m * w) / (1.0 - p.alpha_m);
            y1 = y + h * ((1.0 - p.gamma) * w + p.gamma * w1);
            const double r = yd1 - f(y1);
            if (std::fabs(r) < 1e-14 * (1.0 + std::fabs(yd1)))
                break;
            yd1 -= r / (1.0 - fy(y1) / c);  // dy1/dyd1 = 1 / c
        }
        *worst_iters = std::max(*worst_iters, it);
        y = y1, yd = yd1, w = w1;
        if (w_error)
            *w_error = std::max(*w_error, std::fabs(w - yd_exact((n + 1 + lag) * h)));
    }
    return std::fabs(y - exact);
}

// w approximates y' at the lagged time t_n + (alpha_m - alpha_f) h: started from y'_0 it is
// off by O(h) in the first steps (order 1), started from the corrected value (the analogue of
// a_0 in sec. 3.4) by O(h^2) throughout. y is of order 2 either way.
void corrected_start_makes_w_second_order(void **)
{
    const auto f = [](double y) { return -y * y; };
    const auto fy = [](double y) { return -2.0 * y; };
    const auto yd_exact = [](double t) { return -1.0 / ((1.0 + t) * (1.0 + t)); };
    for (const double rho : {0.0, 0.5, 0.9}) {
        const ga::FirstOrderParams p = ga::first_order_params_from_rho_inf(rho);
        double order[2];
        for (int corrected = 0; corrected < 2; ++corrected) {
            double e[2];
            int iters;
            for (int k = 0; k < 2; ++k)
                integrate(p, 100 << k, 1.0, 0.5, f, fy, &iters, corrected != 0, yd_exact, &e[k]);
            order[corrected] = std::log2(e[0] / e[1]);
        }
        std::printf("    rho_inf %.1f: order of w %.2f from y'_0, %.2f from the corrected start\n",
                    rho, order[0], order[1]);
        assert_true(std::fabs(order[0] - 1.0) < 0.1);
        assert_true(std::fabs(order[1] - 2.0) < 0.1);
    }
}

void order_two_and_quadratic_newton(void **)
{
    for (const double rho : {0.0, 0.5, 0.9}) {
        const ga::FirstOrderParams p = ga::first_order_params_from_rho_inf(rho);
        double e_lin[2], e_nl[2];
        int iters = 0, worst = 0;
        for (int k = 0; k < 2; ++k) {
            const int N = 200 << k;
            e_lin[k] = integrate(p, N, 1.0, std::exp(-2.0), [](double y) { return -2.0 * y; },
                                 [](double) { return -2.0; }, &iters);
            e_nl[k] = integrate(p, N, 1.0, 0.5, [](double y) { return -y * y; },
                                [](double y) { return -2.0 * y; }, &iters);
            worst = std::max(worst, iters);
        }
        const double o_lin = std::log2(e_lin[0] / e_lin[1]), o_nl = std::log2(e_nl[0] / e_nl[1]);
        std::printf("    rho_inf %.1f: orders %.3f (linear), %.3f (y' = -y^2); at most %d "
                    "Newton iterations per step\n",
                    rho, o_lin, o_nl, worst);
        assert_true(std::fabs(o_lin - 2.0) < 0.05 && std::fabs(o_nl - 2.0) < 0.05);
        // from the predictor (an O(h) guess) to 1e-14 in three updates: quadratic
        assert_true(worst <= 3);
    }
}

// The coupled iteration matrix in (dq, dlambda, dy),
//     [beta' M + gamma' C + K   Phi_q^T   -F         ]
//     [Phi_q                    0          0         ]
//     [-(G_q + gamma' G_v)      0          c1 I - G_y],
// scaled as eq. (10) does the mechanical part (rows of the dynamics by beta h^2, lambda by
// 1 / (beta h^2)) and the first-order rows by 1 / c1, keeps a bounded condition number as
// h -> 0; without the 1 / c1 its first-order rows make it grow like 1 / h, and without any
// scaling it grows like 1 / h^4 (as the mechanical part alone does). A small coupled model
// with fixed blocks: n = 3, m = 1, r = 2.
void scaling_bounds_the_condition(void **)
{
    const int n = 3, m = 1, r = 2, N = n + m + r;
    Eigen::MatrixXd M(n, n), C(n, n), K(n, n), J(m, n), F(n, r), Gq(r, n), Gv(r, n), Gy(r, r);
    M << 2.0, 0.1, 0.0, 0.1, 1.0, 0.0, 0.0, 0.0, 0.5;
    C << 0.3, 0.0, 0.1, 0.0, 0.2, 0.0, 0.1, 0.0, 0.4;
    K << 50.0, -10.0, 0.0, -10.0, 40.0, 5.0, 0.0, 5.0, 30.0;
    J << 1.0, -0.5, 0.3;
    F << 0.0, 1.5, 2.0, 0.0, 0.0, -1.0;
    Gq << 0.4, 0.0, -0.2, 0.0, 1.0, 0.0;
    Gv << 0.0, 3.0, 0.0, -1.0, 0.0, 0.5;
    Gy << -20.0, 4.0, -1.0, -5.0;
    const ga::Params p = ga::params_from_rho_inf(0.8);
    const ga::FirstOrderParams p1 = ga::first_order_params_from_rho_inf(0.8);
    double kappa[3][3];  // [scaling][h]: none, mechanical only, full
    const double hs[3] = {1e-2, 1e-4, 1e-6};
    for (int k = 0; k < 3; ++k) {
        const double h = hs[k];
        const ga::NewtonCoefficients c = ga::newton_coefficients(p, h);
        const double c1 = ga::first_order_newton_coefficient(p1, h), bh2 = p.beta * h * h;
        Eigen::MatrixXd S = Eigen::MatrixXd::Zero(N, N);
        S.block(0, 0, n, n) = c.beta_prime * M + c.gamma_prime * C + K;
        S.block(0, n, n, m) = J.transpose();
        S.block(0, n + m, n, r) = -F;
        S.block(n, 0, m, n) = J;
        S.block(n + m, 0, r, n) = -(Gq + c.gamma_prime * Gv);
        S.block(n + m, n + m, r, r) = c1 * Eigen::MatrixXd::Identity(r, r) - Gy;
        for (int scaling = 0; scaling < 3; ++scaling) {
            Eigen::VectorXd dl = Eigen::VectorXd::Ones(N), dr = Eigen::VectorXd::Ones(N);
            if (scaling >= 1) {
                dl.head(n).setConstant(bh2);
                dr.segment(n, m).setConstant(1.0 / bh2);
            }
            if (scaling == 2)
                dl.tail(r).setConstant(1.0 / c1);
            const Eigen::MatrixXd Sb = dl.asDiagonal() * S * dr.asDiagonal();
            const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Sb);
            const Eigen::VectorXd sv = svd.singularValues();
            kappa[scaling][k] = sv(0) / sv(N - 1);
        }
    }
    for (int scaling = 0; scaling < 3; ++scaling)
        std::printf("    %s: condition %.2e %.2e %.2e at h = 1e-2, 1e-4, 1e-6\n",
                    scaling == 0 ? "unscaled" : scaling == 1 ? "eq. (10) only" : "full",
                    kappa[scaling][0], kappa[scaling][1], kappa[scaling][2]);
    // bounded: the same to a few per cent from h = 1e-4 to 1e-6
    assert_true(kappa[2][2] < 1.05 * kappa[2][1] && kappa[2][2] < 1e3);
    // the others grow like 1 / h (first-order rows unscaled) and 1 / h^4
    assert_true(kappa[1][2] > 50.0 * kappa[1][1]);
    assert_true(kappa[0][2] > 5e7 * kappa[0][1]);
}

}  // namespace

int main()
{
    const CMUnitTest tests[] = {
        cmocka_unit_test(parameters_satisfy_their_conditions),
        cmocka_unit_test(stiff_limit_is_rho_inf),
        cmocka_unit_test(order_two_and_quadratic_newton),
        cmocka_unit_test(corrected_start_makes_w_second_order),
        cmocka_unit_test(scaling_bounds_the_condition),
    };
    return cmocka_run_group_tests(tests, nullptr, nullptr);
}
