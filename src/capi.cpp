// The C ABI: argument checks, the re-entrancy guard, exceptions turned into statuses.
// No mathematics here; it lives in the ga:: core.
#include <algorithm>
#include <cfenv>
#include <climits>
#include <cmath>
#include <cstddef>
#include <exception>
#include <new>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "galpha.h"
#include "operating_point.hpp"
#include "params.hpp"
#include "solver.hpp"

#include "capi_internal.hpp"

namespace {

// Floating-point traps the caller enabled (feenableexcept) are held while galpha's own code
// runs, which meets NaN and Inf on purpose (arguments, callback outputs) to report them as
// statuses, and restored for the callbacks and on return. Nothing happens without traps.
class TrapsHeld {
public:
    explicit TrapsHeld(ga::Model &model) : model_(model)
    {
#ifdef __GLIBC__
        if (fegetexcept() != 0) {
            std::feholdexcept(&caller_);
            model_.caller_fenv = &caller_;
        }
#endif
    }
    ~TrapsHeld()
    {
        if (model_.caller_fenv) {
            model_.caller_fenv = nullptr;
            std::fesetenv(&caller_);
        }
    }
    TrapsHeld(const TrapsHeld &) = delete;
    TrapsHeld &operator=(const TrapsHeld &) = delete;

private:
    ga::Model &model_;
    std::fenv_t caller_;
};

// `body` on the core, every C++ exception turned into a status.
template <class Body>
ga_status caught(ga::Solver &core, Body &&body)
{
    try {
        return body(core);
    } catch (const std::bad_alloc &) {
        return core.diag.fail(GA_ERR_NOMEM, "out of memory");
    } catch (const std::length_error &e) {  // a size beyond any vector: memory too, not a bug
        return core.diag.fail(GA_ERR_NOMEM, "out of memory: %s", e.what());
    } catch (const std::exception &e) {
        return core.diag.fail(GA_ERR_INTERNAL, "unexpected C++ exception: %s", e.what());
    } catch (...) {
        return core.diag.fail(GA_ERR_INTERNAL, "unexpected C++ exception of unknown type");
    }
}

void forget_refusal(ga_solver *s, std::thread::id me)
{
    std::thread::id was = me;
    s->refused.compare_exchange_strong(was, std::thread::id());
}

// Runs `body` as one API call on `s`: refuses calls from inside the solver's own callbacks,
// clears the last error if asked, and converts every C++ exception into a status.
template <class Body>
ga_status call(ga_solver *s, bool clear_message, Body &&body)
{
    if (!s)
        return GA_ERR_ARG;
    bool idle = false;
    const std::thread::id me = std::this_thread::get_id();
    if (!s->busy.compare_exchange_strong(idle, true)) {
        s->refused.store(me);  // the message is the outer call's: ga_last_error says this
        return GA_ERR_STATE;
    }
    forget_refusal(s, me);
    const TrapsHeld traps(s->core.model);
    if (clear_message)
        s->core.diag.clear();
    const ga_status st = caught(s->core, std::forward<Body>(body));
    forget_refusal(s, me);  // (a callback's own call refused inside this one)
    s->busy = false;
    return st;
}

// Calls that may change the solver: they start with a clear message.
template <class Body>
ga_status guarded(ga_solver *s, Body &&body)
{
    return call(s, true, std::forward<Body>(body));
}

// A read-only call that failed says why in ga_last_error, instead of leaving an earlier
// failure's message there to mislead; unless another call holds the solver (then that call
// owns the message).
void explain(const ga_solver *s, ga_status st, const char *name, const char *bad_argument)
{
    auto *w = const_cast<ga_solver *>(s);
    bool idle = false;
    if (!w->busy.compare_exchange_strong(idle, true))
        return;
    if (st == GA_ERR_STATE)
        w->core.diag.fail(st, "%s before ga_init or ga_set_state", name);
    else
        w->core.diag.fail(st, "%s: %s", name, bad_argument);
    w->busy = false;
}

// Read-only calls: the same refusal from callbacks; they cannot throw, keep the message when
// they succeed and replace it when they fail (GA_ERR_ARG: `bad_argument` says which).
template <class Body>
ga_status reading(const ga_solver *s, const char *name, const char *bad_argument, Body &&body)
{
    if (!s)
        return GA_ERR_ARG;
    auto *w = const_cast<ga_solver *>(s);
    if (s->busy && !s->in_hook) {
        w->refused.store(std::this_thread::get_id());
        return GA_ERR_STATE;
    }
    forget_refusal(w, std::this_thread::get_id());
    const ga_status st = body(s->core);
    if (st != GA_OK)
        explain(s, st, name, bad_argument);
    return st;
}

// Calls that read the solver but may evaluate callbacks (consistent output): a success keeps
// the last message, as reads do. What they change is output scratch and counters, not the
// state, so they take the caller's const handle.
template <class Body>
ga_status computing(const ga_solver *s, Body &&body)
{
    auto *w = const_cast<ga_solver *>(s);
    if (w && w->in_hook) {
        // from the step hook, under the stepping call's guard; the callbacks this evaluates
        // are refused reads as any callback is
        w->in_hook = false;
        const ga_status st = caught(w->core, std::forward<Body>(body));
        w->in_hook = true;
        return st;
    }
    return call(w, false, std::forward<Body>(body));
}

ga_status copy_out(const ga::Solver &c, const ga::Vec &x, double *out)
{
    if (!out)
        return GA_ERR_ARG;
    if (!c.kernel().initialized())
        return GA_ERR_STATE;
    Eigen::Map<ga::Vec>(out, x.size()) = x;
    return GA_OK;
}

}  // namespace

namespace {
// Changes an option that shapes the tangents; a failure (no place on the sparse path, out of
// memory) puts every such option back: a failed call leaves the solver as it was.
template <class Change>
ga_status change_tangents(ga::Solver &c, Change &&change)
{
    const ga::Callbacks cb = c.model.cb;
    const ga_tangent_mode mode = c.model.tangent_mode;
    const bool constant_mass = c.model.constant_mass;
    const auto restore = [&] {
        c.model.cb = cb;
        c.model.tangent_mode = mode;
        c.model.constant_mass = constant_mass;
    };
    change();
    try {
        if (const ga_status st = c.kernel().tangent_options_changed()) {
            restore();
            return st;
        }
    } catch (...) {
        restore();
        throw;
    }
    return GA_OK;
}
}  // namespace

namespace {
// The checks both sensitivity reads share; `copy` reads the accepted step's derivatives.
template <class Copy>
ga_status read_sensitivity(const ga_solver *s, const char *name, int j, Copy &&copy)
{
    return reading(s, name, "j is not the index of a parameter", [&](const ga::Solver &c) {
        if (!c.kernel().initialized() || !c.sens().active() || !c.sens().forward)
            return GA_ERR_STATE;
        if (j < 0 || j >= c.sens().np)
            return GA_ERR_ARG;
        copy(c.sens().accepted[j]);
        return GA_OK;
    });
}

void put(const ga::Vec &from, double *to)
{
    if (to)
        Eigen::Map<ga::Vec>(to, from.size()) = from;
}
}  // namespace

