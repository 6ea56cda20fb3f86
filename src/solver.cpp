// The transaction's construction, its services' options and its checkpoints: the kernel's
// share with the controller's entries, then the forward sensitivities' tail (checkpoint.cpp
// holds the layout).
#include "solver.hpp"

#include "derivative_check.hpp"

namespace ga {

Solver::Solver(const ConfigurationSpace &space, int m)
    : k_(space, m), diag(k_.diag), model(k_.model)
{
    k_.attach(*this);
}

ga_status Solver::init(double t0, const double *q0, const double *v0)
{
    const ga_status st = k_.init(t0, q0, v0);
    if (!st)
        control.reset();  // no accepted step: no proposal, no base for a prediction
    return st;
}

ga_status Solver::init_y(double t0, const double *q0, const double *v0, const double *y0)
{
    const ga_status st = k_.init_y(t0, q0, v0, y0);
    if (!st)
        control.reset();
    return st;
}

ga_status Solver::set_sensitivity(int np, double *p, const double *p_scale, int depends)
{
    const bool ready = k_.setup_done();
    forward_.set(np, p, p_scale, depends, k_.nq(), k_.nv(), k_.m(), k_.r(),
                 ready ? &k_.matrix(GA_MATRIX_MASS) : nullptr,
                 ready ? &k_.matrix(GA_MATRIX_JACOBIAN) : nullptr);
    adjoint_.forget();  // the method is forward again (ga_set_sensitivity_method)
    return GA_OK;
}

ga_status Solver::set_sensitivity_start(int j, const double *dq0, const double *dv0)
{
    forward_.set_start(j, dq0, dv0, k_.nv());
    return GA_OK;
}

ga_status Solver::set_sensitivity_method(int methods, long max_steps)
{
    return adjoint_.set_method(methods, max_steps);
}

ga_status Solver::set_adjoint_checkpoints(long interval, long count)
{
    return adjoint_.set_checkpoints(interval, count);
}

ga_status Solver::adjoint_gradient(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ)
{
    return adjoint_.gradient(running, terminal, J, dJ);
}

ga_status Solver::check_derivatives(double t, const double *q, const double *v, const double *qdd,
                                    const double *lambda, const double *y, double tol,
                                    double *worst)
{
    return ga::check_derivatives(k_, forward_.sens, t, q, v, qdd, lambda, y, tol, worst);
}

// ---- checkpoints ----
std::size_t Solver::sensitivity_tail() const { return forward_.checkpoint_size(); }

std::size_t Solver::state_size() const { return k_.checkpoint_size() + sensitivity_tail(); }

void Solver::get_state(double *buf) const
{
    k_.save_checkpoint(buf, control);
    forward_.save_checkpoint(buf + k_.checkpoint_size());
}

ga_status Solver::set_state(const double *buf, std::size_t len, bool internal, bool keep_matrix)
{
    return k_.undoing_a_first_setup([&] { return restore_state(buf, len, internal, keep_matrix); });
}

ga_status Solver::restore_state(const double *buf, std::size_t len, bool internal, bool keep_matrix)
{
    if (auto st = k_.check_checkpoint(buf, len, sensitivity_tail()))
        return st;
    if (forward_.sens.adjoint && !internal)
        return k_.diag.fail(GA_ERR_STATE,
                            "ga_set_state on a run recorded for the adjoint: the "
                            "record starts at ga_init (restoring into it is not built)");
    const bool layout3 = buf[1] == 3.0;
    const bool layout2 = buf[1] == 2.0;
    const ga_status st = k_.load_checkpoint(buf, internal, keep_matrix, control);
    if (!st && !layout2)
        forward_.load_checkpoint(buf + k_.checkpoint_size(layout3));
    if (!st)
        events_.restart();
    return st;
}

}  // namespace ga
