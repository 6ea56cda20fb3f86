// Forward sensitivities of the discrete solution (docs/algorithms.md sec. 11): what they are
// taken with respect to, their values at the accepted step and the step being computed, and
// the scratch of their step; and the service that computes them (ForwardSensitivity,
// sensitivity.cpp), attached to the step transaction at its doors.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "galpha.h"
#include "matrix.hpp"
#include "state.hpp"
#include "step_plan.hpp"
#include "types.hpp"

namespace ga {

// d/dp_j of the quantities a step carries from one state to the next (with r first-order
// states also y, y' and w).
struct StateDerivative {
    Vec q, v, qdd, lambda, a;
    Vec y, ydot, w;
    void allocate(int nv, int m, int r = 0)  // (d/dp of q is a tangent: nv)
    {
        const int n = nv;
        q.setZero(n);
        v.setZero(n);
        qdd.setZero(n);
        lambda.setZero(m);
        a.setZero(n);
        y.setZero(r);
        ydot.setZero(r);
        w.setZero(r);
    }
    void swap(StateDerivative &o)
    {
        for (auto [a, b] : {std::pair{&q, &o.q}, {&v, &o.v}, {&qdd, &o.qdd}, {&lambda, &o.lambda},
                            {&a, &o.a}, {&y, &o.y}, {&ydot, &o.ydot}, {&w, &o.w}})
            a->swap(*b);
    }
};

struct Sensitivities {
    int np = 0;
    double *p = nullptr;        // the user's parameters, perturbed in place by differences
    std::vector<double> scale;  // of those perturbations (p_scale)
    int depends = GA_DEPENDS_FORCE;
    bool forward = true;   // GA_SENSITIVITY_FORWARD: derivatives after each step
    bool adjoint = false;  // GA_SENSITIVITY_ADJOINT: the run recorded (AdjointRecord)

    // d q0 / dp_j and d v0 / dp_j as given (ga_set_sensitivity_start; zero unless given)
    std::vector<Vec> seed_q, seed_v;
    std::vector<StateDerivative> accepted, trial;
    // The step's start (v_n, a_n, qdd_n as the step uses them) when it is not the accepted
    // state's own: fresh starts and their corrected values, by differences.
    std::vector<StateDerivative> start;
    StateDerivative wide;      // a difference at the wider increment (extrapolated differences)
    bool start_given = false;  // start holds this step's
    bool step_done = false;    // a Taylor step (sliver): trial holds its derivative already

    // scratch of one step
    Vec rq, rl, rv, d, w, dl, e, f_plus, f_minus, bt, a0, xq, xv;
    Vec bracket;  // [s, v] on a group (the curvature's part a pattern's Z leaves out)
    Vec q_pert;  // a point of q along a tangent (correction_derivative)
    Vec ry, dy, gy, w0, rate_plus, rate_minus;  // first-order states (r)
    // the constraints' parameter terms (GA_DEPENDS_CONSTRAINT): in r^q, Phi, the velocity
    // constraint and the index-2 position correction; phi is scratch
    Vec cq, cl, cv, cbt, phi;
    Vec cq2, cl2, cv2, cbt2;  // the same at the wider increment (extrapolation)
    ModelMatrix M_pert, J_pert;

    bool active() const { return np > 0; }
    // Sizes the vectors, and the matrices in the layouts of M and Phi_q (at setup, when the
    // patterns are known); throw std::bad_alloc.
    void allocate(int nq, int nv, int m, int r);
    void allocate_matrices(const ModelMatrix &M, const ModelMatrix &J);
    // The perturbation of p_j for central differences, and the wider one of extrapolated
    // differences, (4 D(e/2) - D(e)) / 3 with error O(eps^(4/5)).
    double increment(int j) const;
    double extrapolated_increment(int j) const;
};

class Stepper;

// The forward sensitivities as a service of the step (docs/algorithms.md sec. 11): their start
// at ga_init, the starts by differences before Taylor steps and fresh starts, the linear step
// once a step converged, their half of a commit and of its undoing; and the derivatives in p
// of the residual and the constraints, which the adjoint sweep uses too. It works through the
// solver's kernel (`k_`): the start functions, the exact iteration matrix and its solves.
class ForwardSensitivity {
public:
    explicit ForwardSensitivity(Stepper &kernel) : k_(kernel) {}
    ForwardSensitivity(const ForwardSensitivity &) = delete;
    ForwardSensitivity &operator=(const ForwardSensitivity &) = delete;

    Sensitivities sens;

    // ga_set_sensitivity (the C API validated the arguments): allocates aside, so that
    // std::bad_alloc leaves the set as it was.
    void set(int np, double *p, const double *p_scale, int depends, int nq, int nv, int m, int r,
             const ModelMatrix *M, const ModelMatrix *J);
    void set_start(int j, const double *dq0, const double *dv0, int nv);

    // The doors of the transaction (transaction.cpp).
    ga_status start(const State &x);  // at ga_init, before the consistent accelerations
    void started() { sens.accepted.swap(sens.trial); }
    ga_status before_attempt(const StepPlan &plan, const State &accepted);
    ga_status step(double h);  // after a step converged
    void on_commit();          // after the states' swap
    void on_undo();            // after undo_step's swaps
    // Their tail of a checkpoint: d/dp_j of q, v, qdd, lambda, a, y, y', w for each j.
    std::size_t checkpoint_size() const;
    void save_checkpoint(double *p) const;
    void load_checkpoint(const double *p);

    // d/dp_j of the residual and the constraints at a converged step x (into sens.rq, sens.ry,
    // sens.cq, cl, cv, cbt), and -d/dq (Phi_q^T eta) s: the forward step's and the adjoint's.
    ga_status parameter_residual(int j, double t, const State &x);
    ga_status rate_parameter_residual(int j, double t, const State &x);
    ga_status constraint_parameter_terms(int j, double t, const State &x, bool velocity,
                                         bool correction, double t_n, const Vec &q_n,
                                         const Vec &eta);
    ga_status correction_derivative(double t, const Vec &q, const Vec &eta, const Vec &s, Vec &out);

private:
    template <class Perturb, class Evaluate>
    ga_status central_difference(int j, Perturb &&perturb, Evaluate &&evaluate, double &span,
                                 double increment = 0.0);
    ga_status project_seeds(const State &x, int j, StateDerivative &s);
    void shift_state(const State &from, const StateDerivative &s, double shift, State &to) const;
    ga_status by_differences(const State &accepted, double h, bool taylor_step, bool restart_short);

    State scratch_;  // the accepted state moved along a derivative (by_differences)
    Stepper &k_;
};

}  // namespace ga