extern "C" {

GA_API const char *ga_version(void)
{
#define GA_STR2(x) #x
#define GA_STR(x) GA_STR2(x)
    return GA_STR(GA_VERSION_MAJOR) "." GA_STR(GA_VERSION_MINOR) "." GA_STR(GA_VERSION_PATCH);
#undef GA_STR
#undef GA_STR2
}

GA_API int ga_version_number(void) { return GA_VERSION_NUMBER; }

GA_API const char *ga_strerror(int status)
{
    switch (status) {
    case GA_OK: return "success";
    case GA_ERR_ARG: return "invalid argument";
    case GA_ERR_STATE: return "call out of order or from inside a callback";
    case GA_ERR_NOMEM: return "out of memory";
    case GA_ERR_CALLBACK: return "callback failed (fatal)";
    case GA_ERR_CALLBACK_RETRY: return "callback failed (recoverable): step rejected";
    case GA_ERR_NONFINITE: return "NaN or Inf encountered";
    case GA_ERR_SINGULAR: return "singular matrix";
    case GA_ERR_NEWTON: return "Newton iteration did not converge";
    case GA_ERR_INCONSISTENT: return "inconsistent initial values";
    case GA_ERR_INTERNAL: return "internal error";
    case GA_ERR_STEP_SIZE: return "step size below its minimum";
    case GA_ERR_UNRESOLVED: return "step not resolved: h too large for the motion";
    case GA_ERR_DERIVATIVE: return "a derivative callback disagrees with finite differences";
    case GA_EVENT: return "stopped at an event";
    case GA_STOPPED: return "stopped by the step hook";
    }
    return "unknown status";
}

GA_API const char *ga_last_error(const ga_solver *s)
{
    if (!s)
        return "NULL solver";
    if (s->refused.load() == std::this_thread::get_id())
        return "call refused: another call holds this solver (from another thread, or from "
               "within one of its own callbacks); one solver per thread";
    return s->core.diag.text();
}

GA_API ga_status ga_create(int n, int m, ga_solver **out)
{
    if (!out)
        return GA_ERR_ARG;
    *out = nullptr;
    if (n < 1 || m < 0 || m > n || n > INT_MAX - m)
        return GA_ERR_ARG;
    try {
        *out = new ga_solver(n, m);
    } catch (const std::bad_alloc &) {
        return GA_ERR_NOMEM;
    } catch (...) {
        return GA_ERR_INTERNAL;
    }
    return GA_OK;
}

GA_API ga_status ga_create_space(int count, const int *kinds, const int *counts, int m,
                                 ga_solver **out)
{
    if (!out)
        return GA_ERR_ARG;
    *out = nullptr;
    if (count < 1 || !kinds || !counts || m < 0)
        return GA_ERR_ARG;
    using Space = ga::ConfigurationSpace;
    try {
        std::vector<Space::Block> blocks;
        long long nq = 0, nv = 0;
        for (int i = 0; i < count; ++i) {
            if (counts[i] < 1)
                return GA_ERR_ARG;
            const long long c = counts[i];
            switch (kinds[i]) {
            case GA_SPACE_VECTOR:
                blocks.push_back({Space::Kind::Vector, counts[i]});
                nq += c;
                nv += c;
                break;
            case GA_SPACE_SO3_QUATERNION:
            case GA_SPACE_SO3_MATRIX: {
                const bool quaternion = kinds[i] == GA_SPACE_SO3_QUATERNION;
                nq += (quaternion ? 4 : 9) * c;
                nv += 3 * c;
                if (nq > INT_MAX)  // (before a count of blocks that large is made)
                    return GA_ERR_ARG;
                for (int k = 0; k < counts[i]; ++k)
                    blocks.push_back(
                        {quaternion ? Space::Kind::Quaternion : Space::Kind::Matrix, 3});
                break;
            }
            case GA_SPACE_SE3:
                nq += 7 * c;
                nv += 6 * c;
                if (nq > INT_MAX)
                    return GA_ERR_ARG;
                for (int k = 0; k < counts[i]; ++k)
                    blocks.push_back({Space::Kind::Pose, 6});
                break;
            default: return GA_ERR_ARG;
            }
            if (nq > INT_MAX || nv > INT_MAX)
                return GA_ERR_ARG;
        }
        if (m > nv || nv > INT_MAX - m)
            return GA_ERR_ARG;
        *out = new ga_solver(Space(blocks), m);
    } catch (const std::bad_alloc &) {
        return GA_ERR_NOMEM;
    } catch (...) {
        return GA_ERR_INTERNAL;
    }
    return GA_OK;
}

GA_API ga_status ga_get_space_size(const ga_solver *s, int *nq, int *nv)
{
    return reading(s, "ga_get_space_size", "nq or nv is NULL", [&](const ga::Solver &c) {
        if (!nq || !nv)
            return GA_ERR_ARG;
        *nq = c.kernel().nq();
        *nv = c.kernel().nv();
        return GA_OK;
    });
}

GA_API void ga_free(ga_solver *s)
{
    if (!s || s->busy)  // freeing a solver from its own callback would pull the floor away
        return;
    delete s;
}

GA_API ga_status ga_get_size(const ga_solver *s, int *n, int *m)
{
    return reading(s, "ga_get_size", "n or m is NULL", [&](const ga::Solver &c) {
        if (!n || !m)
            return GA_ERR_ARG;
        *n = c.kernel().nv();  // (ga_create's n; ga_create_space's nv)
        *m = c.kernel().m();
        return GA_OK;
    });
}

GA_API ga_status ga_set_callbacks(ga_solver *s, ga_mass_fn mass, ga_force_fn force,
                                  ga_constraint_fn constraint, ga_jacobian_fn jacobian,
                                  void *user)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!mass)
            return c.diag.fail(GA_ERR_ARG, "the mass matrix callback is required");
        if (c.kernel().m() > 0 && (!constraint || !jacobian))
            return c.diag.fail(GA_ERR_ARG, "m = %d > 0: constraint and jacobian callbacks are "
                               "required", c.kernel().m());
        c.model.cb.mass = mass;
        c.model.cb.force = force;
        c.model.cb.constraint = c.kernel().m() > 0 ? constraint : nullptr;
        c.model.cb.jacobian = c.kernel().m() > 0 ? jacobian : nullptr;
        c.model.cb.user = user;
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_tangents(ga_solver *s, ga_stiffness_fn stiffness, ga_damping_fn damping)
{
    return guarded(s, [&](ga::Solver &c) {
        return change_tangents(c, [&] {
            c.model.cb.stiffness = stiffness;
            c.model.cb.damping = damping;
        });
    });
}

GA_API ga_status ga_set_tangent_mode(ga_solver *s, int mode)
{
    return guarded(s, [&](ga::Solver &c) {
        if (mode != GA_TANGENT_AUTO && mode != GA_TANGENT_FD && mode != GA_TANGENT_NEGLECT)
            return c.diag.fail(GA_ERR_ARG, "unknown tangent mode %d", mode);
        return change_tangents(c, [&] { c.model.tangent_mode = static_cast<ga_tangent_mode>(mode); });
    });
}

GA_API ga_status ga_set_constraint_accel(ga_solver *s, ga_constraint_accel_fn fn)
{
    return guarded(s, [&](ga::Solver &c) {
        c.model.cb.constraint_accel = fn;
        return GA_OK;
    });
}

GA_API ga_status ga_set_constraint_dt(ga_solver *s, ga_constraint_fn fn)
{
    return guarded(s, [&](ga::Solver &c) {
        c.model.cb.constraint_dt = fn;
        return GA_OK;
    });
}

