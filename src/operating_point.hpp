// Operating points of the model (docs/algorithms.md sec. 15): its static equilibrium, the
// linearization about one in minimal coordinates, and the undamped vibration modes there.
// From the callbacks the dynamics already uses; the solver's state and set-up are not touched.
#pragma once

#include "stepper.hpp"

namespace ga {

// Newton on f(q, 0, t) = Phi_q^T lambda, Phi(q, t) = 0 from q, with a backtracking line
// search; on GA_OK q and lambda (may be null) hold the equilibrium, else they are untouched.
ga_status static_equilibrium(Stepper &kernel, double t, double *q, double *lambda, double tol,
                             int max_iter);

// With first-order states y (r of them) as unknowns too: f(q, 0, y) = Phi_q^T lambda,
// g(q, 0, y) = 0, Phi = 0 (y null: static_equilibrium's problem, dense).
ga_status static_equilibrium_y(Stepper &kernel, double t, double *q, double *y, double *lambda,
                               double tol, int max_iter);

// The same on [K_t, Phi_q^T; Phi_q, 0] (static_saddle.cpp): for models the solver takes on
// its sparse path, where the null space would be dense; static_equilibrium goes there itself.
ga_status static_equilibrium_saddle(Stepper &kernel, double t, double *q, double *lambda,
                                    double tol, int max_iter);

// The system of the small motions about (q, lambda) at rest in minimal coordinates
// q = q0 + N z: dof = n - rank(Phi_q), N (n x dof, orthonormal columns), and the reduced
// mass, damping and stiffness (dof x dof); lambda null: the static multipliers at q. Each
// output may be null; none is written unless dof <= max_dof.
struct Linearization {
    int dof = 0;
    Mat N, M, C, K;
    double stiffness_size = 0.0;  // max |K_t| in q (a force scale: ga_modes)
};
ga_status linearize(Stepper &kernel, double t, const double *q, const double *lambda,
                    Linearization &out);

// The first-order form of the small motions about (q, y, lambda) at rest: x = (z, z', y),
// x' = A x, dim = 2 dof + r (y, lambda may be null: no states; the balancing multipliers).
struct StateSpace {
    int dof = 0, dim = 0;
    Mat N, A;
};
ga_status state_space(Stepper &kernel, double t, const double *q, const double *y,
                      const double *lambda, StateSpace &out);

// The same about a moving state (t, q, v, y) on the constraints, from the consistent
// acceleration (and the rates) in a chart of the constraint manifold (motion_state_space.cpp):
// dim = 2 dof + r; y may be null without first-order states.
ga_status motion_state_space(Stepper &kernel, double t, const double *q, const double *v,
                             const double *y, StateSpace &out);

// The `count` lowest undamped modes at an equilibrium (q, lambda): K z = omega^2 M z,
// omega^2 ascending (negative: unstable there), shapes N z in q with unit modal mass.
ga_status modes(Stepper &kernel, double t, const double *q, const double *lambda, int count,
                double *omega2, double *shapes);

// The `count` undamped modes at an equilibrium whose omega^2 lie nearest sigma, by
// shift-invert Lanczos on the saddle-point factorization (modes_near.cpp): omega2 ascending,
// shapes (may be null) in q with unit modal mass and their largest entry positive.
ga_status modes_near(Stepper &kernel, double t, const double *q, const double *lambda,
                     double sigma, int count, double *omega2, double *shapes);

// The `count` modes of the damped, possibly non-conservative system there, of
// x' = [0, I; -M^-1 K, -M^-1 C] x: eigenvalues s by |s| (a pair's positive imaginary part
// first), displacement shapes N z in q with their largest entry 1 (each output may be null).
ga_status damped_modes(Stepper &kernel, double t, const double *q, const double *lambda,
                       int count, double *re, double *im, double *shapes_re, double *shapes_im);

// The equilibrium path in the load factor *load (which the callbacks read) from (q, *load) by
// pseudo-arclength continuation, through limit points; fn (may be null) sees each point.
ga_status static_path(Stepper &kernel, double t, double *load, double *q, double *lambda,
                      double ds, int max_points, double tol, ga_path_fn fn, void *fn_user);

}  // namespace ga
