/*
 * galpha — the generalized-alpha method of Arnold & Bruls for constrained mechanical systems.
 * SPDX-License-Identifier: BSD-3-Clause
 *
 * This header is the whole public interface of libgalpha: plain C99, no C++ types, usable from
 * C, C++, Fortran (iso_c_binding) and Python (ctypes).
 *
 * ## The problem
 *
 * galpha integrates index-3 differential-algebraic equations of constrained mechanics
 *
 *     M(q) q'' = f(q, q', t) - Phi_q(q, t)^T lambda        (n equations)
 *            0 = Phi(q, t)                                 (m equations)
 *
 * with q in R^n (generalized coordinates) and lambda in R^m (Lagrange multipliers). Note the sign
 * convention: the constraint force is -Phi_q^T lambda. M may be singular (massless nodes) as long
 * as the saddle-point matrix [M Phi_q^T; Phi_q 0] is regular; M is never inverted.
 *
 * ## The method
 *
 * Algorithm 1 of M. Arnold, O. Bruls, "Convergence of the generalized-alpha scheme for
 * constrained mechanical systems", Multibody Syst. Dyn. 18 (2007): the dynamic equilibrium is
 * enforced exactly at t_{n+1} (non-weighted residual), an auxiliary acceleration-like vector `a`
 * follows (1-alpha_m) a_{n+1} + alpha_m a_n = (1-alpha_f) q''_{n+1} + alpha_f q''_n, positions
 * and velocities follow the Newmark formulas driven by `a`, and each step solves the nonlinear
 * equations by Newton's method on the iteration matrix scaled as proposed by Bottasso et al.
 * q, q', q'' and lambda converge with order 2.
 *
 * ## Life cycle
 *
 *     ga_create -> ga_set_callbacks -> [ga_set_* options] -> ga_init -> ga_step ... -> ga_free
 *
 * Memory is allocated by ga_create and ga_init (and by options that need more workspace once
 * it exists: ga_set_formulation to index 2, tangent options that call for finite differences,
 * the first adaptive step); ga_step never allocates. On the sparse path the storage of the
 * LU factors is reserved with the workspace (ga_init), from the fill of the ordering; a step
 * that chooses new pivots (the first after a layout-2 checkpoint is restored, see
 * ga_set_state, or one whose refactorization with the old pivots comes out numerically
 * singular, pivot ratio below 1e-12) allocates only if its factors fill more than that.
 *
 * ## Conventions
 *  - Every function that can fail returns a ::ga_status (0 = GA_OK, negative = error);
 *    ga_strerror() names the status, ga_last_error() gives the details for one solver.
 *  - The library never prints, never exits, never aborts, and never lets a C++ exception out.
 *  - Dense matrices are column-major with leading dimension equal to the number of rows
 *    (Fortran, LAPACK and Eigen agree). M is n x n, Phi_q is m x n.
 *  - Arrays passed in are read during the call only; arrays passed out are filled by copying.
 *    Nothing returned by the library must be freed by the caller, except the solver by ga_free.
 *  - Callbacks return 0 on success, a positive value for a recoverable failure (the step is
 *    rejected; the caller may retry, e.g. with a smaller h) and a negative value for a fatal one.
 *  - Threads: there is no global mutable state. Any number of solvers may run in parallel
 *    threads; one solver must not be used by two threads at the same time.
 *  - A call on a solver from inside one of its own callbacks is refused with GA_ERR_STATE.
 *
 * ## ABI
 * Status values and counter keys are pinned and only ever appended. New options get new setter
 * functions, never new fields in a struct (there are no public structs), which keeps the ABI
 * stable and the bindings for Fortran and ctypes trivial. Parameters that take one of the enum
 * values below are declared `int`: a C caller may pass any integer, and an out-of-range value
 * must be a GA_ERR_ARG, not undefined behaviour in the C++ implementation.
 * SONAME: libgalpha.so.GA_VERSION_MAJOR.
 */
#ifndef GALPHA_H
#define GALPHA_H

#include <stddef.h>

#if defined(_WIN32)
#  if defined(GALPHA_BUILDING)
#    define GA_API __declspec(dllexport)
#  elif defined(GALPHA_SHARED)
#    define GA_API __declspec(dllimport)
#  else
#    define GA_API
#  endif
#elif defined(__GNUC__) || defined(__clang__)
#  define GA_API __attribute__((visibility("default")))
#else
#  define GA_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ------------------------------------------------------------------------------------------ */
/** @name Versions
 *  The macros give the version of this header, ga_version() and ga_version_number() the
 *  version of the library actually loaded; a binding should compare them at load time. */
/**@{*/
#define GA_VERSION_MAJOR 0
#define GA_VERSION_MINOR 3
#define GA_VERSION_PATCH 0
/** major * 10000 + minor * 100 + patch */
#define GA_VERSION_NUMBER (GA_VERSION_MAJOR * 10000 + GA_VERSION_MINOR * 100 + GA_VERSION_PATCH)

/** The library's version as "MAJOR.MINOR.PATCH" (static string). */
GA_API const char *ga_version(void);
/** The library's version as major * 10000 + minor * 100 + patch. */
GA_API int ga_version_number(void);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** Status codes. Values are pinned; new codes are only appended. */
typedef enum ga_status {
    GA_OK = 0,                  /**< success */
    GA_ERR_ARG = -1,            /**< invalid argument (NULL pointer, bad size, h <= 0, NaN, ...) */
    GA_ERR_STATE = -2,          /**< call out of order (e.g. ga_step before ga_init) or from a
                                     callback of the same solver */
    GA_ERR_NOMEM = -3,          /**< memory allocation failed */
    GA_ERR_CALLBACK = -4,       /**< a callback returned a negative value (fatal) */
    GA_ERR_CALLBACK_RETRY = -5, /**< a callback returned a positive value (recoverable: the step
                                     was rejected; it may be retried, e.g. with a smaller h) */
    GA_ERR_NONFINITE = -6,      /**< NaN or Inf in a callback output or in the Newton iteration */
    GA_ERR_SINGULAR = -7,       /**< singular (or numerically singular) matrix */
    GA_ERR_NEWTON = -8,         /**< Newton iteration did not converge in max_iter iterations */
    GA_ERR_INCONSISTENT = -9,   /**< initial values violate the constraints and were not, or
                                     could not be, projected onto them */
    GA_ERR_INTERNAL = -10,      /**< unexpected internal error, including a C++ exception thrown
                                     by a user callback written in C++ */
    GA_ERR_STEP_SIZE = -11,     /**< adaptive mode: the step size fell below its minimum */
    GA_ERR_UNRESOLVED = -12,    /**< the step is not resolved: in the index-3 formulation its
                                     velocities violate the velocity constraint by more than
                                     2 % of their size (recoverable: retry with a smaller h,
                                     or take the stabilized index-2 formulation); see
                                     ga_set_resolution_check */
    GA_ERR_DERIVATIVE = -13,    /**< ga_check_derivatives: a derivative callback disagrees with
                                     central differences (or a constraint has a zero
                                     gradient); the message names the worst entries */
    GA_EVENT = 1,               /**< not an error: ga_step, ga_step_adaptive or ga_advance stopped
                                     at a terminal event (or with its event log full); see
                                     ga_set_events */
    GA_STOPPED = 2              /**< not an error: the step hook asked to stop after an accepted
                                     step (ga_set_step_hook) */
} ga_status;

/** Fixed English name of a status (a ::ga_status value), e.g. "invalid argument"; "unknown
 *  status" for other values. Never NULL. */
GA_API const char *ga_strerror(int status);

/* ------------------------------------------------------------------------------------------ */
/** Opaque solver handle. */
typedef struct ga_solver ga_solver;

/** @name Callbacks
 *  Each receives the time t, the input vectors (length n), an output buffer owned by the
 *  library, and the `user` pointer given to ga_set_callbacks(). Outputs must be written
 *  completely. Return 0 = ok, > 0 = recoverable failure, < 0 = fatal failure. Output buffers
 *  are not zeroed before the call. */
/**@{*/
/** Mass matrix M(q): n x n, column-major, ld = n. */
typedef int (*ga_mass_fn)(double t, const double *q, double *M, void *user);
/** Applied forces f(q, v, t) (external, internal and complementary inertia forces): length n. */
typedef int (*ga_force_fn)(double t, const double *q, const double *v, double *f, void *user);
/** Constraints Phi(q, t): length m. */
typedef int (*ga_constraint_fn)(double t, const double *q, double *phi, void *user);
/** Constraint Jacobian Phi_q(q, t): m x n, column-major, ld = m. */
typedef int (*ga_jacobian_fn)(double t, const double *q, double *Phi_q, void *user);
/** Tangent stiffness K_t = d(M(q) qdd - f(q, v, t) + Phi_q(q, t)^T lambda)/dq at fixed qdd, v,
 *  lambda: n x n, column-major, ld = n. Optional (finite differences otherwise). */
typedef int (*ga_stiffness_fn)(double t, const double *q, const double *v, const double *qdd,
                               const double *lambda, double *K, void *user);
/** Tangent damping C_t = -df/dv: n x n, column-major, ld = n. Optional. */
typedef int (*ga_damping_fn)(double t, const double *q, const double *v, double *C, void *user);
/** Constraint acceleration term Phi_qq(v, v) + 2 Phi_qt v + Phi_tt, i.e.
 *  d^2/dt^2 Phi(q(t), t) - Phi_q q'': length m. Optional (finite differences otherwise). */
typedef int (*ga_constraint_accel_fn)(double t, const double *q, const double *v, double *out,
                                      void *user);
/** Event functions g_k(t, q, v, lambda), k = 0 .. count-1, written to g (length count; see
 *  ga_set_events). lambda (length m) is NULL unless ga_set_events asked for multipliers. */
typedef int (*ga_event_fn)(double t, const double *q, const double *v, const double *lambda,
                           double *g, void *user);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Life cycle */
/**@{*/
/** Create a solver for n coordinates and m constraints (0 <= m <= n, n >= 1); sizes are fixed
 *  for the life of the solver. On success *out holds the new solver; on failure *out is NULL.
 *  Errors: GA_ERR_ARG (out NULL, n < 1, m < 0, m > n), GA_ERR_NOMEM. */
GA_API ga_status ga_create(int n, int m, ga_solver **out);

/** Kinds of block of a configuration space (ga_create_space). */
typedef enum {
    GA_SPACE_VECTOR = 0,         /**< coordinates of R^k, in q and in v alike */
    GA_SPACE_SO3_QUATERNION = 1, /**< rotations, each 4 numbers (w, x, y, z) in q, 3 in v */
    GA_SPACE_SO3_MATRIX = 2,     /**< rotations, each 9 numbers in q (the rotation matrix,
                                      column-major), 3 in v */
    GA_SPACE_SE3 = 3             /**< rigid poses (x, R) of SE(3), each 7 numbers in q (the
                                      position x in space, then R's unit quaternion w, x, y,
                                      z) and 6 in v, the body-frame twist (u, w) = (R^T x',
                                      omega), moved by (x, R) o exp(u, w) = (x + R V(w) u,
                                      R exp(w)), V(w) = T(w)^T (docs/algorithms.md sec. 14) */
} ga_space_kind;

/** Create a solver whose configuration is a product of blocks, block i of kind kinds[i]
 *  holding counts[i] coordinates (GA_SPACE_VECTOR), counts[i] rotations in a row (the SO(3)
 *  kinds) or counts[i] poses (GA_SPACE_SE3), and m constraints. Rotations and poses move on
 *  the group, by right increments with body-frame velocities, q_{n+1} = q_n o exp(xi) (the
 *  conventions of the rotation and pose maps below; docs/algorithms.md sec. 13, 14): no
 *  unit-norm constraint, and no Euler parameters' velocities.
 *
 *  Storage and algebra: q (ga_init's q0, ga_get_q, ga_interpolate, every callback's q) holds
 *  nq numbers, the blocks' storage in order; v, qdd, a, f and everything shaped like them hold
 *  nv, 3 per rotation (the body-frame angular velocity and its rate) and 6 per pose (the
 *  body-frame twist (u, w) and its rate). So do the rows of M, C_t
 *  and K_t and the columns of Phi_q: Phi_q and K_t are derivatives along right increments,
 *  Phi_q w = d/de Phi(q o exp(e w)) at e = 0 and K_t likewise of M qdd - f + Phi_q^T lambda
 *  (on a vector block the ordinary ones); build them with the maps below. ga_get_size's n is
 *  nv; ga_get_space_size gives both.
 *
 *  A space of vector blocks only is R^n and the solver is exactly that of ga_create(n, m).
 *  With rotations, in this version: index 3 and the stabilized index 2, fixed and adaptive
 *  steps, dense output and events, checkpoints, forward and adjoint sensitivities (a
 *  sensitivity's dq is a tangent along right increments, nv numbers), on the dense linear
 *  solver, with first-order states (their g_q along right increments too). The sparse path
 *  (ga_set_pattern: patterns of the nv-column matrices) in index 3 and the stabilized index
 *  2, for the step and its finite-difference tangents; there sensitivities return GA_ERR_ARG
 *  at ga_init, saying so, as does a coupling pattern of g_q. q0 of ga_init (and q in
 *  ga_set_state) must hold rotations (a quaternion's norm, a pose's quaternion's, a matrix's
 *  orthonormality within 1e-6, det > 0; storage more than 1e-10 off at ga_init, 1e-8 off at
 *  ga_set_state, is taken as its nearest rotation, closer storage as it is: a solver's own
 *  checkpoint is restored bit for bit), else GA_ERR_ARG names the block.
 *  Errors: GA_ERR_ARG (out, kinds or counts NULL with count > 0, count < 1, an unknown kind, a
 *  count < 1, nq or nv above INT_MAX, m < 0 or m > nv), GA_ERR_NOMEM. */