GA_API ga_status ga_set_rho_inf(ga_solver *s, double rho_inf)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(rho_inf >= 0.0 && rho_inf <= 1.0))
            return c.diag.fail(GA_ERR_ARG, "rho_inf = %g is outside [0, 1]", rho_inf);
        c.kernel().params = ga::params_from_rho_inf(rho_inf);
        c.kernel().params1 = ga::first_order_params_from_rho_inf(rho_inf);
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_params(ga_solver *s, double alpha_m, double alpha_f, double beta,
                               double gamma)
{
    return guarded(s, [&](ga::Solver &c) {
        const ga::Params p{alpha_m, alpha_f, beta, gamma};
        if (const char *why = ga::check_params(p))
            return c.diag.fail(GA_ERR_ARG, "parameters refused: %s", why);
        c.kernel().params = p;
        // the first-order states' damping from the same alpha_f = rho_inf / (1 + rho_inf)
        c.kernel().params1 = ga::first_order_params_from_rho_inf(
            std::min(1.0, std::max(0.0, alpha_f / (1.0 - alpha_f))));
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_get_params(const ga_solver *s, double *alpha_m, double *alpha_f,
                               double *beta, double *gamma)
{
    return reading(s, "ga_get_params", "no argument can fail", [&](const ga::Solver &c) {
        if (alpha_m)
            *alpha_m = c.kernel().params.alpha_m;
        if (alpha_f)
            *alpha_f = c.kernel().params.alpha_f;
        if (beta)
            *beta = c.kernel().params.beta;
        if (gamma)
            *gamma = c.kernel().params.gamma;
        return GA_OK;
    });
}

GA_API ga_status ga_set_newton(ga_solver *s, double tol, int max_iter)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(tol > 0.0 && tol < 1.0))
            return c.diag.fail(GA_ERR_ARG, "Newton tolerance %g is outside (0, 1)", tol);
        if (max_iter < 1)
            return c.diag.fail(GA_ERR_ARG, "max_iter = %d < 1", max_iter);
        c.kernel().newton_tol = tol;
        c.kernel().max_iter = max_iter;
        return GA_OK;
    });
}

GA_API ga_status ga_set_scaling(ga_solver *s, int on)
{
    return guarded(s, [&](ga::Solver &c) {
        if (on != 0 && on != 1)
            return c.diag.fail(GA_ERR_ARG, "scaling must be 0 or 1, got %d", on);
        c.kernel().scaling = on == 1;
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_jacobian_reuse(ga_solver *s, int mode)
{
    return guarded(s, [&](ga::Solver &c) {
        if (mode != GA_REUSE_AUTO && mode != GA_REUSE_NEVER)
            return c.diag.fail(GA_ERR_ARG, "unknown reuse mode %d", mode);
        c.kernel().reuse = static_cast<ga_reuse_mode>(mode);
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_constant_mass(ga_solver *s, int on)
{
    return guarded(s, [&](ga::Solver &c) {
        if (on != 0 && on != 1)
            return c.diag.fail(GA_ERR_ARG, "constant mass must be 0 or 1, got %d", on);
        if (on == 1 && c.sens().active() && (c.sens().depends & GA_DEPENDS_MASS))
            return c.diag.fail(GA_ERR_STATE, "the mass matrix depends on the sensitivity "
                               "parameters (GA_DEPENDS_MASS): it is not constant");
        return change_tangents(c, [&] { c.model.constant_mass = on == 1; });
    });
}

namespace {
// What a space with rotations does not offer yet (ga_create_space): refused with its name.
ga_status refuse_on_rotations(ga::Solver &c, const char *what)
{
    return c.diag.fail(GA_ERR_ARG,
                       "%s is not available on a configuration space with rotations "
                       "(ga_create_space) in this version",
                       what);
}

// The checks and the declaration shared by both forms of ga_set_pattern.
ga_status declare_pattern(ga::Solver &c, int which, int nnz, const int *rows, const int *cols)
{
    if (which < GA_MATRIX_MASS || which > GA_MATRIX_DAMPING)
        return c.diag.fail(GA_ERR_ARG, "unknown matrix %d", which);
    if (c.kernel().setup_done())
        return c.diag.fail(GA_ERR_STATE, "patterns are declared before ga_init");
    if (nnz < 0 || (nnz > 0 && (!rows || !cols)))
        return c.diag.fail(GA_ERR_ARG, "pattern with nnz = %d needs rows and cols", nnz);
    const int nv = c.kernel().nv();
    const int nr = which == GA_MATRIX_JACOBIAN ? c.kernel().m() : nv, nc = nv;
    if (which == GA_MATRIX_JACOBIAN && c.kernel().m() == 0)
        return c.diag.fail(GA_ERR_ARG, "m = 0: there is no constraint Jacobian");
    for (int k = 0; k < nnz; ++k)
        if (rows[k] < 0 || rows[k] >= nr || cols[k] < 0 || cols[k] >= nc)
            return c.diag.fail(GA_ERR_ARG, "pattern entry %d = (%d, %d) is outside the "
                               "%d x %d matrix", k, rows[k], cols[k], nr, nc);
    c.kernel().matrix(static_cast<ga_matrix>(which)).set_pattern(nr, nc, rows, cols, nnz);
    return GA_OK;
}
}  // namespace

GA_API ga_status ga_set_pattern(ga_solver *s, int which, int nnz, const int *rows,
                                const int *cols)
{
    return guarded(s, [&](ga::Solver &c) { return declare_pattern(c, which, nnz, rows, cols); });
}

GA_API ga_status ga_set_pattern_csc(ga_solver *s, int which, const int *colptr,
                                    const int *rowind)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!colptr)
            return c.diag.fail(GA_ERR_ARG, "pattern in CSC form needs colptr");
        if (colptr[0] != 0)
            return c.diag.fail(GA_ERR_ARG, "colptr[0] = %d, not 0", colptr[0]);
        const int nc = c.kernel().nv();
        for (int j = 0; j < nc; ++j)
            if (colptr[j + 1] < colptr[j])
                return c.diag.fail(GA_ERR_ARG, "colptr decreases at column %d (%d -> %d)", j,
                                   colptr[j], colptr[j + 1]);
        // triplets in the same order: the callback's values are the CSC value array
        const int nnz = colptr[nc];
        std::vector<int> cols(static_cast<std::size_t>(nnz));
        for (int j = 0; j < nc; ++j)
            for (int k = colptr[j]; k < colptr[j + 1]; ++k)
                cols[static_cast<std::size_t>(k)] = j;
        return declare_pattern(c, which, nnz, rowind, cols.data());
    });
}

GA_API ga_status ga_set_linear_solver(ga_solver *s, int solver)
{
    return guarded(s, [&](ga::Solver &c) {
        if (solver < GA_LINEAR_AUTO || solver > GA_LINEAR_DENSE_UNBLOCKED)
            return c.diag.fail(GA_ERR_ARG, "unknown linear solver %d", solver);
        if (c.kernel().setup_done())
            return c.diag.fail(GA_ERR_STATE, "the linear solver is chosen before ga_init");
        c.kernel().linear_solver = static_cast<ga_linear_solver>(solver);
        return GA_OK;
    });
}

GA_API const char *ga_linear_solver_name(const ga_solver *s)
{
    if (!s)
        return "none";
    return s->core.kernel().linear_backend();
}

GA_API ga_status ga_set_redundant_constraints(ga_solver *s, int mode)
{
    return guarded(s, [&](ga::Solver &c) {
        if (mode != GA_REDUNDANT_REFUSE && mode != GA_REDUNDANT_DROP)
            return c.diag.fail(GA_ERR_ARG, "unknown redundancy mode %d", mode);
        if (c.kernel().setup_done())
            return c.diag.fail(GA_ERR_STATE,
                               "the treatment of redundant constraints is chosen before ga_init");
        c.kernel().redundancy = static_cast<ga_redundancy>(mode);
        return GA_OK;
    });
}

GA_API ga_status ga_get_active_constraints(const ga_solver *s, int *active)
{
    return reading(s, "ga_get_active_constraints", "active is NULL",
                   [&](const ga::Solver &c) {
        if (!active)
            return GA_ERR_ARG;
        if (!c.kernel().initialized())
            return GA_ERR_STATE;
        for (int i = 0; i < c.kernel().m(); ++i)
            active[i] = c.kernel().constraint_active(i) ? 1 : 0;
        return GA_OK;
    });
}

GA_API ga_status ga_set_formulation(ga_solver *s, int formulation)
{
    return guarded(s, [&](ga::Solver &c) {
        if (formulation != GA_INDEX3 && formulation != GA_INDEX2_STABILIZED)
            return c.diag.fail(GA_ERR_ARG, "unknown formulation %d", formulation);
        if (formulation == GA_INDEX2_STABILIZED && c.kernel().setup_done())
            c.kernel().setup_index2();  // may throw std::bad_alloc: the formulation stays as it was
        c.kernel().formulation = static_cast<ga_formulation>(formulation);
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_resolution_check(ga_solver *s, double limit)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(limit > 0.0))
            return c.diag.fail(GA_ERR_ARG, "resolution check limit %g must be > 0 (INFINITY: "
                               "no check)", limit);
        c.kernel().max_velocity_residual = limit;
        return GA_OK;
    });
}

static ga_status set_switch(ga_solver *s, int on, const char *what, bool ga::Stepper::*field)
{
    return guarded(s, [&](ga::Solver &c) {
        if (on != 0 && on != 1)
            return c.diag.fail(GA_ERR_ARG, "%s must be 0 or 1, got %d", what, on);
        c.kernel().*field = on == 1;
        return GA_OK;
    });
}

GA_API ga_status ga_set_rescale(ga_solver *s, int on)
{
    return set_switch(s, on, "rescale", &ga::Stepper::rescale_a);
}

GA_API ga_status ga_set_corrected_start(ga_solver *s, int on)
{
    return set_switch(s, on, "corrected start", &ga::Stepper::corrected_start);
}

GA_API ga_status ga_set_tolerances(ga_solver *s, double rtol, double atol)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(rtol > 0.0 && std::isfinite(rtol)) || !(atol > 0.0 && std::isfinite(atol)))
            return c.diag.fail(GA_ERR_ARG, "tolerances rtol = %g, atol = %g must be positive "
                               "and finite", rtol, atol);
        c.control.rtol = rtol;
        c.control.atol = atol;
        c.control.atol_q_each.clear();
        c.control.atol_v_each.clear();
        c.control.atol_y_each.clear();
        return GA_OK;
    });
}

