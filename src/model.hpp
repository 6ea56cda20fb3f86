// ga::Model: the user's callbacks behind one interface. Maps callback return codes to statuses,
// rejects non-finite outputs, counts evaluations, and supplies finite-difference fallbacks for
// the optional pieces (tangent stiffness, tangent damping, constraint acceleration term, Phi_t).
// Finite differences of sparse tangents perturb groups of structurally independent columns
// together (Curtis-Powell-Reid), so a banded or block-diagonal K_t costs a few evaluations,
// not n.
#pragma once

#include <cfenv>
#include <cmath>
#include <utility>
#include <vector>

#include "configuration_space.hpp"
#include "diagnostics.hpp"
#include "matrix.hpp"

namespace ga {

struct Callbacks {
    ga_mass_fn mass = nullptr;
    ga_force_fn force = nullptr;
    ga_constraint_fn constraint = nullptr;
    ga_jacobian_fn jacobian = nullptr;
    ga_stiffness_fn stiffness = nullptr;
    ga_damping_fn damping = nullptr;
    ga_constraint_accel_fn constraint_accel = nullptr;
    ga_constraint_fn constraint_dt = nullptr;
    // first-order states (ga_set_first_order, ga_set_coupling)
    ga_force_y_fn force_y = nullptr;
    ga_rate_fn rate = nullptr;
    ga_coupling_fn coupling = nullptr;
    // parameter derivatives (ga_set_parameter_derivatives)
    ga_force_p_fn force_p = nullptr;
    ga_mass_p_fn mass_p = nullptr;
    ga_constraint_p_fn constraint_p = nullptr;  // ga_set_constraint_parameter_derivative
    void *user = nullptr;
};

// The coupling blocks of first-order states, dense: g_q, g_v (r x nv), g_y (r x r), f_y
// (nv x r).
struct CouplingBlocks {
    Mat g_q, g_v, g_y, f_y;
    void allocate(int nv, int r)
    {
        g_q.setZero(r, nv);
        g_v.setZero(r, nv);
        g_y.setZero(r, r);
        f_y.setZero(nv, r);
    }
};

// Columns of a sparse matrix grouped so that no two columns of a group share a row.
struct ColumnGroups {
    std::vector<int> start;    // group g holds columns cols[start[g] .. start[g+1])
    std::vector<int> cols;
    std::vector<int> entry_start;  // and pattern entries entries[entry_start[g] ..)
    std::vector<int> entries;      // (first occurrence of each (row, col) only)
    // space (columns that are q's increments): the columns of one rotation in separate
    // groups, since a shift of q in a rotation's column replaces the whole rotation
    void build(const ModelMatrix &A, const ConfigurationSpace *space = nullptr);
    int count() const { return start.empty() ? 0 : static_cast<int>(start.size()) - 1; }
};

class Model {
public:
    Model(const ConfigurationSpace &space, int m, Counters &counters, Diagnostics &diag);

    // The problem's q: where it lives and how it moves (configuration_space.hpp)
    const ConfigurationSpace space;
    Callbacks cb;
    // The caller's floating-point environment while a call runs with its traps held (the C
    // shim sets it when the caller has traps enabled): callbacks run in it, galpha's own
    // arithmetic, which meets NaN and Inf on purpose to report them, does not.
    const std::fenv_t *caller_fenv = nullptr;
    ga_tangent_mode tangent_mode = GA_TANGENT_AUTO;
    bool constant_mass = false;

    // Scratch for finite differences, shaped like the solver's matrices (setup only).
    void allocate_workspace(const ModelMatrix &M, const ModelMatrix &J, const ModelMatrix &K,
                            const ModelMatrix &C);
    // The part of it that depends on the options (tangent callbacks and mode, constant mass):
    // built at setup, and again by the option setters when an option change needs more, so
    // that steps never allocate. Builds only what is missing.
    void prepare_differences(const ModelMatrix &M, const ModelMatrix &K, const ModelMatrix &C);

    bool ready() const { return cb.mass != nullptr && (m_ == 0 || (cb.constraint && cb.jacobian)); }