GA_API ga_status ga_create_space(int count, const int *kinds, const int *counts, int m,
                                 ga_solver **out);
/** The number of q's coordinates (storage) and of v's (nv, ga_get_size's n). */
GA_API ga_status ga_get_space_size(const ga_solver *s, int *nq, int *nv);

/** Free a solver and everything it owns. ga_free(NULL) does nothing. Must not be called from
 *  one of the solver's own callbacks. */
GA_API void ga_free(ga_solver *s);

/** Set the model. mass is required; force may be NULL (f = 0); constraint and jacobian are
 *  required when m > 0 and ignored when m = 0. `user` is passed unchanged to every callback
 *  (also to the optional ones set later). May be called again, also after ga_init().
 *  Errors: GA_ERR_ARG, GA_ERR_STATE (from a callback). */
GA_API ga_status ga_set_callbacks(ga_solver *s, ga_mass_fn mass, ga_force_fn force,
                                  ga_constraint_fn constraint, ga_jacobian_fn jacobian,
                                  void *user);

/** Compute consistent initial values at t0 from q0 and v0 (both length n) and make the solver
 *  ready to step:
 *   1. positions: if |Phi(q0, t0)|_inf > init_tol, q0 is projected onto the constraint manifold
 *      by the minimum-norm (Euclidean) Gauss-Newton correction (or refused, see
 *      ga_set_init_mode());
 *   2. velocities: if |Phi_q v0 + Phi_t|_inf > init_tol, v0 is replaced by its minimum-norm
 *      correction onto Phi_q v + Phi_t = 0 (or refused);
 *   3. accelerations and multipliers from the saddle-point system
 *      [M Phi_q^T; Phi_q 0] [qdd0; lambda0] = [f; -(Phi_qq(v,v) + 2 Phi_qt v + Phi_tt)];
 *   4. a0 = qdd0 (eq. 3 of the paper).
 *  Called again on a running solver it is the restart after a jump in q or v (an impact law,
 *  a switched force): every option, pattern, callback and event function stays, nothing of
 *  the run before does (step-size history, kept matrix, sparse pivots, the event search and
 *  its log), and the first step applies the
 *  corrected start; the run then repeats a new solver started there with the same options,
 *  bit for bit (tests/c/test_checkpoint.c).
 *  Allocates the solver's linear-algebra workspace (the last allocation before stepping).
 *  Errors: GA_ERR_ARG, GA_ERR_STATE (callbacks not set, or from a callback), GA_ERR_NOMEM,
 *  GA_ERR_CALLBACK, GA_ERR_CALLBACK_RETRY, GA_ERR_NONFINITE, GA_ERR_SINGULAR,
 *  GA_ERR_INCONSISTENT. On failure the solver is as it was: not initialized, or, called again
 *  on an initialized solver, with its state and its constraints in use unchanged
 *  (tests/c/test_redundant.c). */
GA_API ga_status ga_init(ga_solver *s, double t0, const double *q0, const double *v0);

/** Advance by exactly one step of size h > 0 (Algorithm 1). With event functions
 *  (ga_set_events) it returns GA_EVENT, a success, when a terminal one fired in the step (or in
 *  the rest of the step a call before stopped in: then no step is taken). The step is
 *  transactional: unless GA_OK, GA_EVENT or GA_STOPPED (ga_set_step_hook) is returned, t, q, v, qdd, lambda and a are bit-identical to the last accepted step
 *  (work counters do count the failed attempt). After GA_ERR_CALLBACK_RETRY, GA_ERR_NEWTON,
 *  GA_ERR_NONFINITE or GA_ERR_SINGULAR the caller may retry, typically with a smaller h.
 *  A step more than 100 times shorter than the one before (a sliver that lands on an output
 *  time) is not solved from Algorithm 1's equations, which cannot determine accelerations over
 *  it: it is a Taylor step, q + h v + h^2/2 qdd and v + h qdd, with v projected onto the
 *  velocity constraint and qdd, lambda at its end from the acceleration-level equations (as in
 *  ga_init); a keeps its offset from qdd and ga_get_h_last that of the step before, so that the
 *  next steps go on as if the sliver had not been taken. (ga_step_adaptive does so only for a
 *  step that lands on its t_stop.) Consecutive slivers are Taylor steps while together they
 *  span at most 1/100 of the step before them; a short step beyond that is the caller's new
 *  step size and an Algorithm 1 step again, started like a first one from the consistent
 *  state the slivers left. A step more than 100 times longer than the one before
 *  starts like a first one, from accelerations and multipliers of the acceleration-level
 *  equations and corrected starting values (ga_set_corrected_start), instead of rescaling a_n
 *  by that ratio, which would multiply its round-off.
 *  Errors: GA_ERR_ARG (h <= 0, NaN, Inf, or t + h == t), GA_ERR_STATE (before ga_init, or from a
 *  callback), GA_ERR_CALLBACK, GA_ERR_CALLBACK_RETRY, GA_ERR_NONFINITE, GA_ERR_SINGULAR,
 *  GA_ERR_NEWTON, GA_ERR_INTERNAL. */
GA_API ga_status ga_step(ga_solver *s, double h);

/** Details of the last error on this solver: which callback, which Newton iteration of which
 *  step, which norm. Every call that can change the solver (ga_init, ga_step, ga_set_*,
 *  ga_reset_counters) clears it when it starts; read-only calls (ga_get_*, ga_interpolate*)
 *  leave it when they succeed, so it can be read after inspecting the state, and replace it
 *  with their own when they fail. "" when
 *  there is nothing to report. The string belongs to the solver. ga_last_error(NULL) returns a
 *  fixed message. */
GA_API const char *ga_last_error(const ga_solver *s);

/** Sizes given to ga_create. Errors: GA_ERR_ARG. */
GA_API ga_status ga_get_size(const ga_solver *s, int *n, int *m);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Method parameters
 *  The default is rho_inf = 0.9. The parameters may be changed between steps. In the index-3
 *  formulation little damping does not suit fast rotation: a pendulum turning 0.2 rad per
 *  step ends with a multiplier 10^4 times too large at rho_inf = 0.9 and is right at 0.7
 *  (tests/c/test_adaptive.c); the stabilized index-2 formulation keeps it at 0.9. */
/**@{*/
/** Chung-Hulbert parameters from the spectral radius at infinity rho_inf in [0, 1] (eq. 24 with
 *  gamma from eq. 20): alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1),
 *  gamma = 1/2 + alpha_f - alpha_m, beta = (gamma + 1/2)^2 / 4. rho_inf = 1 (no numerical
 *  damping) is allowed; it is the limit where strict stability at infinity (eq. 23) is lost.
 *  Errors: GA_ERR_ARG (outside [0, 1] or NaN), GA_ERR_STATE. */
GA_API ga_status ga_set_rho_inf(ga_solver *s, double rho_inf);

/** Explicit parameters. Refused with GA_ERR_ARG, and a message naming the broken condition,
 *  unless all of: finite values; second order, gamma = 1/2 + alpha_f - alpha_m (eq. 20, to
 *  1e-12); zero stability, alpha_m <= 1/2; strict stability at infinity (eq. 23),
 *  alpha_m < alpha_f < 1/2 and beta > 1/4 + (alpha_f - alpha_m)/2. */
GA_API ga_status ga_set_params(ga_solver *s, double alpha_m, double alpha_f, double beta,
                               double gamma);

/** Current parameters; any output pointer may be NULL. Errors: GA_ERR_ARG. */
GA_API ga_status ga_get_params(const ga_solver *s, double *alpha_m, double *alpha_f, double *beta,
                               double *gamma);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Newton iteration and linear algebra */
/**@{*/
/** Newton tolerance and iteration limit (default 20). Without this call the tolerance is
 *  1e-10 for ga_step, and for adaptive steps (ga_step_adaptive, ga_advance) a tenth of the
 *  local error tolerance, 0.1 rtol x 0.5 sqrt(rtol) (ga_set_tolerances): once an error
 *  tolerance is given, a Newton error far below it is wasted work, and one near it would
 *  spoil the error the tolerance promises. A tolerance set here applies to both.
 *
 *  The test is on the Newton increments, relative and per quantity: positions
 *  |dq| <= tol |q|, accelerations |beta' dw| <= tol |qdd| (dw = dq in index 3) and
 *  multipliers |dlambda| <= tol |lambda| (max-norms). A step is converged when each quantity
 *  is within the tolerance, or predicted within it by its own contraction rate (with an old
 *  matrix the quantities converge at different rates), or at its round-off floor and no longer
 *  improving (positions within 64 ulps of |q|; index-3 accelerations and multipliers are only
 *  determined to ~eps |q| / (beta h^2), paper sec. 3.3). At that floor an update with a matrix
 *  of an earlier step is not trusted: the matrix is rebuilt at the current iterate, and one
 *  update with it ends the step. Why not the paper's absolute test on the scaled residual:
 *  the residual of the dynamics is scaled by beta h^2, so once h is small the test accepts
 *  unconverged accelerations and multipliers (at h = 1e-6 it accepts the predictor with
 *  lambda = 0). With the defaults, every fixed h from 1e-2 down to 1e-7 ends within 1.5
 *  times the error of full Newton (GA_REUSE_NEVER), on every shipped scene in both
 *  formulations (tests/c/test_newton_sweep.c). tol in (0, 1), max_iter >= 1.
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_newton(ga_solver *s, double tol, int max_iter);

/** Tangent matrices in the iteration matrix S_t = [beta' M + gamma' C_t + K_t, Phi_q^T;
 *  Phi_q, 0]. */
typedef enum ga_tangent_mode {
    GA_TANGENT_AUTO = 0,    /**< user callbacks where given (default). A missing tangent is
                                 left out (simplified Newton) while a fresh matrix without it
                                 contracts at a rate <= 0.1, and computed by finite
                                 differences from the first step where it does not (or where
                                 the simplified iteration fails): finite differences cost a
                                 residual per column group at every refactorization, and a
                                 tangent that does not matter buys nothing with them. The
                                 choice is made afresh whenever the matrix is dropped (ga_init,
                                 options, failed steps, checkpoints). */
    GA_TANGENT_FD = 1,      /**< finite differences even where callbacks are given */
    GA_TANGENT_NEGLECT = 2  /**< K_t = C_t = 0: simplified Newton (cheaper iterations, linear
                                 convergence; only for non-stiff problems, omega_max h <~ 2) */
} ga_tangent_mode;

/** Optional exact tangent callbacks (either may be NULL: finite differences for that one).
 *  After ga_init, the workspace of the differences a NULL calls for is allocated here.
 *  Errors: GA_ERR_ARG, GA_ERR_STATE, GA_ERR_NOMEM. */
GA_API ga_status ga_set_tangents(ga_solver *s, ga_stiffness_fn stiffness, ga_damping_fn damping);

/** Choose how K_t and C_t enter the iteration matrix: mode is a ::ga_tangent_mode (after
 *  ga_init, allocates the workspace of finite differences if the mode calls for them).
 *  Errors: GA_ERR_ARG, GA_ERR_STATE, GA_ERR_NOMEM. */
GA_API ga_status ga_set_tangent_mode(ga_solver *s, int mode);