GA_API ga_status ga_set_tolerances_vector(ga_solver *s, double rtol, const double *atol)
{
    return guarded(s, [&](ga::Solver &c) {
        // 2 n + r may pass INT_MAX (n itself may be up to INT_MAX - m)
        const std::ptrdiff_t nv = c.kernel().nv(), r = c.kernel().r(), count = 2 * nv + r;
        if (!(rtol > 0.0 && std::isfinite(rtol)))
            return c.diag.fail(GA_ERR_ARG, "tolerance rtol = %g must be positive and finite",
                               rtol);
        if (!atol)
            return c.diag.fail(GA_ERR_ARG, "atol is NULL: 2 n + r = %td absolute tolerances "
                               "expected", count);
        for (std::ptrdiff_t i = 0; i < count; ++i)
            if (!(atol[i] > 0.0 && std::isfinite(atol[i])))
                return c.diag.fail(GA_ERR_ARG, "atol[%td] = %g (%s %td) must be positive and "
                                   "finite", i, atol[i],
                                   i < nv ? "position" : i < 2 * nv ? "velocity" : "state",
                                   i < nv ? i : i < 2 * nv ? i - nv : i - 2 * nv);
        // built aside first: a failed allocation leaves the tolerances as they were
        std::vector<double> q(atol, atol + nv), v(atol + nv, atol + 2 * nv),
            y(atol + 2 * nv, atol + count);
        c.control.rtol = rtol;
        c.control.atol_q_each.swap(q);
        c.control.atol_v_each.swap(v);
        c.control.atol_y_each.swap(y);
        return GA_OK;
    });
}

GA_API ga_status ga_set_step_limits(ga_solver *s, double h_min, double h_max)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(h_min >= 0.0 && std::isfinite(h_min)) || !(h_max >= 0.0 && std::isfinite(h_max)) ||
            (h_max > 0.0 && h_min > h_max))
            return c.diag.fail(GA_ERR_ARG, "step limits h_min = %g, h_max = %g: need 0 <= h_min "
                               "<= h_max (0 = none)", h_min, h_max);
        c.control.h_min = h_min;
        c.control.h_max = h_max;
        return GA_OK;
    });
}

GA_API ga_status ga_set_initial_step(ga_solver *s, double h0)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!(h0 >= 0.0 && std::isfinite(h0)))
            return c.diag.fail(GA_ERR_ARG, "initial step %g must be >= 0 and finite", h0);
        c.control.h_init = h0;
        return GA_OK;
    });
}

GA_API ga_status ga_step_adaptive(ga_solver *s, double t_stop)
{
    return guarded(s, [&](ga::Solver &c) {
        c.events().clear_log();  // the log is this call's, even if it fails at once
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_step_adaptive before ga_init");
        if (!std::isfinite(t_stop))
            return c.diag.fail(GA_ERR_ARG, "t_stop = %g is not finite", t_stop);
        return c.step_adaptive(t_stop);
    });
}

GA_API ga_status ga_advance(ga_solver *s, double t_out)
{
    return guarded(s, [&](ga::Solver &c) {
        c.events().clear_log();  // the log is this call's, even if it fails at once
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_advance before ga_init");
        if (!std::isfinite(t_out))
            return c.diag.fail(GA_ERR_ARG, "t_out = %g is not finite", t_out);
        return c.advance(t_out);
    });
}

namespace {
// ga_set_events and ga_set_events_y: one of fn, fn_y.
ga_status set_events(ga_solver *s, const char *name, int count, ga_event_fn fn,
                     ga_event_y_fn fn_y, const int *direction, const int *terminal,
                     int with_multipliers)
{
    return guarded(s, [&](ga::Solver &c) {
        if (count < 0)
            return c.diag.fail(GA_ERR_ARG, "%s: count = %d is negative", name, count);
        if (count > 0 && !fn && !fn_y)
            return c.diag.fail(GA_ERR_ARG, "%s: %d functions but fn is NULL", name, count);
        if (count > 0 && fn_y && c.kernel().r() == 0)
            return c.diag.fail(GA_ERR_STATE, "%s before ga_set_first_order: no first-order "
                               "states to pass", name);
        for (int k = 0; direction && k < count; ++k)
            if (direction[k] < -1 || direction[k] > 1)
                return c.diag.fail(GA_ERR_ARG, "%s: direction[%d] = %d is not -1, 0 or 1", name,
                                   k, direction[k]);
        c.events().configure(count, fn, fn_y, direction, terminal, with_multipliers != 0,
                             c.kernel().nq(), c.kernel().nv(), c.kernel().m(), c.kernel().r());
        return GA_OK;
    });
}
}  // namespace

GA_API ga_status ga_set_events(ga_solver *s, int count, ga_event_fn fn, const int *direction,
                               const int *terminal, int with_multipliers)
{
    return set_events(s, "ga_set_events", count, fn, nullptr, direction, terminal,
                      with_multipliers);
}

GA_API ga_status ga_set_events_y(ga_solver *s, int count, ga_event_y_fn fn, const int *direction,
                                 const int *terminal, int with_multipliers)
{
    return set_events(s, "ga_set_events_y", count, nullptr, fn, direction, terminal,
                      with_multipliers);
}

GA_API ga_status ga_set_step_hook(ga_solver *s, ga_step_hook_fn fn, void *user,
                                  int with_multipliers)
{
    return guarded(s, [&](ga::Solver &c) {
        ga::StepHook hook;
        if (fn) {
            hook.fn = fn;
            hook.user = user;
            hook.handle = s;
            hook.running = &s->in_hook;
            hook.with_lambda = with_multipliers != 0;
        }
        c.set_step_hook(hook);  // may throw std::bad_alloc: the hook stays as it was
        return GA_OK;
    });
}