    // First-order states (docs/algorithms.md sec. 9): their number, and the states the force
    // callback sees. The solver points y_now at the states that belong with each (t, q, v) it
    // evaluates f at; with r = 0 the force is that of ga_set_callbacks and y_now is unused.
    int first_order_count() const { return r_; }
    // r first-order states; their coupling patterns (declared by ga_set_coupling_pattern)
    // start dense.
    void set_first_order_count(int r)
    {
        r_ = r;
        g_q_pattern.set_dense(r, nv_);
        g_v_pattern.set_dense(r, nv_);
    }
    // Where g_q, g_v may be nonzero (dense: anywhere): their differences perturb the columns
    // of a group together (ColumnGroups, built at setup).
    ModelMatrix g_q_pattern, g_v_pattern;
    const Vec *y_now = nullptr;
    // y' = g(t, q, v, y) into ydot (length r).
    ga_status rate(double t, const Vec &q, const Vec &v, const Vec &y, Vec &ydot);
    // The coupling blocks at (t, q, v, y): the callback, or forward differences from f and
    // g there (f = f(t, q, v, y), ydot = g(t, q, v, y)).
    ga_status coupling(double t, const Vec &q, const Vec &v, const Vec &y, const Vec &f,
                       const Vec &ydot, CouplingBlocks &B, bool central = false);
    bool uses_tangents() const { return tangent_mode != GA_TANGENT_NEGLECT; }
    // applied forces exist: the callback of ga_set_callbacks, or with first-order states theirs
    bool has_force() const { return cb.force || (r_ > 0 && cb.force_y); }
    bool stiffness_needed(const ModelMatrix &K) const { return uses_tangents() && !K.zero(); }
    bool damping_needed(const ModelMatrix &C) const
    {
        return uses_tangents() && !C.zero() && (has_force() || cb.damping);
    }

    // Callback values are checked for NaN and Inf as they come (Now), or by the caller
    // (Deferred) through a result that every value enters, with check_deferred() naming the
    // culprit only if that result is not finite: Stepper::residual checks r^q, which takes in
    // every entry of f and Phi_q, instead of f and Phi_q (at 100 000 chain links 6 MB less
    // to read per Newton iteration).
    enum class Check { Now, Deferred };
    ga_status mass(double t, const Vec &q, ModelMatrix &M);
    ga_status force(double t, const Vec &q, const Vec &v, Vec &f, Check check = Check::Now);
    ga_status constraint(double t, const Vec &q, Vec &phi);
    ga_status jacobian(double t, const Vec &q, ModelMatrix &J, Check check = Check::Now);
    // The status and message the immediate checks of f and Phi_q would have given (GA_OK if
    // both are finite).
    ga_status check_deferred(double t, const Vec &f, const ModelMatrix &J);
    // Z = d/dq (Phi_q(q, t) v + Phi_t(q, t)), the curvature block of the index-2 velocity
    // constraint, from J = Phi_q(q, t) and one more Jacobian evaluation (layout of J).
    // central: differences on both sides (error O(eps^(2/3)) instead of O(eps^(1/2)), twice
    // the evaluations), here and for K_t and C_t below.
    ga_status velocity_constraint_tangent(double t, const Vec &q, const Vec &v,
                                          const ModelMatrix &J, ModelMatrix &Z,
                                          bool central = false);