/** Switch the scaling (10) of the iteration matrix, D_L = diag(beta h^2 I, I),
 *  D_R = diag(I, I/(beta h^2)), on (1, default) or off (0). Off exists to show why it is on:
 *  without it the condition number grows like h^-4. Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_scaling(ga_solver *s, int on);

/** Reuse of the factorized iteration matrix (and of the tangents in it). */
typedef enum ga_reuse_mode {
    GA_REUSE_AUTO = 0, /**< modified Newton (default): keep the factorization across iterations
                            and steps; rebuild it when there is none yet, when h changed by more
                            than the factor 5/3 in h^2 since it was built (IDA's band), when the
                            contraction measured with it says the tolerance cannot be reached
                            within 4 iterations on that matrix (or the iteration diverges), and
                            after any failed step. A step that fails to converge with an old
                            matrix is retried once with a fresh one before GA_ERR_NEWTON is
                            reported. */
    GA_REUSE_NEVER = 1 /**< full Newton as printed in Algorithm 1: tangents and factorization
                            at every iteration */
} ga_reuse_mode;

/** mode is a ::ga_reuse_mode. Setting it, to the mode in use too, drops the kept
 *  factorization: the next step builds a fresh one (e.g. after the model changed in a way its
 *  callbacks do not show). Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_jacobian_reuse(ga_solver *s, int mode);

/** Declare the mass matrix constant (1) or not (0, default): with 1, M is evaluated once (at
 *  ga_init or ga_set_state, and after an option changes) and its derivative is dropped from
 *  finite-difference tangents. Switching it off after ga_init allocates the perturbed mass
 *  matrix of finite-difference tangents, if they are used. Errors: GA_ERR_ARG, GA_ERR_STATE,
 *  GA_ERR_NOMEM. */
GA_API ga_status ga_set_constant_mass(ga_solver *s, int on);

/** Newton predictor. Both converge to the same step solution (to the Newton tolerance). */
typedef enum ga_predictor {
    GA_PREDICTOR_CONSTANT_A = 0, /**< a_{n+1} = a_n, lambda_{n+1} = lambda_n: an O(h) accurate
                                      start (gena's predictor) */
    GA_PREDICTOR_ZERO = 1,       /**< Algorithm 1 verbatim: qdd_{n+1} = 0, lambda_{n+1} = 0 */
    GA_PREDICTOR_EXTRAPOLATE = 2 /**< qdd_{n+1} extrapolated linearly with the third derivative
                                      that a_n - qdd_n carries (= delta_alpha h q''' + O(h^2)),
                                      lambda_{n+1} = lambda_n: an O(h^2) accurate start
                                      (default; the constant-a predictor when rho_inf = 1, where
                                      delta_alpha = 0, and in the first step) */
} ga_predictor;

/** predictor is a ::ga_predictor. Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_predictor(ga_solver *s, int predictor);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Large models: sparsity patterns and the linear solver
 *
 *  By default every matrix is dense and its callback fills it column-major. After
 *  ga_set_pattern(s, which, nnz, rows, cols), the callback of that matrix instead writes nnz
 *  values, one per declared entry, in the declared order (entries repeated in the pattern add
 *  up). nnz = 0 declares the matrix identically zero: it is never evaluated (e.g. C_t when the
 *  forces do not depend on the velocities). With patterns for M and Phi_q (and for K_t and C_t
 *  unless neglected), the iteration matrix can be assembled and factorized as a sparse matrix
 *  (galpha's sparse LU in SuiteSparse KLU's ordering): no dense n x n object exists then, and the cost per step grows linearly
 *  with the size for mechanism-like sparsity. Finite-difference tangents with a declared pattern
 *  perturb structurally independent columns together (Curtis-Powell-Reid).
 *  Patterns are declared before ga_init / ga_set_state and copied; indices are 0-based. */
/**@{*/
typedef enum ga_matrix {
    GA_MATRIX_MASS = 0,      /**< M, n x n */
    GA_MATRIX_JACOBIAN = 1,  /**< Phi_q, m x n */
    GA_MATRIX_STIFFNESS = 2, /**< K_t, n x n */
    GA_MATRIX_DAMPING = 3    /**< C_t, n x n */
} ga_matrix;

/** Declare the pattern of matrix `which` (a ::ga_matrix): nnz >= 0 entries (rows[k], cols[k]).
 *  Errors: GA_ERR_ARG (unknown matrix, NULL arrays with nnz > 0, index out of range, a
 *  Jacobian pattern with m = 0), GA_ERR_STATE (after ga_init or ga_set_state). */
GA_API ga_status ga_set_pattern(ga_solver *s, int which, int nnz, const int *rows,
                                const int *cols);

/** The same pattern in compressed-column form, as sparse libraries hold it (SciPy's
 *  csc_matrix, SuiteSparse, Eigen's SparseMatrix): colptr has cols + 1 entries, colptr[0] = 0
 *  and non-decreasing, nnz = colptr[cols]; column j holds the rows rowind[colptr[j] ..
 *  colptr[j + 1] - 1]. The callback writes the values in that order (column by column), so a
 *  CSC matrix's value array can be filled as it is. cols = n (every matrix has n columns).
 *  Errors: as ga_set_pattern, and GA_ERR_ARG for colptr NULL, colptr[0] != 0 or decreasing. */
GA_API ga_status ga_set_pattern_csc(ga_solver *s, int which, const int *colptr,
                                    const int *rowind);

typedef enum ga_linear_solver {
    GA_LINEAR_AUTO = 0,         /**< sparse when the patterns allow it and n + m >= 10, dense
                                     otherwise (default; measured in bench/linear_algebra) */
    GA_LINEAR_DENSE = 1,        /**< dense LU, the kernel chosen at each factorization: the
                                     unblocked one when n + m <= 40 or at most 10 % of the
                                     matrix is nonzero, Eigen's otherwise */
    GA_LINEAR_SPARSE = 2,       /**< sparse LU (galpha's, in KLU's ordering; named "sparse
                                     KLU"); needs the patterns */
    GA_LINEAR_DENSE_LAPACK = 3, /**< dense LU by the system's LAPACK dgetrf/dgetrs: their
                                     bits, and any allocation they make, are the BLAS's
                                     (BLIS allocates in every call, about 100 times a
                                     step of a 12-link chain; reference BLAS and OpenBLAS
                                     do not); galpha's own kernels do neither */
    GA_LINEAR_DENSE_EIGEN = 4,  /**< dense LU by Eigen's (blocked) PartialPivLU */
    GA_LINEAR_DENSE_UNBLOCKED = 5 /**< dense LU by galpha's unblocked kernel, which skips the
                                     zero entries of a saddle-point matrix */
} ga_linear_solver;

/** Choose the linear algebra (a ::ga_linear_solver) before ga_init / ga_set_state.
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_linear_solver(ga_solver *s, int solver);

/** Name of the linear algebra in use ("dense unblocked LU", "dense Eigen LU" - with
 *  GA_LINEAR_DENSE the kernel of the last factorization -, "dense LAPACK LU", "sparse KLU"), or
 *  "none" before ga_init. Static string; never NULL. */
GA_API const char *ga_linear_solver_name(const ga_solver *s);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Formulation and variable step size */
/**@{*/
typedef enum ga_formulation {
    GA_INDEX3 = 0,           /**< the paper's index-3 formulation (default) */
    GA_INDEX2_STABILIZED = 1 /**< stabilized index-2 form of Arnold & Hante (GGL type): an extra
                                  multiplier eta bends the position update along
                                  Phi_q(q_n)^T so that the velocity constraint
                                  Phi_q v + Phi_t = 0 holds at every step too. Multipliers stay
                                  second order across step-size changes (index 3: an O(h) burst
                                  after every change) and are far less sensitive to round-off
                                  for small h; recommended with adaptive steps. Same callbacks
                                  (Phi_t: ga_set_constraint_dt, or finite differences), dense
                                  or sparse: with declared
                                  patterns the n + 2m system has its products of the user's
                                  matrices assembled on fixed patterns, or, where they would
                                  fill (a coordinate in many constraints), keeps the Newmark
                                  increment as n extra unknowns instead.
                                  Its Newton matrix includes the curvature of the velocity
                                  constraint, d(Phi_q v + Phi_t)/dq, from one more Jacobian
                                  call per matrix (left out with GA_TANGENT_NEGLECT): without
                                  it Newton converges only linearly, at about the angle a
                                  body turns in one step. */
} ga_formulation;

/** formulation is a ::ga_formulation. Errors: GA_ERR_ARG, GA_ERR_STATE, GA_ERR_NOMEM (index-2
 *  chosen after the workspace was set up, and its system does not fit). */
GA_API ga_status ga_set_formulation(ga_solver *s, int formulation);

/** The index-3 step's check of its own resolution. Index 3 holds Phi(q) = 0 at every step and
 *  the velocity constraint Phi_q v + Phi_t = 0 only to O(h^2). Where a step does not resolve
 *  the motion -- fast rotation at more than about 0.1 rad per step at rho_inf = 0.9 (0.2 at
 *  0.8, 0.3 at 0.7, 0.5 at 0.5; at rho_inf = 1 at every h), where the index-3 step map itself
 *  is unstable and every Newton iteration converges -- the velocities turn away from the
 *  constraints. After each index-3 step the largest |Phi_q v + Phi_t|_i, relative to row i's
 *  gradient (1-norm) times the model's largest speed (max_j |v_j| + |q_j - q_n,j| / h), is
 *  compared with `limit` (default 0.02; the shipped scenes stay below 0.007 where they
 *  converge at order 2): above it the step fails with GA_ERR_UNRESOLVED and changes nothing
 *  (adaptive steps retry smaller). It sees the unstable step map, not every inaccuracy:
 *  steps too long for a motion can still end far off with GA_OK (docs/choosing-settings.md).
 *  One Phi_t per step (ga_set_constraint_dt, or two constraint calls); the last step's value:
 *  ga_get_info(GA_INFO_VELOCITY_RESIDUAL). limit = INFINITY turns the check off. Errors:
 *  GA_ERR_ARG (limit not > 0, or NaN), GA_ERR_STATE (from a callback). */
GA_API ga_status ga_set_resolution_check(ga_solver *s, double limit);

/** Redundant constraints: Phi_q of rank r < m, so that only Phi_q^T lambda is unique and the
 *  saddle-point matrices are singular. */
typedef enum ga_redundancy {
    GA_REDUNDANT_REFUSE = 0, /**< (default) ga_init fails with GA_ERR_SINGULAR, and its
                                  message names the constraints that depend on the others */
    GA_REDUNDANT_DROP = 1    /**< ga_init (and ga_set_state) deactivates the constraints whose
                                  gradients depend on those of the constraints before them
                                  (in index order, on Phi_q at the initial position: a dense
                                  Gram-Schmidt for a dense Phi_q, n m <= 4e6; a sparse QR,
                                  SuiteSparseQR, for a declared pattern): the others carry the whole
                                  constraint force and a dropped constraint's multiplier is 0
                                  (a basic solution; order the constraints so that the ones to
                                  keep come first). A dropped constraint is kept through the
                                  others and is not enforced on its own: if the redundancy
                                  changes with the configuration, a later matrix is singular
                                  and the step fails with GA_ERR_SINGULAR. */
} ga_redundancy;

/** mode is a ::ga_redundancy. Errors: GA_ERR_ARG, GA_ERR_STATE (after ga_init or
 *  ga_set_state: the sparse layouts depend on it). */
GA_API ga_status ga_set_redundant_constraints(ga_solver *s, int mode);

/** The m flags of the constraints in use (1) or dropped as redundant (0). Errors: GA_ERR_ARG,
 *  GA_ERR_STATE (before ga_init or ga_set_state). */
GA_API ga_status ga_get_active_constraints(const ga_solver *s, int *active);

/** Rescale the stored a_n to the size of the coming step, a_n <- qdd_n + (h/h_last)(a_n -
 *  qdd_n), when h changes (1, default), or not (0). Without it the method drops to first order
 *  when h changes often (docs/algorithms.md sec. 1.1); the switch exists to show that.
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_rescale(ga_solver *s, int on);

/** Corrected starting values (1, default) for the first step after ga_init: a_0 = qdd_0 +
 *  delta_alpha h qddd_0 (qddd_0 from two extra consistent-acceleration solves) and, in the
 *  index-3 formulation, an O(h^2) velocity offset along the constraint normals, so that
 *  lambda has no O(h) start-up transient. 0: a_0 = qdd_0 as eq. (3) of the paper.
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_corrected_start(ga_solver *s, int on);

/** Tolerances of adaptive mode, for the global error: a step is accepted when the weighted
 *  RMS norm of its local error estimates, e_i / (c (atol + rtol max(|y_i(t_n)|,
 *  |y_i(t_n+1)|))) with c = 0.5 sqrt(rtol), over the positions and velocities (multipliers
 *  excluded), is at most 1. The factor c makes the local tolerance ~ rtol^(3/2): an order-2
 *  method held to a local tolerance tol' ends with a global error ~ tol'^(2/3), so that the
 *  global error follows rtol (tolerance proportionality, tests/c/test_tolerance.c).
 *  Defaults 1e-6, 1e-6.
 *  Errors: GA_ERR_ARG (rtol or atol not positive and finite), GA_ERR_STATE. */