GA_API ga_status ga_get_event_count(const ga_solver *s, int *count)
{
    return reading(s, "ga_get_event_count", "count is NULL", [&](const ga::Solver &c) {
        if (!count)
            return GA_ERR_ARG;
        *count = c.events().logged();
        return GA_OK;
    });
}

GA_API ga_status ga_get_event(const ga_solver *s, int i, double *t, int *index, int *direction)
{
    return reading(s, "ga_get_event", "i is not an entry of the event log",
                   [&](const ga::Solver &c) {
        if (i < 0 || i >= c.events().logged())
            return GA_ERR_ARG;
        const ga::EventSet::Entry &e = c.events().entry(i);
        if (t)
            *t = e.t;
        if (index)
            *index = e.index;
        if (direction)
            *direction = e.direction;
        return GA_OK;
    });
}

GA_API ga_status ga_interpolate(const ga_solver *s, double t, double *q, double *v,
                                double *lambda)
{
    return computing(s, [&](ga::Solver &c) {
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_interpolate before ga_init");
        if (!std::isfinite(t))
            return c.diag.fail(GA_ERR_ARG, "ga_interpolate: t = %g is not finite", t);
        return c.kernel().interpolate(t, q, v, nullptr, lambda);
    });
}

GA_API ga_status ga_interpolate_qdd(const ga_solver *s, double t, double *qdd)
{
    return computing(s, [&](ga::Solver &c) {
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_interpolate_qdd before ga_init");
        if (!std::isfinite(t) || !qdd)
            return c.diag.fail(GA_ERR_ARG, "ga_interpolate_qdd: t = %g not finite or qdd NULL",
                               t);
        return c.kernel().interpolate(t, nullptr, nullptr, qdd, nullptr);
    });
}

GA_API ga_status ga_set_first_order(ga_solver *s, int r, ga_force_y_fn force, ga_rate_fn rate)
{
    return guarded(s, [&](ga::Solver &c) {
        if (r < 0)
            return c.diag.fail(GA_ERR_ARG, "r = %d first-order states: must be >= 0", r);
        if (r > 0 && !rate)
            return c.diag.fail(GA_ERR_ARG, "r = %d > 0: the rate callback is required", r);
        if (c.kernel().setup_done())
            return c.diag.fail(GA_ERR_STATE, "ga_set_first_order after the solver was set up "
                               "(ga_init or ga_set_state): declare the states before");
        if (c.events().fn_y())
            return c.diag.fail(GA_ERR_STATE, "ga_set_first_order after ga_set_events_y: the "
                               "event functions take the states declared before them");
        if (!c.control.atol_q_each.empty() && r != c.kernel().r())
            return c.diag.fail(GA_ERR_STATE, "ga_set_first_order(r = %d) after "
                               "ga_set_tolerances_vector for r = %d states: declare the states "
                               "first (the absolute tolerances cover them)", r, c.kernel().r());
        if (r > 0 && c.sens().active())
            return c.diag.fail(GA_ERR_STATE, "ga_set_first_order after ga_set_sensitivity: "
                               "declare the states first (the sensitivities include theirs)");
        c.kernel().set_first_order(r);  // may throw std::bad_alloc before anything below changed
        c.model.cb.force_y = r > 0 ? force : nullptr;
        c.model.cb.rate = r > 0 ? rate : nullptr;
        return GA_OK;
    });
}

GA_API ga_status ga_set_coupling(ga_solver *s, ga_coupling_fn fn)
{
    return guarded(s, [&](ga::Solver &c) {
        c.model.cb.coupling = fn;
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_coupling_pattern(ga_solver *s, int which, int nnz, const int *rows,
                                         const int *cols)
{
    return guarded(s, [&](ga::Solver &c) {
        if (which != GA_COUPLING_G_Q && which != GA_COUPLING_G_V)
            return c.diag.fail(GA_ERR_ARG, "unknown coupling block %d", which);
        if (c.kernel().r() == 0)
            return c.diag.fail(GA_ERR_STATE, "ga_set_coupling_pattern before ga_set_first_order "
                               "with r > 0");
        if (c.kernel().setup_done())
            return c.diag.fail(GA_ERR_STATE, "coupling patterns are declared before ga_init_y");
        if (nnz < 0 || (nnz > 0 && (!rows || !cols)))
            return c.diag.fail(GA_ERR_ARG, "pattern with nnz = %d needs rows and cols", nnz);
        if (which == GA_COUPLING_G_Q && !c.model.space.euclidean())
            return refuse_on_rotations(c, "a pattern of g_q");
        const int r = c.kernel().r(), nv = c.kernel().nv();
        for (int k = 0; k < nnz; ++k)
            if (rows[k] < 0 || rows[k] >= r || cols[k] < 0 || cols[k] >= nv)
                return c.diag.fail(GA_ERR_ARG, "pattern entry %d = (%d, %d) is outside the "
                                   "%d x %d block", k, rows[k], cols[k], r, nv);
        (which == GA_COUPLING_G_Q ? c.model.g_q_pattern : c.model.g_v_pattern)
            .set_pattern(c.kernel().r(), c.kernel().nv(), rows, cols, nnz);
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_set_coupling_exact(ga_solver *s, int exact)
{
    return guarded(s, [&](ga::Solver &c) {
        c.kernel().coupling_exact = exact != 0;
        c.kernel().invalidate_jacobian();
        return GA_OK;
    });
}

GA_API ga_status ga_init_y(ga_solver *s, double t0, const double *q0, const double *v0,
                           const double *y0)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!q0 || !v0 || (!y0 && c.kernel().r() > 0))
            return c.diag.fail(GA_ERR_ARG, "q0, v0 and y0 must not be NULL");
        if (!std::isfinite(t0))
            return c.diag.fail(GA_ERR_ARG, "t0 = %g is not finite", t0);
        if (!c.model.ready())
            return c.diag.fail(GA_ERR_STATE, "ga_init_y before ga_set_callbacks");
        return c.init_y(t0, q0, v0, y0);
    });
}

GA_API ga_status ga_set_sensitivity(ga_solver *s, int np, double *p, const double *p_scale,
                                    int depends)
{
    return guarded(s, [&](ga::Solver &c) {
        if (np < 0)
            return c.diag.fail(GA_ERR_ARG, "np = %d parameters: must be >= 0", np);
        if (np > 0 && !p)
            return c.diag.fail(GA_ERR_ARG, "np = %d parameters and p is NULL", np);
        if ((depends & ~(GA_DEPENDS_FORCE | GA_DEPENDS_MASS | GA_DEPENDS_RATE |
                         GA_DEPENDS_CONSTRAINT)) != 0)
            return c.diag.fail(GA_ERR_ARG, "unknown dependence flags 0x%x", static_cast<unsigned>(depends));
        for (int j = 0; p && j < np; ++j)
            if (!std::isfinite(p[j]))
                return c.diag.fail(GA_ERR_ARG, "p[%d] is not finite", j);
        for (int j = 0; p_scale && j < np; ++j)
            if (!(p_scale[j] > 0.0) || !std::isfinite(p_scale[j]))
                return c.diag.fail(GA_ERR_ARG, "p_scale[%d] = %g: must be positive and finite", j,
                                   p_scale[j]);
        if ((depends & GA_DEPENDS_MASS) && c.model.constant_mass)
            return c.diag.fail(GA_ERR_ARG, "a mass matrix that depends on the parameters is not "
                               "constant (ga_set_constant_mass)");
        if (c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_set_sensitivity after ga_init: sensitivities "
                               "start at ga_init");
        return c.set_sensitivity(np, p, p_scale, depends);
    });
}

GA_API ga_status ga_set_sensitivity_start(ga_solver *s, int j, const double *dq0,
                                          const double *dv0)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!c.sens().active())
            return c.diag.fail(GA_ERR_STATE, "ga_set_sensitivity_start before ga_set_sensitivity "
                               "with np > 0");
        if (j < 0 || j >= c.sens().np)
            return c.diag.fail(GA_ERR_ARG, "parameter %d: there are %d (0-based)", j, c.sens().np);
        for (int i = 0; i < c.kernel().nv(); ++i)
            if ((dq0 && !std::isfinite(dq0[i])) || (dv0 && !std::isfinite(dv0[i])))
                return c.diag.fail(GA_ERR_ARG, "dq0 or dv0 entry %d is not finite", i);
        return c.set_sensitivity_start(j, dq0, dv0);
    });
}