    // K_t = d r^q / dq at fixed v, qdd, lambda. rq is r^q at q, M the mass matrix at q (both
    // used by finite differences; with a constant mass M is not evaluated again).
    ga_status stiffness(double t, const Vec &q, const Vec &v, const Vec &qdd, const Vec &lambda,
                        const Vec &rq, const ModelMatrix &M, ModelMatrix &K,
                        bool central = false);
    // C_t = -df/dv. f is f(q, v, t) (used by finite differences).
    ga_status damping(double t, const Vec &q, const Vec &v, const Vec &f, ModelMatrix &C,
                      bool central = false);
    // df/dp_j, and (dM/dp_j) a, by the callbacks of ga_set_parameter_derivatives.
    ga_status force_p(double t, const Vec &q, const Vec &v, int j, Vec &out);
    ga_status mass_p(double t, const Vec &q, int j, const Vec &a, Vec &out);
    // dPhi/dp_j, dPhi_q/dp_j (layout of J) and, when phi_tp is given, dPhi_t/dp_j, by the
    // callback of ga_set_constraint_parameter_derivative.
    ga_status constraint_p(double t, const Vec &q, int j, Vec &phi_p, ModelMatrix &J_p,
                           Vec *phi_tp);
    // A cost term of ga_adjoint_gradient (q, v, qdd, lambda as recorded): its value and its
    // gradients, checked.
    ga_status cost(ga_cost_fn fn, double t, const double *q, const double *v, const double *qdd,
                   const double *lambda, double &value, Vec &d_q, Vec &d_v, Vec &d_qdd,
                   Vec &d_lambda, Vec &d_p);
    // Phi_qq(v, v) + 2 Phi_qt v + Phi_tt.
    ga_status constraint_accel(double t, const Vec &q, const Vec &v, Vec &out);
    // Phi_t: the callback, or extrapolated central differences in t (exactly zero for
    // time-independent constraints); coarse: one central difference (two calls instead of
    // four: enough for a check).
    ga_status constraint_dt(double t, const Vec &q, Vec &out, bool coarse = false);
    // The event functions of ga_set_events or ga_set_events_y: `count` values into g (lambda
    // may be null).
    // Inline: called after every step, where a run with events that never fire should cost
    // no more than the call itself.
    // fn_y (ga_set_events_y), when set, takes the first-order states y as well.
    ga_status event_functions(ga_event_fn fn, ga_event_y_fn fn_y, double t, const double *q,
                              const double *v, const double *y, const double *lambda, double *g,
                              int count)
    {
        count_event();
        if (const int rc = user([&] {
                return fn_y ? fn_y(t, q, v, y, lambda, g, cb.user) : fn(t, q, v, lambda, g, cb.user);
            }))
            return callback_status(rc, "event", t);
        bool finite = true;
        for (int k = 0; k < count; ++k)
            finite = finite && std::isfinite(g[k]);
        return finite ? GA_OK : check_finite(g, count, 0, "event function g", t);
    }

    // r^q = M qdd - f + Phi_q^T lambda: the residual of eq. (1), not weighted.
    static void dynamics_residual(const ModelMatrix &M, const Vec &qdd, const Vec &f,
                                  const ModelMatrix &J, const Vec &lambda, Vec &rq);

    // A user function outside the model (the step hook), in the caller's environment as well.
    template <class Call>
    int run_user(Call &&call)
    {
        return user(std::forward<Call>(call));
    }

private:
    void count_event() { ga::count(counters_, GA_COUNT_EVENT_EVALS); }
    // Runs a user callback in the caller's floating-point environment (see caller_fenv).
    template <class Call>
    int user(Call &&call)
    {
        if (!caller_fenv)
            return call();
        std::fenv_t held;
        std::fesetenv(caller_fenv);
        const int rc = call();
        std::feholdexcept(&held);
        return rc;
    }
    ga_status callback_status(int rc, const char *name, double t);
    ga_status check_finite(const double *x, Eigen::Index size, Eigen::Index rows,
                           const char *what, double t);
    ga_status perturbed_residual(double t, const Vec &qp, const Vec &v, const Vec &qdd,
                                 const Vec &lambda, const ModelMatrix &M, Vec &r);

    int nv_, m_;  // v's coordinates (q's: space.nq())
    Counters &counters_;
    Diagnostics &diag_;
    // finite-difference scratch
    Vec q_pert_, v_pert_, f_pert_, r_pert_, r_minus_, f_minus_, phi_plus_, phi_minus_, g_plus_,
        g_minus_, step_;
    int r_ = 0;
    Vec y_pert_, rate_pert_, rate_minus_;  // first-order differences
    ColumnGroups g_q_groups_, g_v_groups_;
    // one block of g_q or g_v (column j from the states perturbed in x) by differences
    ga_status coupling_block(double t, const Vec &q, const Vec &v, const Vec &y, const Vec &ydot,
                             bool of_q, const ModelMatrix &pattern, const ColumnGroups &groups,
                             Mat &G, bool central);
    ModelMatrix M_pert_, J_pert_;
    ColumnGroups k_groups_, c_groups_;
};

}  // namespace ga