GA_API ga_status ga_set_tolerances(ga_solver *s, double rtol, double atol);

/** As ga_set_tolerances with an absolute tolerance for each coordinate (as SUNDIALS'
 *  IDASVtolerances, SciPy's vector atol): atol holds 2 n + r numbers, the n positions (on a
 *  space with rotations, the n coordinates of the tangent increments), the n velocities, then
 *  the r first-order states. A coordinate whose scale differs from the others' by orders of
 *  magnitude is then held to its own (tests/c/test_tolerance_vector.c). ga_set_tolerances
 *  goes back to one atol. The states are those declared when it is called: ga_set_first_order
 *  with another r afterwards is refused (GA_ERR_STATE).
 *  Errors: GA_ERR_ARG (rtol or an atol entry not positive and finite, atol NULL; the message
 *  names the entry), GA_ERR_STATE. */
GA_API ga_status ga_set_tolerances_vector(ga_solver *s, double rtol, const double *atol);

/** Bounds of adaptive step sizes: h_min (0: 16 eps max(|t|, 1)) and h_max (0: none).
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_step_limits(ga_solver *s, double h_min, double h_max);

/** Size of the first adaptive step (0, default: estimated from q, v, qdd and the tolerances).
 *  Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_initial_step(ga_solver *s, double h0);

/** One adaptive step, of the size the controller proposes but not beyond t_stop (> t); a step
 *  that reaches t_stop lands on it exactly. GA_EVENT as ga_step. Steps rejected by the error test (counter
 *  GA_COUNT_REJECTED_STEPS) or by a recoverable failure (Newton, callback > 0, NaN, singular
 *  matrix; GA_COUNT_FAILED_STEPS) are retried smaller until one is accepted.
 *  Error estimate (position, docs/algorithms.md sec. 1.5a): h^2 (beta + delta_alpha/2 - 1/6)
 *  (a_n+1 - a_n); velocity (sec. 1.5b) from the divided differences of a over two steps. In
 *  the index-3 formulation with constraints at rho_inf <= 0.9 (sec. 1.5c) the differences are
 *  those of the accelerations consistent with each step's (q, v): they are solved for at the
 *  end of every attempted step, and after an accepted one they are its consistent output
 *  (ga_get_qdd, ga_get_lambda read them without another solve). Both follow the tolerance
 *  (tests/c/test_tolerance.c).
 *  Controller: predictive (Gustafsson, as in Radau5), safety 0.9, growth at most 2 and not on
 *  consecutive steps nor right after a rejection, shrink at least 0.2. First step (unless
 *  ga_set_initial_step): half the step over which qdd moves q by the tolerance, in the
 *  weighted norm of the error test.
 *  Use with ga_interpolate for output at user times without shortening steps. The first
 *  adaptive call allocates the workspace of the error estimate's projection or of consistent
 *  output (fixed-step runs do without it); ga_step_adaptive never allocates after that.
 *  Errors: GA_ERR_ARG (t_stop not after t; or the index-3 formulation with constraints at
 *  rho_inf = 1, where each change of h starts a multiplier transient that is never damped and
 *  the run loses its accuracy or its step size: take GA_INDEX2_STABILIZED or rho_inf < 1),
 *  GA_ERR_STATE, GA_ERR_STEP_SIZE, fatal callback failures, and the statuses of ga_step. On
 *  failure the state is that of the last accepted step. */
GA_API ga_status ga_step_adaptive(ga_solver *s, double t_stop);

/** Adaptive steps until t_out (>= t), landing on it exactly (ga_get_t then returns t_out),
 *  or until a terminal event: GA_EVENT, with t at the end of the step that holds it, or until
 *  the step hook asks to stop: GA_STOPPED, with t at the end of that step.
 *  Errors: as ga_step_adaptive; steps accepted before a failure are kept. */
GA_API ga_status ga_advance(ga_solver *s, double t_out);

/** Dense output inside the last step [t_prev, t]: q and v by cubic Hermite interpolation
 *  (from q, v, qdd at both ends; third-order local accuracy); lambda as ga_get_lambda gives
 *  it, at the interpolated (q, v) (GA_OUTPUT_CONSISTENT, default: one saddle-point solve per
 *  call) or linear between the step's own values (GA_OUTPUT_STEP). Any of q (n), v (n),
 *  lambda (m) may be NULL. Errors: GA_ERR_ARG (t outside the last step), GA_ERR_STATE (no step
 *  since ga_init or ga_set_state, or from a callback), and with lambda in
 *  GA_OUTPUT_CONSISTENT those of ga_get_lambda. */
GA_API ga_status ga_interpolate(const ga_solver *s, double t, double *q, double *v,
                                double *lambda);

/** Accelerations at t inside the last step (n doubles): consistent with the interpolated
 *  (q, v) (GA_OUTPUT_CONSISTENT) or linear between the step's own (GA_OUTPUT_STEP).
 *  Errors: as ga_interpolate. */
GA_API ga_status ga_interpolate_qdd(const ga_solver *s, double t, double *qdd);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Events
 *  Event functions g_k(t, q, v, lambda) whose sign changes are located inside accepted steps on
 *  the dense output, never by taking steps again (with Jacobian reuse a re-taken step need not
 *  reproduce a sign change): after each accepted step g is evaluated at its end, and where a
 *  watched sign change shows, the earliest root is found by the Illinois secant method
 *  safeguarded by bisection, to within 100 u (|t| + |h|) after it (u the unit round-off; the
 *  tolerance of SUNDIALS IDA), then the rest of the step is searched from there, so that
 *  roots of several functions in one step are found in time order. A function exactly zero
 *  where a search starts does not fire there; its sign just past that point (1e-6 of the
 *  step, or 100 u |t|) stands for it, so that it fires where it next crosses zero within the
 *  step (a restart at an event whose function crosses again in the first step).
 *  docs/algorithms.md sec. 10. */
/**@{*/
typedef enum ga_event_direction {
    GA_EVENT_BOTH = 0,    /**< any sign change */
    GA_EVENT_RISING = 1,  /**< from below zero to zero or above */
    GA_EVENT_FALLING = -1 /**< from above zero to zero or below */
} ga_event_direction;

/** Entries of the event log of one stepping call: GA_EVENT_LOG, or the number of event
 *  functions if that is larger (every root fits an empty log). */
#define GA_EVENT_LOG 64

/** Watch `count` event functions (0 removes them), evaluated by `fn` with the user pointer of
 *  ga_set_callbacks. direction[k] is a ::ga_event_direction (NULL: all GA_EVENT_BOTH).
 *  terminal[k] nonzero (NULL: all terminal): ga_step, ga_step_adaptive and ga_advance stop
 *  after locating it and return GA_EVENT; zero: the event is logged and the run goes on.
 *  with_multipliers nonzero: fn receives lambda as ga_get_lambda and ga_interpolate give it
 *  (by default from the acceleration-level equations at the interpolated q, v, so that the
 *  time where a multiplier vanishes converges at the method's order; one saddle-point solve
 *  per step and per evaluation inside a step); zero: lambda is NULL and a step costs one call
 *  of fn more than without events.
 *  After GA_EVENT the solver stands at the end of the step in which the event lies (ga_get_t):
 *  ga_get_event gives its time t_e, ga_interpolate(t_e) and ga_interpolate_qdd the state
 *  there. The next stepping call first searches the rest of that step, then goes on; to change
 *  q, v at the event (an impact, a switched force), restart with ga_init(t_e, q, v), which
 *  keeps every option and these events. The search starts afresh from the current state at
 *  the next stepping call after ga_init, ga_set_state or this call.
 *  A failed event callback (or a NaN in g) fails the step that called it, which is undone like
 *  any failed step; a failed ga_step or ga_step_adaptive leaves the search where it was, so
 *  that a retry finds the same events. Allocates (a few arrays of `count` entries, 2 n + m
 *  doubles and the log); may be called before or after ga_init. Errors: GA_ERR_ARG
 *  (count < 0, fn NULL with count > 0, a direction not -1, 0 or 1), GA_ERR_STATE, GA_ERR_NOMEM
 *  (the events set before stay). */
GA_API ga_status ga_set_events(ga_solver *s, int count, ga_event_fn fn, const int *direction,
                               const int *terminal, int with_multipliers);

/** Step hook: called after every step that ga_step, ga_step_adaptive or ga_advance accepts,
 *  with the solver (for reading only: ga_get_*, ga_interpolate*, ga_get_sensitivity, counters),
 *  the step's t, q (n), v (n), lambda (m; NULL unless asked for, see ga_set_step_hook) and its
 *  own user pointer. Return 0 to go on; nonzero stops the call after this step, which stays
 *  accepted: the call returns GA_STOPPED (GA_EVENT if a terminal event stops it too). */
typedef int (*ga_step_hook_fn)(const ga_solver *s, double t, const double *q, const double *v,
                               const double *lambda, void *user);

/** Install the step hook `fn` with its `user` pointer (fn NULL removes it), for progress
 *  reports, on-line reductions (a peak force, an energy balance) and recording without a loop
 *  around ga_step. with_multipliers nonzero: fn receives lambda as ga_get_lambda gives it (in
 *  GA_OUTPUT_CONSISTENT one saddle-point solve per step, whose failure fails the step and
 *  undoes it); zero: lambda is NULL. Not called for steps an adjoint sweep computes again from
 *  its checkpoints, nor by ga_init. Calls that change the solver are refused from the hook
 *  (GA_ERR_STATE); a C++ exception thrown by it fails the call (GA_ERR_INTERNAL) and undoes the
 *  step. Kept by ga_init and ga_set_state; may be set before or after ga_init. Errors:
 *  GA_ERR_ARG (s NULL), GA_ERR_STATE (from a callback or the hook). */
GA_API ga_status ga_set_step_hook(ga_solver *s, ga_step_hook_fn fn, void *user,
                                  int with_multipliers);

/** Events logged by the last ga_step, ga_step_adaptive or ga_advance (each starts an empty
 *  log; ga_advance keeps those of the steps it accepted before a failure; ga_init, ga_set_state
 *  and ga_set_events empty it). A call stops with GA_EVENT when its log is full, as at a
 *  terminal event: nothing is lost. Errors: GA_ERR_ARG, GA_ERR_STATE (from a callback). */
GA_API ga_status ga_get_event_count(const ga_solver *s, int *count);

/** Entry i (0 <= i < count) of that log, in time order: the located time t, the function
 *  `index` and its `direction` (+1 rising, -1 falling). Functions that cross at one located
 *  time are logged one after the other with the same t. Any output pointer may be NULL.
 *  Errors: GA_ERR_ARG (i out of range), GA_ERR_STATE (from a callback). */