GA_API ga_status ga_set_parameter_derivatives(ga_solver *s, ga_force_p_fn force_p,
                                              ga_mass_p_fn mass_p)
{
    return guarded(s, [&](ga::Solver &c) {
        c.model.cb.force_p = force_p;
        c.model.cb.mass_p = mass_p;
        return GA_OK;
    });
}

GA_API ga_status ga_set_constraint_parameter_derivative(ga_solver *s, ga_constraint_p_fn fn)
{
    return guarded(s, [&](ga::Solver &c) {
        c.model.cb.constraint_p = fn;
        return GA_OK;
    });
}

GA_API ga_status ga_get_sensitivity(const ga_solver *s, int j, double *dq, double *dv,
                                    double *dqdd, double *dlambda)
{
    return read_sensitivity(s, "ga_get_sensitivity", j, [&](const ga::StateDerivative &x) {
        put(x.q, dq);
        put(x.v, dv);
        put(x.qdd, dqdd);
        put(x.lambda, dlambda);
    });
}

GA_API ga_status ga_get_sensitivity_y(const ga_solver *s, int j, double *dy, double *dydot)
{
    return read_sensitivity(s, "ga_get_sensitivity_y", j, [&](const ga::StateDerivative &x) {
        put(x.y, dy);
        put(x.ydot, dydot);
    });
}

GA_API ga_status ga_set_sensitivity_method(ga_solver *s, int methods, long max_steps)
{
    return guarded(s, [&](ga::Solver &c) {
        if ((methods & ~(GA_SENSITIVITY_FORWARD | GA_SENSITIVITY_ADJOINT)) != 0 || methods == 0)
            return c.diag.fail(GA_ERR_ARG, "sensitivity methods 0x%x: an or of "
                               "GA_SENSITIVITY_FORWARD and GA_SENSITIVITY_ADJOINT",
                               static_cast<unsigned>(methods));
        if ((methods & GA_SENSITIVITY_ADJOINT) && max_steps < 1)
            return c.diag.fail(GA_ERR_ARG, "max_steps = %ld: the adjoint record needs room for "
                               "at least one step", max_steps);
        if (!c.sens().active())
            return c.diag.fail(GA_ERR_STATE, "ga_set_sensitivity_method before "
                               "ga_set_sensitivity with np > 0");
        if (c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_set_sensitivity_method after ga_init");
        return c.set_sensitivity_method(methods, max_steps);
    });
}

GA_API ga_status ga_set_adjoint_checkpoints(ga_solver *s, long interval, long count)
{
    return guarded(s, [&](ga::Solver &c) {
        if (interval < 0 || (interval > 0 && count < 1))
            return c.diag.fail(GA_ERR_ARG, "interval = %ld, count = %ld: interval >= 0 steps, "
                               "and with interval > 0 at least one checkpoint", interval, count);
        if (interval > 0 && count > LONG_MAX / interval)
            return c.diag.fail(GA_ERR_ARG, "interval = %ld times count = %ld steps overflows",
                               interval, count);
        if (!c.sens().adjoint)
            return c.diag.fail(GA_ERR_STATE, "ga_set_adjoint_checkpoints before "
                               "ga_set_sensitivity_method with GA_SENSITIVITY_ADJOINT");
        if (c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_set_adjoint_checkpoints after ga_init");
        return c.set_adjoint_checkpoints(interval, count);
    });
}

GA_API ga_status ga_adjoint_gradient(ga_solver *s, ga_cost_fn running, ga_cost_fn terminal,
                                     double *J, double *dJ_dp)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!running && !terminal)
            return c.diag.fail(GA_ERR_ARG, "ga_adjoint_gradient: no cost (running and terminal "
                               "are NULL)");
        if (!J || !dJ_dp)
            return c.diag.fail(GA_ERR_ARG, "ga_adjoint_gradient: J or dJ_dp is NULL");
        if (!c.sens().adjoint)
            return c.diag.fail(GA_ERR_STATE, "ga_adjoint_gradient without a recorded run "
                               "(ga_set_sensitivity_method with GA_SENSITIVITY_ADJOINT)");
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_adjoint_gradient before ga_init");
        return c.adjoint_gradient(running, terminal, J, dJ_dp);
    });
}

GA_API ga_status ga_get_y(const ga_solver *s, double *y, double *ydot)
{
    return reading(s, "ga_get_y", "no argument can fail", [&](const ga::Solver &c) {
        if (!c.kernel().initialized())
            return GA_ERR_STATE;
        if (y)
            Eigen::Map<ga::Vec>(y, c.kernel().r()) = c.kernel().state().y;
        if (ydot)
            Eigen::Map<ga::Vec>(ydot, c.kernel().r()) = c.kernel().state().ydot;
        return GA_OK;
    });
}

GA_API ga_status ga_interpolate_y(const ga_solver *s, double t, double *y, double *ydot)
{
    return computing(s, [&](ga::Solver &c) {
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_interpolate_y before ga_init");
        if (!std::isfinite(t))
            return c.diag.fail(GA_ERR_ARG, "ga_interpolate_y: t = %g is not finite", t);
        return c.kernel().interpolate_y(t, y, ydot);
    });
}

GA_API ga_status ga_set_predictor(ga_solver *s, int predictor)
{
    return guarded(s, [&](ga::Solver &c) {
        if (predictor != GA_PREDICTOR_CONSTANT_A && predictor != GA_PREDICTOR_ZERO &&
            predictor != GA_PREDICTOR_EXTRAPOLATE)
            return c.diag.fail(GA_ERR_ARG, "unknown predictor %d", predictor);
        c.kernel().predictor = static_cast<ga_predictor>(predictor);
        return GA_OK;
    });
}

GA_API ga_status ga_set_init_mode(ga_solver *s, int mode, double init_tol)
{
    return guarded(s, [&](ga::Solver &c) {
        if (mode != GA_INIT_PROJECT && mode != GA_INIT_REFUSE)
            return c.diag.fail(GA_ERR_ARG, "unknown init mode %d", mode);
        if (!(init_tol > 0.0 && std::isfinite(init_tol)))
            return c.diag.fail(GA_ERR_ARG, "init_tol = %g must be positive and finite",
                               init_tol);
        c.kernel().init_mode = static_cast<ga_init_mode>(mode);
        c.kernel().init_tol = init_tol;
        return GA_OK;
    });
}

GA_API ga_status ga_init(ga_solver *s, double t0, const double *q0, const double *v0)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!q0 || !v0)
            return c.diag.fail(GA_ERR_ARG, "q0 and v0 must not be NULL");
        if (!std::isfinite(t0))
            return c.diag.fail(GA_ERR_ARG, "t0 = %g is not finite", t0);
        if (!c.model.ready())
            return c.diag.fail(GA_ERR_STATE, "ga_init before ga_set_callbacks");
        return c.init(t0, q0, v0);
    });
}

GA_API ga_status ga_step(ga_solver *s, double h)
{
    return guarded(s, [&](ga::Solver &c) {
        c.events().clear_log();  // the log is this call's, even if it fails at once
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_step before ga_init");
        if (!(h > 0.0) || !std::isfinite(h))
            return c.diag.fail(GA_ERR_ARG, "step size h = %g must be positive and finite", h);
        if (c.kernel().state().t + h == c.kernel().state().t)
            return c.diag.fail(GA_ERR_ARG, "step size h = %g is too small to advance t = %.17g",
                               h, c.kernel().state().t);
        return c.step(h);
    });
}

GA_API ga_status ga_get_t(const ga_solver *s, double *t)
{
    return reading(s, "ga_get_t", "t is NULL", [&](const ga::Solver &c) {
        if (!t)
            return GA_ERR_ARG;
        if (!c.kernel().initialized())
            return GA_ERR_STATE;
        *t = c.kernel().state().t;
        return GA_OK;
    });
}

GA_API ga_status ga_get_h_last(const ga_solver *s, double *h)
{
    return reading(s, "ga_get_h_last", "h is NULL", [&](const ga::Solver &c) {
        if (!h)
            return GA_ERR_ARG;
        if (!c.kernel().initialized())
            return GA_ERR_STATE;
        *h = c.kernel().state().h_last;
        return GA_OK;
    });
}

GA_API ga_status ga_get_q(const ga_solver *s, double *q)
{
    return reading(s, "ga_get_q", "q is NULL",
                   [&](const ga::Solver &c) { return copy_out(c, c.kernel().state().q, q); });
}

GA_API ga_status ga_get_v(const ga_solver *s, double *v)
{
    return reading(s, "ga_get_v", "v is NULL",
                   [&](const ga::Solver &c) { return copy_out(c, c.kernel().state().v, v); });
}

GA_API ga_status ga_get_qdd(const ga_solver *s, double *qdd)
{
    return computing(s, [&](ga::Solver &c) {
        if (!qdd)
            return c.diag.fail(GA_ERR_ARG, "ga_get_qdd: qdd is NULL");
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_get_qdd before ga_init or ga_set_state");
        return c.kernel().output_state(qdd, nullptr);
    });
}

GA_API ga_status ga_get_lambda(const ga_solver *s, double *lambda)
{
    return computing(s, [&](ga::Solver &c) {
        if (c.kernel().m() == 0 && c.kernel().initialized())
            return GA_OK;  // nothing to copy; lambda may be NULL
        if (!lambda)
            return c.diag.fail(GA_ERR_ARG, "ga_get_lambda: lambda is NULL");
        if (!c.kernel().initialized())
            return c.diag.fail(GA_ERR_STATE, "ga_get_lambda before ga_init or ga_set_state");
        return c.kernel().output_state(nullptr, lambda);
    });
}

GA_API ga_status ga_set_output(ga_solver *s, int mode)
{
    return guarded(s, [&](ga::Solver &c) {
        if (mode != GA_OUTPUT_CONSISTENT && mode != GA_OUTPUT_STEP)
            return c.diag.fail(GA_ERR_ARG, "unknown output mode %d", mode);
        if (mode == GA_OUTPUT_CONSISTENT)
            c.kernel().setup_output();  // may throw std::bad_alloc: the mode stays as it was
        c.kernel().output = static_cast<ga_output>(mode);
        return GA_OK;
    });
}

GA_API ga_status ga_get_a(const ga_solver *s, double *a)
{
    return reading(s, "ga_get_a", "a is NULL",
                   [&](const ga::Solver &c) { return copy_out(c, c.kernel().state().a, a); });
}

GA_API ga_status ga_state_size(const ga_solver *s, size_t *len)
{
    return reading(s, "ga_state_size", "len is NULL", [&](const ga::Solver &c) {
        if (!len)
            return GA_ERR_ARG;
        *len = c.state_size();
        return GA_OK;
    });
}

GA_API ga_status ga_get_state(const ga_solver *s, double *buf, size_t len)
{
    return reading(s, "ga_get_state", "buf is NULL or shorter than ga_state_size",
                   [&](const ga::Solver &c) {
        if (!buf || len < c.state_size())
            return GA_ERR_ARG;
        if (!c.kernel().initialized())
            return GA_ERR_STATE;
        c.get_state(buf);
        return GA_OK;
    });
}

GA_API ga_status ga_set_state(ga_solver *s, const double *buf, size_t len)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!buf)
            return c.diag.fail(GA_ERR_ARG, "checkpoint buffer is NULL");
        return c.set_state(buf, len);
    });
}

GA_API ga_status ga_get_counter(const ga_solver *s, int key, long long *value)
{
    return reading(s, "ga_get_counter", "value is NULL or the key is unknown",
                   [&](const ga::Solver &c) {
        if (!value || key < 0 || key >= GA_COUNTER_COUNT)
            return GA_ERR_ARG;
        *value = c.kernel().counters[key];
        return GA_OK;
    });
}

GA_API ga_status ga_get_info(const ga_solver *s, int key, double *value)
{
    // a failure says so in ga_last_error, instead of leaving an earlier failure's message there
    return computing(s, [&](ga::Solver &c) {
        if (!value)
            return c.diag.fail(GA_ERR_ARG, "ga_get_info: value is NULL");
        switch (key) {
        case GA_INFO_RCOND: *value = c.kernel().last_rcond(); return GA_OK;
        case GA_INFO_NEWTON_ITERS: *value = c.kernel().last_newton_iters(); return GA_OK;
        case GA_INFO_NEWTON_RATIO: *value = c.kernel().last_newton_ratio(); return GA_OK;
        case GA_INFO_ERROR_ESTIMATE: *value = c.control.err_last; return GA_OK;
        case GA_INFO_H_NEXT: *value = c.control.h_next; return GA_OK;
        case GA_INFO_VELOCITY_RESIDUAL: *value = c.kernel().last_velocity_residual(); return GA_OK;
        default: return c.diag.fail(GA_ERR_ARG, "ga_get_info: unknown key %d", key);
        }
    });
}

GA_API ga_status ga_check_derivatives(ga_solver *s, double t, const double *q, const double *v,
                                      const double *qdd, const double *lambda, const double *y,
                                      double tol, double *worst)
{
    return guarded(s, [&](ga::Solver &c) {
        if (!q || !v)
            return c.diag.fail(GA_ERR_ARG, "ga_check_derivatives: q or v is NULL");
        if (!(tol > 0.0) || !std::isfinite(t))
            return c.diag.fail(GA_ERR_ARG, "ga_check_derivatives: tol = %g must be > 0, t = %g "
                               "finite", tol, t);
        if (!c.model.ready())
            return c.diag.fail(GA_ERR_STATE, "ga_check_derivatives needs the callbacks "
                               "(ga_set_callbacks)");
        return c.check_derivatives(t, q, v, qdd, lambda, y, tol, worst);
    });
}

GA_API ga_status ga_reset_counters(ga_solver *s)
{
    return guarded(s, [&](ga::Solver &c) {
        c.kernel().counters.fill(0);
        return GA_OK;
    });
}

}  // extern "C"