GA_API ga_status ga_get_event(const ga_solver *s, int i, double *t, int *index, int *direction);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name First-order states
 *  r states y with first-order equations integrated in the same Newton solve as the mechanism
 *  (a motor current, a controller's integral, a pressure):
 *
 *      M(q) q'' = f(t, q, v, y) - Phi_q^T lambda,   Phi(q, t) = 0,   y' = g(t, q, v, y),
 *
 *  by the first-order generalized-alpha method of Jansen, Whiting and Hulbert with parameters
 *  from the same rho_inf (its spectral radius at infinity is rho_inf; with ga_set_params,
 *  rho_inf = alpha_f / (1 - alpha_f)), second order in y and y'. The coupling blocks enter
 *  the iteration matrix exactly (docs/algorithms.md sec. 9). Without them (r = 0, the
 *  default) the solver is the one it was before they existed, bit for bit. The mechanical
 *  iteration matrix stays as it is (dense or sparse): the Newton system is solved by block
 *  elimination onto y, r more solves with each matrix. */
/**@{*/
/** Applied forces that depend on the first-order states: f(t, q, v, y), length n. */
typedef int (*ga_force_y_fn)(double t, const double *q, const double *v, const double *y,
                             double *f, void *user);
/** The rates y' = g(t, q, v, y): length r. */
typedef int (*ga_rate_fn)(double t, const double *q, const double *v, const double *y,
                          double *ydot, void *user);
/** The coupling blocks, dense and column-major: g_q = dg/dq (r x n), g_v = dg/dv (r x n),
 *  g_y = dg/dy (r x r), f_y = df/dy (n x r). All four are written at every call. */
typedef int (*ga_coupling_fn)(double t, const double *q, const double *v, const double *y,
                              double *g_q, double *g_v, double *g_y, double *f_y, void *user);

/** Declare r >= 0 first-order states, before the first ga_init or ga_init_y (they size the
 *  workspace). rate is required when r > 0; force (may be NULL) then replaces the force
 *  callback of ga_set_callbacks, so that the applied forces see y. Both receive the user
 *  pointer of ga_set_callbacks. r = 0 removes them; coupling patterns declared before are
 *  dropped. Errors: GA_ERR_ARG (r < 0, rate NULL with r > 0), GA_ERR_STATE (after the solver
 *  was set up by ga_init or ga_set_state, or after ga_set_events_y). */
GA_API ga_status ga_set_first_order(ga_solver *s, int r, ga_force_y_fn force, ga_rate_fn rate);

/** The coupling blocks by a callback (NULL: forward differences, r force and 2 n + r rate calls
 *  per iteration matrix). Errors: GA_ERR_STATE (from a callback). */
GA_API ga_status ga_set_coupling(ga_solver *s, ga_coupling_fn fn);

/** Blocks of the first-order coupling with a declared sparsity pattern (ga_set_coupling_pattern). */
typedef enum ga_coupling_block {
    GA_COUPLING_G_Q = 0, /**< dg/dq, r x n */
    GA_COUPLING_G_V = 1  /**< dg/dv, r x n */
} ga_coupling_block;

/** Declare where g_q or g_v can be nonzero (nnz >= 0 entries (rows[k], cols[k]), 0-based; an
 *  empty pattern declares the block zero), after ga_set_first_order and before the first
 *  ga_init_y or ga_set_state. Their finite differences then perturb structurally independent
 *  columns together: one rate call per group of columns instead of one per column (a motor
 *  whose rate depends on one velocity: 1 call instead of n). The blocks the coupling callback
 *  writes are dense whatever the pattern. Errors: GA_ERR_ARG (unknown block, NULL arrays with
 *  nnz > 0, an index out of range), GA_ERR_STATE (before ga_set_first_order with r > 0, or
 *  after the solver was set up). */
GA_API ga_status ga_set_coupling_pattern(ga_solver *s, int which, int nnz, const int *rows,
                                         const int *cols);

/** exact nonzero (default): the coupling blocks g_q, g_v and f_y are in the iteration matrix;
 *  zero: they are left out (only g_y, in the rows of y), as codes that couple such states
 *  loosely do -- the same solution, at the price of more Newton iterations (a measurement
 *  aid). Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_coupling_exact(ga_solver *s, int exact);

/** ga_init with the initial first-order states y0 (length r): y'0 = g(t0, q0, v0, y0) after
 *  the positions and velocities are made consistent. ga_init on a solver with r > 0 keeps the
 *  states it holds (a restart after an impact) and is refused before the first ga_init_y.
 *  Errors: those of ga_init; GA_ERR_ARG (y0 NULL or not finite). */
GA_API ga_status ga_init_y(ga_solver *s, double t0, const double *q0, const double *v0,
                           const double *y0);

/** The first-order states y and their rates y' = g at the accepted step (length r each; either
 *  pointer may be NULL). Errors: GA_ERR_ARG, GA_ERR_STATE (before ga_init_y). */
GA_API ga_status ga_get_y(const ga_solver *s, double *y, double *ydot);

/** Dense output of y and y' inside the last step (as ga_interpolate): cubic Hermite from y and
 *  y' at both ends, and its derivative. Errors: as ga_interpolate. */
GA_API ga_status ga_interpolate_y(const ga_solver *s, double t, double *y, double *ydot);

/** Event functions that see the first-order states: g_k(t, q, v, y, lambda) (y of length r;
 *  lambda as for ga_event_fn). */
typedef int (*ga_event_y_fn)(double t, const double *q, const double *v, const double *y,
                             const double *lambda, double *g, void *user);
/** ga_set_events with functions of y as well (inside a step y comes from ga_interpolate_y);
 *  replaces the functions of ga_set_events, and the reverse. Errors: as ga_set_events;
 *  GA_ERR_STATE (functions given before ga_set_first_order with r > 0). */
GA_API ga_status ga_set_events_y(ga_solver *s, int count, ga_event_y_fn fn, const int *direction,
                                 const int *terminal, int with_multipliers);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Sensitivities
 *  Derivatives of the discrete solution with respect to np parameters p (docs/algorithms.md
 *  sec. 11), forward (after each accepted step, dq/dp_j, dv/dp_j, dqdd/dp_j and dlambda/dp_j of
 *  that step's own q, v, qdd and lambda) or by the discrete adjoint of a cost -- the derivative
 *  of what galpha computes (with the step sizes held fixed as inputs), not of the exact
 *  solution. The iteration matrix is factorized again at each converged step with every
 *  tangent (the next step's Newton iteration starts with it); each parameter then costs one
 *  solve and the parameter derivatives of the residual. Exact to round-off with exact tangents
 *  (ga_set_tangents); with tangents by central differences (galpha's otherwise), to their
 *  precision, about eps^(2/3). */
/**@{*/
/** What depends on the parameters (flags, or-ed). The others are taken as independent of p:
 *  their derivatives are not evaluated. */
typedef enum ga_depends {
    GA_DEPENDS_FORCE = 1, /**< the applied forces f */
    GA_DEPENDS_MASS = 2,  /**< the mass matrix M (not with ga_set_constant_mass) */
    GA_DEPENDS_RATE = 4,  /**< the rates g of first-order states (central differences) */
    GA_DEPENDS_CONSTRAINT = 8 /**< the constraints Phi (and so Phi_q, Phi_t) */
} ga_depends;

/** df/dp_j at (t, q, v) into f_p (length n), for parameter j (0-based). */
typedef int (*ga_force_p_fn)(double t, const double *q, const double *v, int j, double *f_p,
                             void *user);
/** (dM/dp_j)(q) a into out (length n). */
typedef int (*ga_mass_p_fn)(double t, const double *q, int j, const double *a, double *out,
                            void *user);

/** The derivatives of the constraints in p_j at (t, q): dPhi/dp_j into phi_p (length m), the
 *  derivative of Phi_q into Phi_q_p (in the layout of the Jacobian callback: dense column-major
 *  m x n, or the values of its pattern) and, when Phi_t_p is not NULL (stabilized index 2),
 *  that of Phi_t into Phi_t_p (length m; zeros for constraints that do not depend on t). */
typedef int (*ga_constraint_p_fn)(double t, const double *q, int j, double *phi_p,
                                  double *Phi_q_p, double *Phi_t_p, void *user);

/** Sensitivities with respect to p[0 .. np-1], before ga_init (they start there: q0 and v0
 *  independent of p unless ga_set_sensitivity_start says otherwise, qdd0 and lambda0 follow). p is the array
 *  the callbacks read through their user pointer: without derivative callbacks galpha
 *  perturbs its entries in place (central differences, restored bit for bit before any call
 *  returns), and it must stay valid while the solver lives. p_scale (may be NULL: |p_j|, or 1
 *  where p_j = 0) sets the size of those perturbations, cbrt(eps) p_scale[j]. depends is an
 *  or of ::ga_depends. np = 0 turns sensitivities off; the method is forward again
 *  (ga_set_sensitivity_method). Errors: GA_ERR_ARG (np < 0, p NULL
 *  with np > 0, a p_scale entry not positive and finite, unknown flags, GA_DEPENDS_MASS with
 *  a constant mass), GA_ERR_STATE (after ga_init), GA_ERR_NOMEM. First-order states are declared before
 *  (ga_set_first_order); their y and y' have derivatives too (ga_get_sensitivity_y), with the
 *  coupling blocks in the iteration matrix (ga_set_coupling_exact on, the default). */
GA_API ga_status ga_set_sensitivity(ga_solver *s, int np, double *p, const double *p_scale,
                                    int depends);

/** The derivatives of the initial values with respect to p_j, dq0/dp_j and dv0/dp_j (length n
 *  each; NULL: zero, the default), used by every later ga_init: initial values as parameters
 *  (a p_j that no callback reads), or initial values that depend on a model parameter. The
 *  start projects them as it projects q0 and v0 (at consistent q0 and v0 the derivative of its
 *  minimum-norm projections): dq0 onto Phi_q dq = 0, dv0 onto Phi_q dv = -d(Phi_q v + Phi_t)/dq
 *  dq. Errors: GA_ERR_ARG (j out of range, a value not finite), GA_ERR_STATE (no
 *  sensitivities), GA_ERR_NOMEM. */
GA_API ga_status ga_set_sensitivity_start(ga_solver *s, int j, const double *dq0,
                                          const double *dv0);

/** Derivative callbacks (either may be NULL: central differences in p). Errors: GA_ERR_STATE
 *  (from a callback). */
GA_API ga_status ga_set_parameter_derivatives(ga_solver *s, ga_force_p_fn force_p,
                                              ga_mass_p_fn mass_p);

/** The constraints' derivative callback, for GA_DEPENDS_CONSTRAINT (NULL: central differences
 *  of Phi, Phi_q and Phi_t in p, the default). Where the constraints depend on p, q0 and v0
 *  that satisfy them at p do not at p + dp: their derivatives are those of the start's
 *  minimum-norm projection, Phi_q dq0 = -dPhi/dp and the like for v0. Errors: GA_ERR_STATE
 *  (from a callback). */
GA_API ga_status ga_set_constraint_parameter_derivative(ga_solver *s, ga_constraint_p_fn fn);

/** The sensitivities of the accepted step with respect to p_j (lengths n, n, n, m; any pointer
 *  may be NULL). qdd and lambda are the step's own (GA_OUTPUT_STEP), whatever ga_set_output
 *  says. Errors: GA_ERR_ARG (j out of range), GA_ERR_STATE (before ga_init, no sensitivities,
 *  or only the adjoint's record). */
GA_API ga_status ga_get_sensitivity(const ga_solver *s, int j, double *dq, double *dv,
                                    double *dqdd, double *dlambda);

/** The sensitivities of the first-order states y and their rates y' with respect to p_j
 *  (length r each; either pointer may be NULL). Errors: as ga_get_sensitivity. */
GA_API ga_status ga_get_sensitivity_y(const ga_solver *s, int j, double *dy, double *dydot);

/** How sensitivities are computed (flags, or-ed). */
typedef enum ga_sensitivity_method {
    GA_SENSITIVITY_FORWARD = 1, /**< after each step, for ga_get_sensitivity (default) */
    GA_SENSITIVITY_ADJOINT = 2  /**< the run is recorded for ga_adjoint_gradient */
} ga_sensitivity_method;

/** methods is an or of ::ga_sensitivity_method; with GA_SENSITIVITY_ADJOINT each accepted step
 *  from ga_init on is recorded (its size, q, v, qdd, lambda: 3 n + 2 m + 4 doubles), for up to
 *  max_steps steps, allocated here; a step beyond them fails with GA_ERR_NOMEM and changes
 *  nothing. A rejected adaptive step then drops the kept iteration matrix (one factorization
 *  more per rejection), so that the run can be repeated from a checkpoint bit for bit
 *  (ga_set_adjoint_checkpoints). After ga_set_sensitivity, before ga_init. Errors: GA_ERR_ARG (no method, unknown
 *  flags, max_steps < 1 with the adjoint), GA_ERR_STATE (no parameters, after ga_init),
 *  GA_ERR_NOMEM (also a record larger than any vector: checked before it is computed). */
GA_API ga_status ga_set_sensitivity_method(ga_solver *s, int methods, long max_steps);

/** Checkpointing for runs whose adjoint record does not fit: the record keeps the steps of one
 *  segment of `interval` steps, and a checkpoint of the solver (ga_state_size doubles) after
 *  every interval-th step, `count` of them, for runs of up to interval * count steps (plus 11
 *  doubles per step: each step's size, time and how it was attempted). ga_adjoint_gradient
 *  computes each earlier segment again from its checkpoint: one more forward pass. Memory
 *  (3 n + 2 m + 4) (interval + 1) + count ga_state_size + 11 N doubles instead of
 *  (3 n + 2 m + 4) N; interval = sqrt(N ga_state_size / (3 n + 2 m + 4)) makes the first two
 *  equal. The recomputed steps are the recorded ones bit for bit: each begins with the
 *  kept matrix and reuse state its original began with (in runs recorded for the adjoint a
 *  rejected step drops the kept matrix, so that this is known). The callbacks must give the
 *  same values when called again, and the options stay as they were during the run. interval = 0 returns to the full record of
 *  ga_set_sensitivity_method's max_steps. After ga_set_sensitivity_method with
 *  GA_SENSITIVITY_ADJOINT, before ga_init. Errors: GA_ERR_ARG (interval < 0, count < 1 with
 *  interval > 0, interval * count overflows), GA_ERR_STATE (no adjoint method, after
 *  ga_init), GA_ERR_NOMEM (also sizes larger than any vector: checked before they are
 *  computed). */
GA_API ga_status ga_set_adjoint_checkpoints(ga_solver *s, long interval, long count);

/** A cost term: its value at (t, q, v, qdd, lambda) and every partial derivative, in q, v, qdd
 *  (n each), lambda (m; lambda and d_lambda are NULL when m = 0) and the parameters p (np); all
 *  outputs are written. (On a space with rotations, ga_create_space, q has nq entries and d_q
 *  nv: the derivative along right increments, as Phi_q's.) */
typedef int (*ga_cost_fn)(double t, const double *q, const double *v, const double *qdd,
                          const double *lambda, double *value, double *d_q, double *d_v,
                          double *d_qdd, double *d_lambda, double *d_p, void *user);

/** The cost J = G(x_N) + sum_n w_n L(x_n) over the steps recorded since ga_init (x_n: t, q, v,
 *  and the steps' own qdd and lambda; w_n the trapezoidal weights of the step sizes, so that
 *  the sum is the trapezoidal rule for the integral of L), and its gradient dJ/dp (np) by the
 *  discrete adjoint of the steps taken: one backward sweep, one transposed solve per step with
 *  the exact iteration matrix evaluated again at the recorded state. running (L) or terminal
 *  (G) may be NULL. The recorded run must not contain Taylor steps or fresh starts after the
 *  first step (ga_step sizes over 100 times shorter or longer than the one before). Leaves the
 *  run as it was (it may be continued and asked again), also when it fails: with checkpoints
 *  (ga_set_adjoint_checkpoints) the segments are computed again in an iteration matrix of
 *  their own, allocated by each call, while the run's kept one waits aside, so that the run
 *  goes on bit for bit as it would have without the call. Errors: GA_ERR_ARG (both NULL),
 *  GA_ERR_STATE (no adjoint recording, before ga_init, a step kind not covered, dropped
 *  redundant constraints), callback and linear-algebra errors. */
GA_API ga_status ga_adjoint_gradient(ga_solver *s, ga_cost_fn running, ga_cost_fn terminal,
                                     double *J, double *dJ_dp);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Consistent start */
/**@{*/
/** Optional callback for the constraint acceleration term (finite differences of Phi_q and Phi
 *  otherwise). Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_constraint_accel(ga_solver *s, ga_constraint_accel_fn fn);

/** Optional callback for Phi_t(q, t), the partial time derivative of the constraints (length m,
 *  same signature as the constraint callback), used by the consistent start (velocities) and by
 *  the stabilized index-2 formulation (the velocity constraint Phi_q v + Phi_t, every Newton
 *  iteration). NULL (default): central differences in t over 2^-13 max(|t|, 1) and half
 *  that, extrapolated (error O(d^4)), four constraint calls per evaluation; in index 2 the
 *  velocity constraint then holds to the error of those differences (4e-12 on a pendulum of
 *  varying length, 2e-16 with the callback; tests/c/test_init.c).
 *  Constraints that do not depend on t have Phi_t = 0: a callback that writes zeros saves
 *  those calls. Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_constraint_dt(ga_solver *s, ga_constraint_fn fn);

typedef enum ga_init_mode {
    GA_INIT_PROJECT = 0, /**< project inconsistent q0, v0 (minimum-norm correction; default) */
    GA_INIT_REFUSE = 1   /**< refuse inconsistent q0, v0 with GA_ERR_INCONSISTENT */
} ga_init_mode;

/** What ga_init does with inconsistent q0, v0 (mode is a ::ga_init_mode), and the tolerance
 *  init_tol (> 0, default 1e-10, in the units of Phi and of Phi_q v) beyond which they count as
 *  inconsistent. Projection
 *  iterates to round-off, well below init_tol. Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_set_init_mode(ga_solver *s, int mode, double init_tol);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Output of accelerations and multipliers */
/**@{*/
typedef enum ga_output {
    GA_OUTPUT_CONSISTENT = 0, /**< (default) ga_get_qdd, ga_get_lambda, ga_interpolate and
                                   ga_interpolate_qdd solve the acceleration-level system
                                   [M Phi_q^T; Phi_q 0] [qdd; lambda] =
                                   [f; -(Phi_qq(v,v) + 2 Phi_qt v + Phi_tt)] at the step's (or
                                   the interpolated) t, q, v: as accurate as q and v, free of
                                   the eps |q| / (beta h^2) round-off of index-3 multipliers
                                   (paper, sec. 3.3) and of their transient after each change
                                   of h in adaptive runs (docs/algorithms.md sec. 1.4). Costs the
                                   callbacks M, f, Phi_q, the constraint acceleration term and
                                   one factorization of that matrix per accepted step read (the
                                   result is kept until the next step), dense or sparse like
                                   the iteration matrix, with a workspace of its own allocated
                                   with the solver's: reading never changes the run. */
    GA_OUTPUT_STEP = 1        /**< the values the step computed (Algorithm 1's qdd_{n+1} and
                                   lambda_{n+1}), interpolated linearly: no work at output */
} ga_output;

/** mode is a ::ga_output. Errors: GA_ERR_ARG, GA_ERR_STATE, GA_ERR_NOMEM (consistent output
 *  chosen after ga_init, and its workspace does not fit). */
GA_API ga_status ga_set_output(ga_solver *s, int mode);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name State
 *  Copies of the current (last accepted) state. Errors: GA_ERR_ARG (NULL), GA_ERR_STATE
 *  (before ga_init, or from a callback). */
/**@{*/
/** Time t of the last accepted step (t0 after ga_init). */
GA_API ga_status ga_get_t(const ga_solver *s, double *t);
/** Copy the positions q (n doubles, caller's buffer). */
GA_API ga_status ga_get_q(const ga_solver *s, double *q);
/** Copy the velocities q' (n doubles). */
GA_API ga_status ga_get_v(const ga_solver *s, double *v);
/** The accelerations q'' (n doubles) of the last accepted step: by default (see
 *  ga_set_output) consistent with its q and v, otherwise the step's own (second order
 *  accurate: the residual is not weighted, unlike the auxiliary vector a).
 *  Errors: GA_ERR_ARG, GA_ERR_STATE, and in GA_OUTPUT_CONSISTENT those of the callbacks
 *  (GA_ERR_CALLBACK, GA_ERR_CALLBACK_RETRY, GA_ERR_NONFINITE) and GA_ERR_SINGULAR, with a
 *  message; the solver's state is never changed. */
GA_API ga_status ga_get_qdd(const ga_solver *s, double *qdd);
/** The Lagrange multipliers lambda (m doubles; with the sign convention
 *  M q'' = f - Phi_q^T lambda) of the last accepted step, as ga_get_qdd gives accelerations.
 *  With m = 0, lambda may be NULL. Errors: as ga_get_qdd. */
GA_API ga_status ga_get_lambda(const ga_solver *s, double *lambda);
/** Copy the auxiliary acceleration-like vector a of eq. (3) (n doubles). */
GA_API ga_status ga_get_a(const ga_solver *s, double *a);
/** Size of the last accepted step of Algorithm 1 (0 before the first; a sliver, a Taylor step
 *  more than 100 times shorter than the one before it, leaves it: see ga_step). */
GA_API ga_status ga_get_h_last(const ga_solver *s, double *h);
/**@}*/

/** @name Checkpoint and restart
 *  The full state as a flat array of doubles, so a host simulator can save, restore and
 *  restart: a run restarted from a checkpoint continues bit-identically, in fixed-step and in
 *  adaptive mode, dense and sparse, in both formulations (from a checkpoint taken before the
 *  first step too: that step still applies the corrected start). Taking a checkpoint only
 *  reads: a run that takes them is the run that does not, bit for bit and with the same work.
 *  Layout 4 (treat it as opaque): a header [magic, layout version, n, m, t, h_last, h_next,
 *  err_prev, grew, sliver_span, then 9 entries on the kept iteration matrix and its reuse,
 *  c_count, c_dt], the state q(n), v(n), qdd(n), lambda(m), a(n), a_prev(n), c(n),
 *  c_prev(n), the iterate the kept matrix was factorized at, the constraints in use (m flags),
 *  and the pivots of the sparse factorizations (zeros on the dense path).
 *  h_next, err_prev, grew: the step-size controller; sliver_span: the time covered by slivers
 *  since the last step of Algorithm 1 (see ga_step); a_prev: the a of the step before, for
 *  the error estimate; c, c_prev: the accelerations consistent with this state and the one
 *  before, c_dt apart in t, for the index-3 error estimate (c_count of them known, zeros
 *  where not). ga_set_state rebuilds the kept matrix from the callbacks at that
 *  iterate (one evaluation and one factorization, counted like any other; should a callback
 *  fail there, the next step factorizes afresh instead, and the run continues as after a
 *  restart) and gives each sparse factorization its pivots back. A failed step drops the
 *  kept matrix, so the checkpoint taken after it has none. ga_set_state also reads layout 3,
 *  as the same state without consistent accelerations (the next adaptive index-3 step
 *  estimates its error from a, as after a fixed step), and layout 2 (galpha 0.2), as a
 *  restart: a fresh iteration matrix, sparse pivots chosen afresh, and with
 *  GA_REDUNDANT_DROP the constraints in use selected anew at its q. ga_set_state needs
 *  callbacks set, allocates like ga_init (when the solver
 *  was not initialized) and makes the solver initialized; dense output (ga_interpolate) is
 *  available again after the next step. */
/**@{*/
/** Number of doubles in a checkpoint. Errors: GA_ERR_ARG. */
GA_API ga_status ga_state_size(const ga_solver *s, size_t *len);
/** Errors: GA_ERR_ARG (NULL, len too small), GA_ERR_STATE (before ga_init). */
GA_API ga_status ga_get_state(const ga_solver *s, double *buf, size_t len);
/** Errors: GA_ERR_ARG (NULL, wrong length, magic, version or sizes, non-finite values, or
 *  step-size entries galpha never writes: h_last or h_next negative or too small to move t,
 *  err_prev negative, grew other than 0 or 1, sliver_span negative or over h_last / 100,
 *  entries 10-18 or the pivots not as a solver writes them, a constraint dropped while this
 *  solver keeps every constraint), GA_ERR_STATE (callbacks not set), GA_ERR_NOMEM. */
GA_API ga_status ga_set_state(ga_solver *s, const double *buf, size_t len);
/**@}*/

/* ------------------------------------------------------------------------------------------ */
/** @name Counters
 *  Work done since creation (or ga_reset_counters), failed attempts included, so that
 *  work-precision comparisons count honestly. Keys are pinned and only appended. */
/**@{*/
typedef enum ga_counter {
    GA_COUNT_STEPS = 0,          /**< accepted steps */
    GA_COUNT_FAILED_STEPS = 1,   /**< step attempts that failed (Newton, callbacks, NaN,
                                      singular matrix), in ga_step or inside adaptive steps */
    GA_COUNT_NEWTON_ITERS = 2,   /**< Newton iterations (linear solves in ga_step) */
    GA_COUNT_FACTORIZATIONS = 3, /**< LU factorizations (including ga_init's and, in adaptive
                                      mode, that of the error estimate's projection) */
    GA_COUNT_RESIDUALS = 4,      /**< evaluations of the residual (r^q, r^lambda), those of
                                      finite-difference tangents included */
    GA_COUNT_MASS_EVALS = 5,     /**< mass matrix callback calls (finite differences included) */
    GA_COUNT_FORCE_EVALS = 6,    /**< force callback calls (finite differences included) */
    GA_COUNT_CONSTRAINT_EVALS = 7, /**< constraint callback calls */
    GA_COUNT_JACOBIAN_EVALS = 8, /**< constraint Jacobian callback calls */
    GA_COUNT_STIFFNESS_EVALS = 9, /**< K_t evaluations (callback or finite differences) */
    GA_COUNT_DAMPING_EVALS = 10, /**< C_t evaluations (callback or finite differences) */
    GA_COUNT_ACCEL_EVALS = 11,   /**< constraint acceleration term evaluations */
    GA_COUNT_REJECTED_STEPS = 12, /**< adaptive mode: steps rejected by the error test (steps
                                      whose Newton iteration or callbacks failed count in
                                      GA_COUNT_FAILED_STEPS) */
    GA_COUNT_CONSTRAINT_DT_EVALS = 13, /**< Phi_t evaluations (callback, or finite differences:
                                      their constraint calls count in
                                      GA_COUNT_CONSTRAINT_EVALS too) */
    GA_COUNT_EVENT_EVALS = 14,   /**< event function callback calls (ga_set_events) */
    GA_COUNT_RATE_EVALS = 15,    /**< first-order rate callback calls, y' = g (finite
                                      differences of the coupling blocks included) */
    GA_COUNT_COUPLING_EVALS = 16 /**< evaluations of the coupling blocks g_q, g_v, g_y, f_y
                                      (callback or finite differences) */
} ga_counter;
#define GA_COUNTER_COUNT 17

/** Value of the counter `key` (a ::ga_counter). Errors: GA_ERR_ARG (NULL or unknown key),
 *  GA_ERR_STATE. */
GA_API ga_status ga_get_counter(const ga_solver *s, int key, long long *value);
/** Set all counters to zero. Errors: GA_ERR_ARG, GA_ERR_STATE. */
GA_API ga_status ga_reset_counters(ga_solver *s);
/**@}*/

/** @name Diagnostics of the last step
 *  Double-valued facts about the most recent Newton solve, for studies and tuning. */
/**@{*/
typedef enum ga_info {
    GA_INFO_RCOND = 0,        /**< reciprocal condition number (1-norm estimate) of the
                                   iteration matrix factorized last, as solved: scaled by
                                   eq. (10) or not; 1/value is its condition number. Dense:
                                   galpha's own estimate on the LU factors (Hager-Higham, the
                                   algorithm of LAPACK's dgecon, whose bits would be the system
                                   BLAS's); sparse: KLU's
                                   klu_condest on a factorization made for it, of the matrix
                                   with its rows equilibrated as factorized. Computed when
                                   asked for (a few solves; on the sparse path also a
                                   factorization, which allocates), never in steps; 0 if the
                                   matrix was singular (or, sparse, memory ran out). */
    GA_INFO_NEWTON_ITERS = 1, /**< Newton iterations of the last ga_step (accepted or not) */
    GA_INFO_NEWTON_RATIO = 2, /**< last increment / tolerance ratio of that step's stopping
                                   test (<= 1 means converged by the relative test) */
    GA_INFO_ERROR_ESTIMATE = 3, /**< adaptive mode: weighted error norm of the last step
                                     attempted (<= 1: accepted) */
    GA_INFO_H_NEXT = 4,         /**< adaptive mode: step size the controller proposes next */
    GA_INFO_VELOCITY_RESIDUAL = 5 /**< index 3 with constraints: the last step's largest
                                       |Phi_q v + Phi_t|_i relative to row i's gradient times
                                       the model's largest speed (ga_set_resolution_check); above its
                                       limit the step fails with GA_ERR_UNRESOLVED. 0 in
                                       index 2 (which holds it) */
} ga_info;
#define GA_INFO_COUNT 6

/** Checks every derivative callback given -- the constraint Jacobian (of ga_set_callbacks),
 *  ga_set_constraint_dt, ga_set_constraint_accel, ga_set_tangents (K_t, C_t), ga_set_coupling
 *  (g_q, g_v, g_y, f_y) and the parameter derivatives (ga_set_parameter_derivatives,
 *  ga_set_constraint_parameter_derivative) -- at the state (t, q, v, qdd, lambda, y) against
 *  central differences of the callbacks they derive (Phi_q of Phi in q, Phi_t of Phi in t, the
 *  acceleration term as the second derivative of Phi along (q + s v, t + s), K_t of
 *  r^q = M qdd - f + Phi_q^T lambda in q, C_t of -f in v, the coupling blocks of g and f, the
 *  parameter derivatives of f, M qdd, Phi and Phi_q in p_j, perturbed in place and put back).
 *  qdd may be NULL (zero), lambda (ones, so that K_t's constraint part is checked too) and y
 *  (zero). Each derivative's worst entry is taken relative to its largest entry (callback or
 *  differences; on the shipped scenes' correct callbacks the differences agree to 2e-8 at
 *  worst, a wrong sign or factor shows as 0.5 to 2):
 *  all within tol (say 1e-6), GA_OK and *worst (may be NULL) the largest; else
 *  GA_ERR_DERIVATIVE, and ga_last_error names each derivative beyond tol with its worst entry
 *  and both values. A constraint whose row of Phi_q is zero at q is GA_ERR_DERIVATIVE too
 *  ("constraint i has a zero gradient"). The solver's state and set-up are not touched; the
 *  evaluations are counted; O(n) evaluations of each function per derivative. Errors:
 *  GA_ERR_ARG (NULL q or v, a value not finite, tol not > 0), GA_ERR_STATE (no callbacks, or
 *  from a callback), callback errors. */
GA_API ga_status ga_check_derivatives(ga_solver *s, double t, const double *q, const double *v,
                                      const double *qdd, const double *lambda, const double *y,
                                      double tol, double *worst);

/** Value of the diagnostic `key` (a ::ga_info); 0 before anything was computed.
 *  Errors: GA_ERR_ARG (NULL or unknown key), GA_ERR_STATE (from a callback). */
GA_API ga_status ga_get_info(const ga_solver *s, int key, double *value);
/**@}*/

/** @name Operating points: static equilibrium, linearization, vibration modes
 *  From the callbacks of the dynamics (M, f, Phi, Phi_q and, where given, K_t and C_t; central
 *  differences otherwise), at rest: v = 0, qdd = 0. Dense, but for ga_modes_near and the
 *  static solve of a model on the sparse path; on coordinates in R^n, and with first-order
 *  states only in ga_static_equilibrium_y, ga_state_space and ga_state_space_motion
 *  (GA_ERR_STATE otherwise). Callable before or after ga_init:
 *  the solver's state and set-up are not touched, the evaluations are counted.
 *  docs/algorithms.md sec. 15. */
/**@{*/
/** Static equilibrium at time t: f(q, 0, t) = Phi_q^T lambda, Phi(q, t) = 0, by Newton from
 *  the q given, in the null space of Phi_q (redundant constraints take the minimum-norm
 *  multipliers) -- for a model on the sparse path (declared patterns of M, Phi_q and K_t, as
 *  the solver's linear-solver option chooses) on the sparse [K_t, Phi_q^T; Phi_q, 0] instead,
 *  where redundant constraints are GA_ERR_SINGULAR, and whose starting multipliers come from
 *  the sparse [M, Phi_q^T; Phi_q, 0]: a free direction without mass (a massless node) is
 *  GA_ERR_SINGULAR there, though the dense path finds its equilibrium --, with a backtracking line search on
 *  |f - Phi_q^T lambda|^2 + |Phi|^2. Converged when a full Newton step moves q by at most
 *  tol max(1, |q|_inf) (taken, or not taken where round-off keeps it from reducing the
 *  residual), or when the residuals are
 *  within 8 ulps of the forces (applied, constraint, elastic) and of q. On GA_OK q holds the
 *  equilibrium and lambda (length m, may be NULL) its multipliers; on failure both are
 *  untouched. Load stepping: a load factor the callbacks read through `user`, raised between
 *  calls, each started from the last equilibrium. Errors: GA_ERR_ARG (NULL q, tol not finite
 *  and > 0, max_iter < 1, t or q not finite), GA_ERR_STATE (no callbacks, rotations,
 *  first-order states, from a callback), GA_ERR_SINGULAR (the stiffness in the constraints'
 *  free directions is singular: a limit point, or a motion nothing restrains),
 *  GA_ERR_NEWTON (no equilibrium in max_iter iterations, or none in reach along Newton's
 *  direction), GA_ERR_INCONSISTENT (redundant constraints that contradict each other, as
 *  Phi = (x, x - 1): Newton stops where |Phi| is least, and |Phi| there is more than 100 tol
 *  times the sizes of q and Phi_q), callback errors. */
GA_API ga_status ga_static_equilibrium(ga_solver *s, double t, double *q, double *lambda,
                                       double tol, int max_iter);

/** The small motions about (q, lambda) at rest in minimal coordinates q = q0 + N z, with
 *  Phi_q N = 0: *dof = n - rank(Phi_q) and, each output optional (NULL), N (n x dof,
 *  orthonormal columns), the reduced mass N^T M N, damping N^T C_t N and stiffness
 *  N^T K_t N (dof x dof; K_t includes the constraints' d(Phi_q^T lambda)/dq), column-major
 *  with ld = n for N and dof for the others. The system is M z'' + C z' + K z = 0 (about an
 *  equilibrium). lambda NULL: the multipliers that balance f at q (least squares). Nothing is
 *  written unless *dof <= max_dof. Errors: GA_ERR_ARG (NULL q or dof, a value not finite,
 *  *dof > max_dof: the message says *dof), GA_ERR_STATE as ga_static_equilibrium, callback
 *  errors. */
GA_API ga_status ga_linearize(ga_solver *s, double t, const double *q, const double *lambda,
                              int max_dof, int *dof, double *N, double *M, double *C, double *K);

/** Static equilibrium with first-order states (ga_set_first_order) as unknowns too:
 *  f(q, 0, y, t) = Phi_q^T lambda, g(q, 0, y, t) = 0, Phi(q, t) = 0, by Newton from (q, y) in
 *  the null space of Phi_q, the coupling blocks g_q, g_y, f_y by their callback
 *  (ga_set_coupling) or central differences; otherwise as ga_static_equilibrium (dense), also
 *  converged when the rates are within 8 ulps of their terms and a step moves y by at most
 *  tol max(1, |y|_inf). y (length r) holds the states' start and, on GA_OK, their rest; with
 *  r = 0 y may be NULL and this is ga_static_equilibrium's dense path. On failure q, y and
 *  lambda are untouched. Errors as ga_static_equilibrium (GA_ERR_ARG also for a NULL y with
 *  r > 0). */
GA_API ga_status ga_static_equilibrium_y(ga_solver *s, double t, double *q, double *y,
                                         double *lambda, double tol, int max_iter);

/** The first-order (state-space) form of the small motions about (q, y, lambda) at rest, in
 *  the minimal coordinates q = q0 + N z of ga_linearize and with the first-order states:
 *  x = (z, z', y), x' = A x with
 *      A = [0, I, 0; -M^-1 K, -M^-1 C, M^-1 N^T f_y; g_q N, g_v N, g_y]
 *  (M, C, K the reduced matrices of ga_linearize, f_y, g_q, g_v, g_y the coupling blocks at
 *  (q, 0, y) by their callback or central differences). *dim = 2 dof + r; N (n x dof, may be
 *  NULL) and A (dim x dim, column-major, may be NULL) written only if *dim <= max_dim. About
 *  an equilibrium its eigenvalues are the damped modes' s with the states' own; about another
 *  point at rest it is the tangent system there. y may be NULL when r = 0; lambda NULL: the
 *  balancing multipliers. Errors: GA_ERR_ARG (NULL q or dim, NULL y with r > 0, a value not
 *  finite, *dim > max_dim: the message says *dim), GA_ERR_SINGULAR (a singular mass in the
 *  free directions), GA_ERR_STATE (no callbacks, rotations, from a callback), callback
 *  errors. */
GA_API ga_status ga_state_space(ga_solver *s, double t, const double *q, const double *y,
                                const double *lambda, int max_dim, int *dim, double *N,
                                double *A);

/** The first-order form of the small motions about a moving state (t, q, v, y) on the
 *  constraints -- any point of a run --: in the chart q(z) = q + N z + R h(z) of the
 *  constraint manifold at q (N as in ga_linearize, R an orthonormal basis of Phi_q's rows'
 *  span, h keeping Phi = 0) with velocities N w + R k (k keeping Phi_q v + Phi_t = 0), the
 *  state x = (z, w, y) obeys x' = (w, N^T qdd, g) with qdd the consistent acceleration and g
 *  the first-order states' rate, and A = dx'/dx at (0, N^T v, y) by central differences
 *  (steps 6.06e-6 max(1, |q|_inf), max(1, |v|_inf), max(1, |y_j|)): with the centripetal
 *  and Coriolis terms, which ga_state_space's tangent system at rest lacks; at v = 0 about an
 *  equilibrium the two agree. *dim = 2 dof + r; N (n x dof) and A (dim x dim, column-major;
 *  each may be NULL) written only if *dim <= max_dim. y (length r) may be NULL when r = 0. On
 *  R^n. Errors: GA_ERR_ARG (NULL q, v or dim, NULL y with r > 0, a value not finite,
 *  *dim > max_dim), GA_ERR_INCONSISTENT (q off the
 *  constraints by more than 1e-8 max(1, |q|_inf), or v off the velocity constraint by more
 *  than 1e-8 max(1, |v|_inf)), GA_ERR_SINGULAR ([M, Phi_q^T; Phi_q, 0] singular near q),
 *  GA_ERR_NEWTON (the chart's projection did not converge), GA_ERR_STATE as
 *  ga_static_equilibrium, callback errors. */
GA_API ga_status ga_state_space_motion(ga_solver *s, double t, const double *q, const double *v,
                                       const double *y, int max_dim, int *dim, double *N,
                                       double *A);

/** The `count` lowest undamped vibration modes at an equilibrium (q, lambda):
 *  (N^T K_t N) z = omega^2 (N^T M N) z. omega2 (length count) ascending; a negative value is an
 *  unstable direction of the equilibrium. shapes (may be NULL): n x count, column-major, the
 *  modes in q (N z), with unit modal mass (shape^T M shape = 1). lambda NULL: the balancing
 *  multipliers. Errors: GA_ERR_ARG (NULL q or omega2, count < 1 or above the degrees of
 *  freedom -- zero when the constraints lock the mechanism --, a value not finite, a
 *  non-symmetric reduced stiffness: a non-conservative force), GA_ERR_INCONSISTENT (q off
 *  the constraints by more than 1e-8 max(1, |q|_inf), or not an equilibrium: the forces along
 *  the free directions above 1e-8 of their size, or a lambda given that does not balance them),
 *  GA_ERR_SINGULAR (a free direction that carries no mass), GA_ERR_STATE as
 *  ga_static_equilibrium, callback errors. */
GA_API ga_status ga_modes(ga_solver *s, double t, const double *q, const double *lambda,
                          int count, double *omega2, double *shapes);

/** The `count` undamped vibration modes at an equilibrium (q, lambda) whose omega^2 lie
 *  nearest the shift sigma, for large models: Lanczos on the shift-inverted operator
 *  (K_t - sigma M)^-1 M restricted to the constraints, through one factorization of
 *  [K_t - sigma M, Phi_q^T; Phi_q, 0] -- sparse where the solver's linear algebra is (declared
 *  patterns of M, Phi_q and K_t; GA_LINEAR_AUTO from n + m >= 10, or GA_LINEAR_SPARSE), dense
 *  otherwise; nothing n x n on the sparse path. sigma = 0 gives the lowest modes of a stable
 *  equilibrium. omega2 (length count) ascending; shapes (may be NULL): n x count,
 *  column-major, unit modal mass (shape^T M shape = 1), the largest entry positive, Phi_q
 *  shape = 0. Converged when each Ritz pair's residual is within 1e-11 of its eigenvalue
 *  (|theta| = 1 / |omega^2 - sigma|). A multiple eigenvalue may appear fewer times than its
 *  multiplicity (as in every single-vector Krylov method). lambda NULL: the multipliers of
 *  [M, Phi_q^T; Phi_q, 0] [a; lambda] = [f; 0], which balance f at an equilibrium. The
 *  constraints must be independent here (they are not dropped). Errors: GA_ERR_ARG (NULL q or
 *  omega2, count < 1 or above n - m, a value not finite, a non-symmetric stiffness in the free
 *  directions), GA_ERR_INCONSISTENT (as ga_modes: off the constraints, not an equilibrium,
 *  lambda unbalanced), GA_ERR_SINGULAR (sigma an eigenvalue, redundant constraints, a free
 *  direction without mass), GA_ERR_INTERNAL (no convergence in 200 restarts), GA_ERR_STATE as
 *  ga_static_equilibrium, callback errors. */
GA_API ga_status ga_modes_near(ga_solver *s, double t, const double *q, const double *lambda,
                               double sigma, int count, double *omega2, double *shapes);

/** The `count` modes of the linearized damped system at an equilibrium (q, lambda), which
 *  may be non-conservative (a follower or circulatory force, gyroscopic terms in C_t): the
 *  eigenvalues s of x' = [0, I; -M^-1 K, -M^-1 C] x in the minimal coordinates of
 *  ga_linearize, 2 dof of them, taken by |s| ascending (a conjugate pair with its positive
 *  imaginary part first): re[k] + i im[k]; Re s > 0 is an unstable mode (divergence or
 *  flutter). shapes_re, shapes_im (each may be NULL): n x count, column-major, the
 *  displacement part in q scaled so that its largest entry is 1. Errors as ga_modes
 *  (count may be up to 2 dof; a non-symmetric stiffness is allowed), GA_ERR_SINGULAR (a
 *  singular mass in the free directions). */
GA_API ga_status ga_modes_damped(ga_solver *s, double t, const double *q, const double *lambda,
                                 int count, double *re, double *im, double *shapes_re,
                                 double *shapes_im);

/** A point of a static path: the load factor, q (n) and lambda (m; NULL when m = 0), with
 *  the user pointer of ga_static_path. Return 0 to go on, nonzero to stop there. */
typedef int (*ga_path_fn)(double load, const double *q, const double *lambda, void *user);

/** The static equilibrium path in a load factor through limit points (snap-through), by
 *  pseudo-arclength continuation: the callbacks read the load factor at *load, which this
 *  call sets (between calls it holds what the caller put there). From the equilibrium at
 *  *load near q (found first, as ga_static_equilibrium does), up to max_points points at arc
 *  length |ds| apart in (q, load) -- the first along increasing load for ds > 0, decreasing
 *  for ds < 0, each next one along the last tangent -- Newton in the null space of Phi_q
 *  bordered by the arc-length equation, converged when a step moves q and the load by at most
 *  tol max(1, |x|); a point Newton misses in 12 iterations is tried at half the arc length,
 *  down to |ds|/1024, and the length grows back by 1.5 after easy points. d f / d load by
 *  central differences in *load. fn (may be NULL) sees each point and may stop the path. On
 *  return, whatever the status, *load, q and lambda (length m, may be NULL) hold the last
 *  point reached, consistent with each other (the start on an early failure). Returns GA_OK
 *  after max_points points, GA_STOPPED when fn stopped it. Errors: GA_ERR_ARG (NULL load or
 *  q, ds = 0 or not finite, max_points < 1, tol not finite and > 0, a value not finite),
 *  GA_ERR_STATE as ga_static_equilibrium, GA_ERR_NEWTON (the path does not go on: the message
 *  says from which load), GA_ERR_SINGULAR (no tangent at a converged point: one exactly on
 *  a bifurcation), the start's errors, callback errors. A bifurcation between two points is
 *  not detected: the path steps over it and stays on its branch (past a pitchfork, on the
 *  branch that has become unstable); ga_modes at the points shows where omega^2 changed
 *  sign. */
GA_API ga_status ga_static_path(ga_solver *s, double t, double *load, double *q, double *lambda,
                                double ds, int max_points, double tol, ga_path_fn fn,
                                void *user);
/**@}*/

/** @name Rotations: SO(3) as unit quaternions
 *  The rotation group's maps, for models whose rotations are rotation vectors or quaternions,
 *  so that their constraint gradients and tangents follow one convention:
 *  - a quaternion is (w, x, y, z), w the scalar part; R(q) x = q x q^-1 maps body to space;
 *  - increments are right (body-frame): q o exp(psi) is q turned by |psi| about psi / |psi| in
 *    its body frame;
 *  - the tangent operator T(psi) is the right-trivialized derivative of exp:
 *    exp(psi + d) = exp(psi) o exp(T(psi) d + O(|d|^2)),
 *    T(psi) = I + ((cos t - 1) / t^2) psi~ + ((t - sin t) / t^3) psi~^2, t = |psi|, psi~ x =
 *    psi cross x (docs/algorithms.md sec. 13).
 *
 *  Each function maps `count` items at once (count >= 0): arrays of count consecutive
 *  3-vectors, quaternions (4 doubles) or 3 x 3 matrices (9, column-major). An output may be
 *  the same array as an input of its shape (in place). They need no solver and touch no state.
 *  Errors (nothing is written): GA_ERR_ARG for count < 0 or too large for its arrays' lengths,
 *  a NULL array with count > 0, a value that is not finite, a finite input whose image is
 *  not (|psi| of 1e200, whose square overflows; ga_so3_compose of quaternions as large), a
 *  quaternion whose norm is not 1 within 1e-6 (ga_so3_log, ga_so3_matrix), and |psi| >= 2 pi
 *  in ga_so3_tangent_inverse (T is singular there); ga_strerror names the status. */
/**@{*/
/** q_i = exp(psi_i): the unit quaternion (cos(t/2), sin(t/2) psi_i / t), t = |psi_i|. */
GA_API ga_status ga_so3_exp(long count, const double *psi, double *q);
/** psi_i = log(q_i): the rotation vector with exp(psi_i) = +-q_i and |psi_i| <= pi (q and -q
 *  are the same rotation); q_i is normalized first. */
GA_API ga_status ga_so3_log(long count, const double *q, double *psi);
/** ab_i = a_i o b_i, the quaternion product (first b_i, then a_i, as rotations). */
GA_API ga_status ga_so3_compose(long count, const double *a, const double *b, double *ab);
/** R_i = R(q_i), the 3 x 3 rotation matrix (column-major); q_i is normalized first. */
GA_API ga_status ga_so3_matrix(long count, const double *q, double *R);
/** T_i = T(psi_i), column-major. */
GA_API ga_status ga_so3_tangent(long count, const double *psi, double *T);
/** T_i = T(psi_i)^-1 = I + (1/2) psi~ + (1/t^2 - cot(t/2) / (2 t)) psi~^2, column-major
 *  (|psi_i| < 2 pi). T is singular at |psi| = 2 pi: the entries grow like 1 / (2 pi - |psi|)
 *  and carry a relative error of about eps / (2 pi - |psi|) there (the increments of a step
 *  stay far below pi). */
GA_API ga_status ga_so3_tangent_inverse(long count, const double *psi, double *T);
/**@}*/

/** @name Poses: SE(3) as a position and a unit quaternion
 *  The special Euclidean group's maps, in the conventions of GA_SPACE_SE3 blocks:
 *  - a pose is 7 numbers (x, q): the position x of the body's origin in space, then its
 *    rotation as a unit quaternion (w, x, y, z), as ga_so3_* take it;
 *  - a twist xi = (u, w) is 6 numbers, the body-frame translation u first, then the rotation w;
 *  - increments are right: (x, R) o exp(u, w) = (x + R V(w) u, R exp(w)), V(w) = T_SO3(w)^T;
 *    exp(u, w) is (V(w) u, exp(w)), and compose is (xa, Ra) o (xb, Rb) = (xa + Ra xb, Ra Rb);
 *  - the tangent operator T(xi) (exp(xi + d) = exp(xi) o exp(T(xi) d + O(|d|^2))) is
 *    [T_SO3(w), C(u, w); 0, T_SO3(w)], C the series sum_k (-1)^k U_k / (k+1)! of the
 *    off-diagonal blocks U_k of ad_xi^k, ad_xi = [w~ u~; 0 w~] (docs/algorithms.md sec. 14).
 *
 *  Arrays, counts, in-place use and errors as for ga_so3_*: twists 6 doubles, poses 7,
 *  matrices 6 x 6 column-major (36); GA_ERR_ARG (nothing written) also for a pose whose
 *  quaternion is not of unit norm within 1e-6 (ga_se3_log, ga_se3_compose), |w| >= 2 pi in
 *  ga_se3_tangent_inverse and |w| > 4 pi in ga_se3_tangent (its series loses accuracy
 *  beyond: a relative error of about eps e^|w|). */
/**@{*/
/** p_i = exp(xi_i) = (V(w_i) u_i, exp(w_i)). */
GA_API ga_status ga_se3_exp(long count, const double *xi, double *p);
/** xi_i = log(p_i): w = log(q_i) (|w| <= pi, as ga_so3_log), u = V(w)^-1 x_i. */
GA_API ga_status ga_se3_log(long count, const double *p, double *xi);
/** ab_i = a_i o b_i = (x_a + R_a x_b, q_a o q_b) (quaternions normalized first). */
GA_API ga_status ga_se3_compose(long count, const double *a, const double *b, double *ab);
/** T_i = T(xi_i), 6 x 6 column-major. */
GA_API ga_status ga_se3_tangent(long count, const double *xi, double *T);
/** T_i = T(xi_i)^-1 = [T_SO3^-1, -T_SO3^-1 C T_SO3^-1; 0, T_SO3^-1] (|w_i| < 2 pi). */
GA_API ga_status ga_se3_tangent_inverse(long count, const double *xi, double *T);
/**@}*/

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* GALPHA_H */