// ---- operating points (operating_point.cpp) ----
namespace {
// What the static problem does not cover yet, refused by name (first_order: the call takes
// the first-order states).
ga_status operating_point_refusal(ga::Solver &c, const char *name, double t,
                                  bool first_order = false)
{
    if (!c.model.ready())
        return c.diag.fail(GA_ERR_STATE, "%s needs the callbacks (ga_set_callbacks)", name);
    if (!c.model.space.euclidean())
        return c.diag.fail(GA_ERR_STATE, "%s: on coordinates in R^n only (not yet on a space "
                           "with rotations)", name);
    if (c.kernel().r() > 0 && !first_order)
        return c.diag.fail(GA_ERR_STATE, "%s: not with first-order states (ga_set_first_order): "
                           "ga_static_equilibrium_y and ga_state_space take them", name);
    if (!std::isfinite(t))
        return c.diag.fail(GA_ERR_ARG, "%s: t = %g is not finite", name, t);
    return GA_OK;
}
}  // namespace

extern "C" {

GA_API ga_status ga_static_equilibrium(ga_solver *s, double t, double *q, double *lambda,
                                       double tol, int max_iter)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_static_equilibrium", t))
            return st;
        if (!q)
            return c.diag.fail(GA_ERR_ARG, "ga_static_equilibrium: q is NULL");
        if (!(tol > 0.0) || !std::isfinite(tol) || max_iter < 1)
            return c.diag.fail(GA_ERR_ARG, "ga_static_equilibrium: tol = %g must be finite and "
                               "> 0, max_iter = %d >= 1", tol, max_iter);
        return ga::static_equilibrium(c.kernel(), t, q, lambda, tol, max_iter);
    });
}

GA_API ga_status ga_linearize(ga_solver *s, double t, const double *q, const double *lambda,
                              int max_dof, int *dof, double *N, double *M, double *C, double *K)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_linearize", t))
            return st;
        if (!q || !dof)
            return c.diag.fail(GA_ERR_ARG, "ga_linearize: q or dof is NULL");
        ga::Linearization lin;
        if (auto st = ga::linearize(c.kernel(), t, q, lambda, lin))
            return st;
        if (lin.dof > max_dof)
            return c.diag.fail(GA_ERR_ARG, "ga_linearize: %d degrees of freedom, max_dof = %d",
                               lin.dof, max_dof);
        *dof = lin.dof;
        const auto put = [](const ga::Mat &A, double *out) {
            if (out)
                Eigen::Map<ga::Mat>(out, A.rows(), A.cols()) = A;
        };
        put(lin.N, N);
        put(lin.M, M);
        put(lin.C, C);
        put(lin.K, K);
        return GA_OK;
    });
}

GA_API ga_status ga_static_path(ga_solver *s, double t, double *load, double *q, double *lambda,
                                double ds, int max_points, double tol, ga_path_fn fn,
                                void *user)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_static_path", t))
            return st;
        if (!q || !load)
            return c.diag.fail(GA_ERR_ARG, "ga_static_path: q or load is NULL");
        if (!(ds != 0.0) || !std::isfinite(ds) || max_points < 1 || !(tol > 0.0) ||
            !std::isfinite(tol))
            return c.diag.fail(GA_ERR_ARG, "ga_static_path: ds = %g must be finite and nonzero, "
                               "max_points = %d >= 1, tol = %g finite and > 0", ds, max_points,
                               tol);
        return ga::static_path(c.kernel(), t, load, q, lambda, ds, max_points, tol, fn, user);
    });
}

GA_API ga_status ga_modes_damped(ga_solver *s, double t, const double *q, const double *lambda,
                                 int count, double *re, double *im, double *shapes_re,
                                 double *shapes_im)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_modes_damped", t))
            return st;
        if (!q || !re || !im || count < 1)
            return c.diag.fail(GA_ERR_ARG, "ga_modes_damped: q, re or im is NULL, or count = "
                               "%d < 1", count);
        return ga::damped_modes(c.kernel(), t, q, lambda, count, re, im, shapes_re, shapes_im);
    });
}

GA_API ga_status ga_modes(ga_solver *s, double t, const double *q, const double *lambda,
                          int count, double *omega2, double *shapes)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_modes", t))
            return st;
        if (!q || !omega2 || count < 1)
            return c.diag.fail(GA_ERR_ARG, "ga_modes: q or omega2 is NULL, or count = %d < 1",
                               count);
        return ga::modes(c.kernel(), t, q, lambda, count, omega2, shapes);
    });
}

GA_API ga_status ga_static_equilibrium_y(ga_solver *s, double t, double *q, double *y,
                                         double *lambda, double tol, int max_iter)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_static_equilibrium_y", t, true))
            return st;
        if (!q || (!y && c.kernel().r() > 0))
            return c.diag.fail(GA_ERR_ARG, "ga_static_equilibrium_y: q or y is NULL");
        if (!(tol > 0.0) || !std::isfinite(tol) || max_iter < 1)
            return c.diag.fail(GA_ERR_ARG, "ga_static_equilibrium_y: tol = %g must be finite "
                               "and > 0, max_iter = %d >= 1", tol, max_iter);
        return ga::static_equilibrium_y(c.kernel(), t, q, c.kernel().r() > 0 ? y : nullptr,
                                        lambda, tol, max_iter);
    });
}

GA_API ga_status ga_state_space(ga_solver *s, double t, const double *q, const double *y,
                                const double *lambda, int max_dim, int *dim, double *N,
                                double *A)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_state_space", t, true))
            return st;
        if (!q || !dim || (!y && c.kernel().r() > 0))
            return c.diag.fail(GA_ERR_ARG, "ga_state_space: q, dim or y is NULL");
        ga::StateSpace ss;
        if (auto st = ga::state_space(c.kernel(), t, q, y, lambda, ss))
            return st;
        if (ss.dim > max_dim)
            return c.diag.fail(GA_ERR_ARG, "ga_state_space: dimension %d (%d degrees of freedom, "
                               "%d first-order states), max_dim = %d", ss.dim, ss.dof,
                               c.kernel().r(), max_dim);
        *dim = ss.dim;
        if (N)
            Eigen::Map<ga::Mat>(N, ss.N.rows(), ss.N.cols()) = ss.N;
        if (A)
            Eigen::Map<ga::Mat>(A, ss.dim, ss.dim) = ss.A;
        return GA_OK;
    });
}

GA_API ga_status ga_state_space_motion(ga_solver *s, double t, const double *q, const double *v,
                                       const double *y, int max_dim, int *dim, double *N,
                                       double *A)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_state_space_motion", t, true))
            return st;
        if (!q || !v || !dim || (!y && c.kernel().r() > 0))
            return c.diag.fail(GA_ERR_ARG, "ga_state_space_motion: q, v, y or dim is NULL");
        ga::StateSpace ss;
        if (auto st = ga::motion_state_space(c.kernel(), t, q, v, y, ss))
            return st;
        if (ss.dim > max_dim)
            return c.diag.fail(GA_ERR_ARG, "ga_state_space_motion: dimension %d (%d degrees of "
                               "freedom, %d first-order states), max_dim = %d", ss.dim, ss.dof,
                               c.kernel().r(), max_dim);
        *dim = ss.dim;
        if (N)
            Eigen::Map<ga::Mat>(N, ss.N.rows(), ss.N.cols()) = ss.N;
        if (A)
            Eigen::Map<ga::Mat>(A, ss.dim, ss.dim) = ss.A;
        return GA_OK;
    });
}

GA_API ga_status ga_modes_near(ga_solver *s, double t, const double *q, const double *lambda,
                               double sigma, int count, double *omega2, double *shapes)
{
    return guarded(s, [&](ga::Solver &c) {
        if (auto st = operating_point_refusal(c, "ga_modes_near", t))
            return st;
        if (!q || !omega2 || count < 1 || !std::isfinite(sigma))
            return c.diag.fail(GA_ERR_ARG, "ga_modes_near: q or omega2 is NULL, count = %d < 1, "
                               "or sigma = %g is not finite", count, sigma);
        return ga::modes_near(c.kernel(), t, q, lambda, sigma, count, omega2, shapes);
    });
}

}  // extern "C"
