! galpha for Fortran: module `galpha`.
!
! Two layers in one module:
!  1. bind(C) interfaces to every function of galpha.h, under the C names (ga_create, ga_step,
!     ...), with the status, counter and option constants;
!  2. a thin Fortran layer over all of them: type(galpha_solver) with type-bound procedures
!     that take assumed-shape arrays and check their sizes, and galpha_version /
!     galpha_strerror that return Fortran strings.
! Callbacks are Fortran procedures with bind(C) and the interfaces ga_mass_fn, ... below
! (scalars by value, arrays as explicit-shape or assumed-size, `user` as type(c_ptr), value);
! matrices are column-major, which is Fortran's own order: M(n, n), Phi_q(m, n).
!
! Build: gfortran prog.f90 $(pkg-config --cflags --libs galpha)
module galpha
  use, intrinsic :: iso_c_binding
  implicit none
  private

  ! ---- status codes (ga_status), pinned -------------------------------------------------
  integer(c_int), parameter, public :: GA_OK = 0, GA_ERR_ARG = -1, GA_ERR_STATE = -2, &
       GA_ERR_NOMEM = -3, GA_ERR_CALLBACK = -4, GA_ERR_CALLBACK_RETRY = -5, &
       GA_ERR_NONFINITE = -6, GA_ERR_SINGULAR = -7, GA_ERR_NEWTON = -8, &
       GA_ERR_INCONSISTENT = -9, GA_ERR_INTERNAL = -10, GA_ERR_STEP_SIZE = -11, &
       GA_ERR_UNRESOLVED = -12, GA_ERR_DERIVATIVE = -13, GA_EVENT = 1, GA_STOPPED = 2
  ! ---- options ----------------------------------------------------------------------------
  integer(c_int), parameter, public :: GA_TANGENT_AUTO = 0, GA_TANGENT_FD = 1, &
       GA_TANGENT_NEGLECT = 2
  integer(c_int), parameter, public :: GA_PREDICTOR_CONSTANT_A = 0, GA_PREDICTOR_ZERO = 1, &
       GA_PREDICTOR_EXTRAPOLATE = 2
  integer(c_int), parameter, public :: GA_REUSE_AUTO = 0, GA_REUSE_NEVER = 1
  integer(c_int), parameter, public :: GA_MATRIX_MASS = 0, GA_MATRIX_JACOBIAN = 1, &
       GA_MATRIX_STIFFNESS = 2, GA_MATRIX_DAMPING = 3
  integer(c_int), parameter, public :: GA_LINEAR_AUTO = 0, GA_LINEAR_DENSE = 1, &
       GA_LINEAR_SPARSE = 2, GA_LINEAR_DENSE_LAPACK = 3, GA_LINEAR_DENSE_EIGEN = 4, &
       GA_LINEAR_DENSE_UNBLOCKED = 5
  integer(c_int), parameter, public :: GA_INDEX3 = 0, GA_INDEX2_STABILIZED = 1
  integer(c_int), parameter, public :: GA_SPACE_VECTOR = 0, GA_SPACE_SO3_QUATERNION = 1, &
       GA_SPACE_SO3_MATRIX = 2, GA_SPACE_SE3 = 3
  integer(c_int), parameter, public :: GA_REDUNDANT_REFUSE = 0, GA_REDUNDANT_DROP = 1
  integer(c_int), parameter, public :: GA_INIT_PROJECT = 0, GA_INIT_REFUSE = 1
  integer(c_int), parameter, public :: GA_OUTPUT_CONSISTENT = 0, GA_OUTPUT_STEP = 1
  integer(c_int), parameter, public :: GA_COUPLING_G_Q = 0, GA_COUPLING_G_V = 1
  integer(c_int), parameter, public :: GA_DEPENDS_FORCE = 1, GA_DEPENDS_MASS = 2, &
       GA_DEPENDS_RATE = 4, GA_DEPENDS_CONSTRAINT = 8
  integer(c_int), parameter, public :: GA_SENSITIVITY_FORWARD = 1, GA_SENSITIVITY_ADJOINT = 2
  integer(c_int), parameter, public :: GA_EVENT_BOTH = 0, GA_EVENT_RISING = 1, &
       GA_EVENT_FALLING = -1, GA_EVENT_LOG = 64
  integer(c_int), parameter, public :: GA_COUNT_STEPS = 0, GA_COUNT_FAILED_STEPS = 1, &
       GA_COUNT_NEWTON_ITERS = 2, GA_COUNT_FACTORIZATIONS = 3, GA_COUNT_RESIDUALS = 4, &
       GA_COUNT_MASS_EVALS = 5, GA_COUNT_FORCE_EVALS = 6, GA_COUNT_CONSTRAINT_EVALS = 7, &
       GA_COUNT_JACOBIAN_EVALS = 8, GA_COUNT_STIFFNESS_EVALS = 9, &
       GA_COUNT_DAMPING_EVALS = 10, GA_COUNT_ACCEL_EVALS = 11, GA_COUNT_REJECTED_STEPS = 12, &
       GA_COUNT_CONSTRAINT_DT_EVALS = 13, GA_COUNT_EVENT_EVALS = 14, &
       GA_COUNT_RATE_EVALS = 15, GA_COUNT_COUPLING_EVALS = 16
  integer(c_int), parameter, public :: GA_INFO_RCOND = 0, GA_INFO_NEWTON_ITERS = 1, &
       GA_INFO_NEWTON_RATIO = 2, GA_INFO_ERROR_ESTIMATE = 3, GA_INFO_H_NEXT = 4, &
       GA_INFO_VELOCITY_RESIDUAL = 5

  ! ---- callback interfaces ----------------------------------------------------------------
  abstract interface
     integer(c_int) function ga_mass_fn(t, q, M, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       real(c_double), intent(out) :: M(*)
       type(c_ptr), value :: user
     end function ga_mass_fn
     integer(c_int) function ga_force_fn(t, q, v, f, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*)
       real(c_double), intent(out) :: f(*)
       type(c_ptr), value :: user
     end function ga_force_fn
     integer(c_int) function ga_constraint_fn(t, q, phi, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       real(c_double), intent(out) :: phi(*)
       type(c_ptr), value :: user
     end function ga_constraint_fn
     integer(c_int) function ga_stiffness_fn(t, q, v, qdd, lambda, K, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), qdd(*), lambda(*)
       real(c_double), intent(out) :: K(*)
       type(c_ptr), value :: user
     end function ga_stiffness_fn
     ! lambda is NULL unless the events were set with multipliers: not to be touched then
     integer(c_int) function ga_event_fn(t, q, v, lambda, g, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), lambda(*)
       real(c_double), intent(out) :: g(*)
       type(c_ptr), value :: user
     end function ga_event_fn
     ! first-order states: forces f(t, q, v, y) (n) and rates y' = g(t, q, v, y) (r)
     integer(c_int) function ga_force_y_fn(t, q, v, y, f, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), y(*)
       real(c_double), intent(out) :: f(*)
       type(c_ptr), value :: user
     end function ga_force_y_fn
     ! the coupling blocks, column-major: g_q, g_v (r x n), g_y (r x r), f_y (n x r)
     integer(c_int) function ga_coupling_fn(t, q, v, y, g_q, g_v, g_y, f_y, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), y(*)
       real(c_double), intent(out) :: g_q(*), g_v(*), g_y(*), f_y(*)
       type(c_ptr), value :: user
     end function ga_coupling_fn
     ! events on the first-order states too (ga_set_events_y); lambda as for ga_event_fn
     integer(c_int) function ga_event_y_fn(t, q, v, y, lambda, g, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), y(*), lambda(*)
       real(c_double), intent(out) :: g(*)
       type(c_ptr), value :: user
     end function ga_event_y_fn
     ! sensitivities: df/dp_j (n) and (dM/dp_j) a (n), j 0-based as in C
     integer(c_int) function ga_force_p_fn(t, q, v, j, f_p, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*)
       integer(c_int), value :: j
       real(c_double), intent(out) :: f_p(*)
       type(c_ptr), value :: user
     end function ga_force_p_fn
     integer(c_int) function ga_mass_p_fn(t, q, j, a, out, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), a(*)
       integer(c_int), value :: j
       real(c_double), intent(out) :: out(*)
       type(c_ptr), value :: user
     end function ga_mass_p_fn
     ! dPhi/dp_j (m), dPhi_q/dp_j (the Jacobian's layout) and, where phi_tp is not
     ! c_null_ptr (stabilized index 2), dPhi_t/dp_j there (m; c_f_pointer)
     integer(c_int) function ga_constraint_p_fn(t, q, j, phi_p, jac_p, phi_tp, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: j
       real(c_double), intent(out) :: phi_p(*), jac_p(*)
       type(c_ptr), value :: phi_tp, user
     end function ga_constraint_p_fn
     ! a cost term of ga_adjoint_gradient: its value and every partial derivative
     integer(c_int) function ga_cost_fn(t, q, v, qdd, lambda, value, d_q, d_v, d_qdd, &
          d_lambda, d_p, user) bind(C)
       import :: c_int, c_double, c_ptr
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), qdd(*), lambda(*)
       real(c_double), intent(out) :: value, d_q(*), d_v(*), d_qdd(*), d_lambda(*), d_p(*)
       type(c_ptr), value :: user
     end function ga_cost_fn
     ! the step hook: after each accepted step; lambda is NULL unless asked for (not to be
     ! touched then); s is the solver's handle, for reads; nonzero stops (GA_STOPPED)
     integer(c_int) function ga_step_hook_fn(s, t, q, v, lambda, user) bind(C)
       import :: c_int, c_double, c_ptr
       type(c_ptr), value :: s
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*), lambda(*)
       type(c_ptr), value :: user
     end function ga_step_hook_fn
  end interface
  public :: ga_mass_fn, ga_force_fn, ga_constraint_fn, ga_stiffness_fn, ga_event_fn, &
       ga_force_y_fn, ga_coupling_fn, ga_event_y_fn, ga_force_p_fn, ga_mass_p_fn, ga_cost_fn, &
       ga_constraint_p_fn, ga_step_hook_fn

  ! ---- the C API, one to one ----------------------------------------------------------------
  interface
     type(c_ptr) function ga_version() bind(C, name="ga_version")
       import :: c_ptr
     end function ga_version
     integer(c_int) function ga_version_number() bind(C, name="ga_version_number")
       import :: c_int
     end function ga_version_number
     type(c_ptr) function ga_strerror(status) bind(C, name="ga_strerror")
       import :: c_ptr, c_int
       integer(c_int), value :: status
     end function ga_strerror
     type(c_ptr) function ga_last_error(s) bind(C, name="ga_last_error")
       import :: c_ptr
       type(c_ptr), value :: s
     end function ga_last_error
     integer(c_int) function ga_create(n, m, out) bind(C, name="ga_create")
       import :: c_int, c_ptr
       integer(c_int), value :: n, m
       type(c_ptr), intent(out) :: out
     end function ga_create
     integer(c_int) function ga_create_space(count, kinds, counts, m, out) &
          bind(C, name="ga_create_space")
       import :: c_int, c_ptr
       integer(c_int), value :: count, m
       integer(c_int), intent(in) :: kinds(*), counts(*)
       type(c_ptr), intent(out) :: out
     end function ga_create_space
     integer(c_int) function ga_get_space_size(s, nq, nv) bind(C, name="ga_get_space_size")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), intent(out) :: nq, nv
     end function ga_get_space_size
     subroutine ga_free(s) bind(C, name="ga_free")
       import :: c_ptr
       type(c_ptr), value :: s
     end subroutine ga_free
     integer(c_int) function ga_get_size(s, n, m) bind(C, name="ga_get_size")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), intent(out) :: n, m
     end function ga_get_size
     integer(c_int) function ga_set_callbacks(s, mass, force, constraint, jacobian, user) &
          bind(C, name="ga_set_callbacks")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: mass, force, constraint, jacobian
       type(c_ptr), value :: user
     end function ga_set_callbacks
     integer(c_int) function ga_set_tangents(s, stiffness, damping) &
          bind(C, name="ga_set_tangents")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: stiffness, damping
     end function ga_set_tangents
     integer(c_int) function ga_set_tangent_mode(s, mode) bind(C, name="ga_set_tangent_mode")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: mode
     end function ga_set_tangent_mode
     integer(c_int) function ga_set_constraint_accel(s, fn) &
          bind(C, name="ga_set_constraint_accel")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: fn
     end function ga_set_constraint_accel
     integer(c_int) function ga_set_constraint_dt(s, fn) bind(C, name="ga_set_constraint_dt")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: fn
     end function ga_set_constraint_dt
     integer(c_int) function ga_set_rho_inf(s, rho_inf) bind(C, name="ga_set_rho_inf")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: rho_inf
     end function ga_set_rho_inf
     integer(c_int) function ga_set_params(s, alpha_m, alpha_f, beta, gamma) &
          bind(C, name="ga_set_params")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: alpha_m, alpha_f, beta, gamma
     end function ga_set_params
     integer(c_int) function ga_get_params(s, alpha_m, alpha_f, beta, gamma) &
          bind(C, name="ga_get_params")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: alpha_m, alpha_f, beta, gamma
     end function ga_get_params
     integer(c_int) function ga_set_newton(s, tol, max_iter) bind(C, name="ga_set_newton")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: tol
       integer(c_int), value :: max_iter
     end function ga_set_newton
     integer(c_int) function ga_set_scaling(s, on) bind(C, name="ga_set_scaling")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: on
     end function ga_set_scaling
     integer(c_int) function ga_set_predictor(s, predictor) bind(C, name="ga_set_predictor")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: predictor
     end function ga_set_predictor
     integer(c_int) function ga_set_init_mode(s, mode, init_tol) &
          bind(C, name="ga_set_init_mode")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: mode
       real(c_double), value :: init_tol
     end function ga_set_init_mode
     integer(c_int) function ga_init(s, t0, q0, v0) bind(C, name="ga_init")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t0
       real(c_double), intent(in) :: q0(*), v0(*)
     end function ga_init
     integer(c_int) function ga_step(s, h) bind(C, name="ga_step")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: h
     end function ga_step
     integer(c_int) function ga_get_t(s, t) bind(C, name="ga_get_t")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: t
     end function ga_get_t
     integer(c_int) function ga_get_h_last(s, h) bind(C, name="ga_get_h_last")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: h
     end function ga_get_h_last
     integer(c_int) function ga_get_q(s, x) bind(C, name="ga_get_q")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: x(*)
     end function ga_get_q
     integer(c_int) function ga_get_v(s, x) bind(C, name="ga_get_v")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: x(*)
     end function ga_get_v
     integer(c_int) function ga_get_qdd(s, x) bind(C, name="ga_get_qdd")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: x(*)
     end function ga_get_qdd
     integer(c_int) function ga_get_lambda(s, x) bind(C, name="ga_get_lambda")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: x(*)
     end function ga_get_lambda
     integer(c_int) function ga_get_a(s, x) bind(C, name="ga_get_a")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out) :: x(*)
     end function ga_get_a
     integer(c_int) function ga_state_size(s, len) bind(C, name="ga_state_size")
       import :: c_int, c_ptr, c_size_t
       type(c_ptr), value :: s
       integer(c_size_t), intent(out) :: len
     end function ga_state_size
     integer(c_int) function ga_get_state(s, buf, len) bind(C, name="ga_get_state")
       import :: c_int, c_ptr, c_double, c_size_t
       type(c_ptr), value :: s
       real(c_double), intent(out) :: buf(*)
       integer(c_size_t), value :: len
     end function ga_get_state
     integer(c_int) function ga_set_state(s, buf, len) bind(C, name="ga_set_state")
       import :: c_int, c_ptr, c_double, c_size_t
       type(c_ptr), value :: s
       real(c_double), intent(in) :: buf(*)
       integer(c_size_t), value :: len
     end function ga_set_state
     integer(c_int) function ga_get_counter(s, key, value) bind(C, name="ga_get_counter")
       import :: c_int, c_ptr, c_long_long
       type(c_ptr), value :: s
       integer(c_int), value :: key
       integer(c_long_long), intent(out) :: value
     end function ga_get_counter
     integer(c_int) function ga_reset_counters(s) bind(C, name="ga_reset_counters")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
     end function ga_reset_counters
     integer(c_int) function ga_get_info(s, key, value) bind(C, name="ga_get_info")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: key
       real(c_double), intent(out) :: value
     end function ga_get_info
     integer(c_int) function ga_set_jacobian_reuse(s, mode) bind(C, name="ga_set_jacobian_reuse")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: mode
     end function ga_set_jacobian_reuse
     integer(c_int) function ga_set_constant_mass(s, on) bind(C, name="ga_set_constant_mass")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: on
     end function ga_set_constant_mass
     integer(c_int) function ga_set_pattern(s, which, nnz, rows, cols) &
          bind(C, name="ga_set_pattern")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: which, nnz
       integer(c_int), intent(in) :: rows(*), cols(*)  ! 0-based, as in C
     end function ga_set_pattern
     integer(c_int) function ga_set_pattern_csc(s, which, colptr, rowind) &
          bind(C, name="ga_set_pattern_csc")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: which
       integer(c_int), intent(in) :: colptr(*), rowind(*)  ! 0-based, as in C
     end function ga_set_pattern_csc
     integer(c_int) function ga_set_linear_solver(s, solver) bind(C, name="ga_set_linear_solver")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: solver
     end function ga_set_linear_solver
     type(c_ptr) function ga_linear_solver_name(s) bind(C, name="ga_linear_solver_name")
       import :: c_ptr
       type(c_ptr), value :: s
     end function ga_linear_solver_name
     integer(c_int) function ga_set_formulation(s, formulation) &
          bind(C, name="ga_set_formulation")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: formulation
     end function ga_set_formulation
     integer(c_int) function ga_set_resolution_check(s, limit) &
          bind(C, name="ga_set_resolution_check")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: limit
     end function ga_set_resolution_check
     integer(c_int) function ga_check_derivatives(s, t, q, v, qdd, lambda, y, tol, worst) &
          bind(C, name="ga_check_derivatives")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, qdd, lambda, y
       real(c_double), value :: t, tol
       real(c_double), intent(in) :: q(*), v(*)
       real(c_double), intent(out) :: worst
     end function ga_check_derivatives
     ! operating points: lambda, shapes and the linearization's matrices may be c_null_ptr
     integer(c_int) function ga_static_equilibrium(s, t, q, lambda, tol, max_iter) &
          bind(C, name="ga_static_equilibrium")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, lambda
       real(c_double), value :: t, tol
       real(c_double), intent(inout) :: q(*)
       integer(c_int), value :: max_iter
     end function ga_static_equilibrium
     integer(c_int) function ga_static_equilibrium_y(s, t, q, y, lambda, tol, max_iter) &
          bind(C, name="ga_static_equilibrium_y")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, y, lambda
       real(c_double), value :: t, tol
       real(c_double), intent(inout) :: q(*)
       integer(c_int), value :: max_iter
     end function ga_static_equilibrium_y
     integer(c_int) function ga_state_space(s, t, q, y, lambda, max_dim, dim, n_basis, a) &
          bind(C, name="ga_state_space")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, y, lambda, n_basis, a
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: max_dim
       integer(c_int), intent(out) :: dim
     end function ga_state_space
     integer(c_int) function ga_state_space_motion(s, t, q, v, y, max_dim, dim, n_basis, a) &
          bind(C, name="ga_state_space_motion")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, y, n_basis, a
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*), v(*)
       integer(c_int), value :: max_dim
       integer(c_int), intent(out) :: dim
     end function ga_state_space_motion
     integer(c_int) function ga_linearize(s, t, q, lambda, max_dof, dof, n_basis, m_red, &
          c_red, k_red) bind(C, name="ga_linearize")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, lambda, n_basis, m_red, c_red, k_red
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: max_dof
       integer(c_int), intent(out) :: dof
     end function ga_linearize
     integer(c_int) function ga_modes(s, t, q, lambda, count, omega2, shapes) &
          bind(C, name="ga_modes")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, lambda, shapes
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: count
       real(c_double), intent(out) :: omega2(*)
     end function ga_modes
     integer(c_int) function ga_modes_near(s, t, q, lambda, sigma, count, omega2, shapes) &
          bind(C, name="ga_modes_near")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, lambda, shapes
       real(c_double), value :: t, sigma
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: count
       real(c_double), intent(out) :: omega2(*)
     end function ga_modes_near
     integer(c_int) function ga_modes_damped(s, t, q, lambda, count, re, im, shapes_re, &
          shapes_im) bind(C, name="ga_modes_damped")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s, lambda, shapes_re, shapes_im
       real(c_double), value :: t
       real(c_double), intent(in) :: q(*)
       integer(c_int), value :: count
       real(c_double), intent(out) :: re(*), im(*)
     end function ga_modes_damped
     integer(c_int) function ga_static_path(s, t, load, q, lambda, ds, max_points, tol, fn, &
          user) bind(C, name="ga_static_path")
       import :: c_int, c_ptr, c_double, c_funptr
       type(c_ptr), value :: s, load, lambda, user
       real(c_double), value :: t, ds, tol
       real(c_double), intent(inout) :: q(*)
       integer(c_int), value :: max_points
       type(c_funptr), value :: fn
     end function ga_static_path
     integer(c_int) function ga_set_redundant_constraints(s, mode) &
          bind(C, name="ga_set_redundant_constraints")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: mode
     end function ga_set_redundant_constraints
     integer(c_int) function ga_get_active_constraints(s, active) &
          bind(C, name="ga_get_active_constraints")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), intent(out) :: active(*)
     end function ga_get_active_constraints
     integer(c_int) function ga_set_rescale(s, on) bind(C, name="ga_set_rescale")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: on
     end function ga_set_rescale
     integer(c_int) function ga_set_corrected_start(s, on) bind(C, name="ga_set_corrected_start")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: on
     end function ga_set_corrected_start
     integer(c_int) function ga_set_tolerances(s, rtol, atol) bind(C, name="ga_set_tolerances")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: rtol, atol
     end function ga_set_tolerances
     integer(c_int) function ga_set_tolerances_vector(s, rtol, atol) &
          bind(C, name="ga_set_tolerances_vector")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: rtol
       real(c_double), intent(in) :: atol(*)
     end function ga_set_tolerances_vector
     integer(c_int) function ga_set_step_limits(s, h_min, h_max) &
          bind(C, name="ga_set_step_limits")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: h_min, h_max
     end function ga_set_step_limits
     integer(c_int) function ga_set_initial_step(s, h0) bind(C, name="ga_set_initial_step")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: h0
     end function ga_set_initial_step
     integer(c_int) function ga_step_adaptive(s, t_stop) bind(C, name="ga_step_adaptive")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t_stop
     end function ga_step_adaptive
     integer(c_int) function ga_advance(s, t_out) bind(C, name="ga_advance")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t_out
     end function ga_advance
     integer(c_int) function ga_interpolate(s, t, q, v, lambda) bind(C, name="ga_interpolate")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t
       real(c_double), intent(out), optional :: q(*), v(*), lambda(*)  ! absent: NULL
     end function ga_interpolate
     integer(c_int) function ga_interpolate_qdd(s, t, qdd) bind(C, name="ga_interpolate_qdd")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t
       real(c_double), intent(out) :: qdd(*)
     end function ga_interpolate_qdd
     integer(c_int) function ga_set_output(s, mode) bind(C, name="ga_set_output")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: mode
     end function ga_set_output
     integer(c_int) function ga_set_events(s, count, fn, direction, terminal, with_multipliers) &
          bind(C, name="ga_set_events")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       integer(c_int), value :: count
       type(c_funptr), value :: fn
       integer(c_int), intent(in), optional :: direction(*), terminal(*)  ! absent: NULL
       integer(c_int), value :: with_multipliers
     end function ga_set_events
     integer(c_int) function ga_set_step_hook(s, fn, user, with_multipliers) &
          bind(C, name="ga_set_step_hook")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: fn
       type(c_ptr), value :: user
       integer(c_int), value :: with_multipliers
     end function ga_set_step_hook
     integer(c_int) function ga_get_event_count(s, count) bind(C, name="ga_get_event_count")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), intent(out) :: count
     end function ga_get_event_count
     integer(c_int) function ga_get_event(s, i, t, index, direction) &
          bind(C, name="ga_get_event")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: i
       real(c_double), intent(out), optional :: t  ! absent: NULL
       integer(c_int), intent(out), optional :: index, direction
     end function ga_get_event
     integer(c_int) function ga_set_first_order(s, r, force, rate) &
          bind(C, name="ga_set_first_order")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       integer(c_int), value :: r
       type(c_funptr), value :: force, rate
     end function ga_set_first_order
     integer(c_int) function ga_set_coupling(s, fn) bind(C, name="ga_set_coupling")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: fn
     end function ga_set_coupling
     integer(c_int) function ga_set_coupling_pattern(s, which, nnz, rows, cols) &
          bind(C, name="ga_set_coupling_pattern")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: which, nnz
       integer(c_int), intent(in) :: rows(*), cols(*)
     end function ga_set_coupling_pattern
     integer(c_int) function ga_set_coupling_exact(s, exact) &
          bind(C, name="ga_set_coupling_exact")
       import :: c_int, c_ptr
       type(c_ptr), value :: s
       integer(c_int), value :: exact
     end function ga_set_coupling_exact
     integer(c_int) function ga_init_y(s, t0, q0, v0, y0) bind(C, name="ga_init_y")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t0
       real(c_double), intent(in) :: q0(*), v0(*), y0(*)
     end function ga_init_y
     integer(c_int) function ga_get_y(s, y, ydot) bind(C, name="ga_get_y")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), intent(out), optional :: y(*), ydot(*)  ! absent: NULL
     end function ga_get_y
     integer(c_int) function ga_set_events_y(s, count, fn, direction, terminal, &
          with_multipliers) bind(C, name="ga_set_events_y")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       integer(c_int), value :: count
       type(c_funptr), value :: fn
       integer(c_int), intent(in), optional :: direction(*), terminal(*)  ! absent: NULL
       integer(c_int), value :: with_multipliers
     end function ga_set_events_y
     integer(c_int) function ga_interpolate_y(s, t, y, ydot) bind(C, name="ga_interpolate_y")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       real(c_double), value :: t
       real(c_double), intent(out), optional :: y(*), ydot(*)  ! absent: NULL
     end function ga_interpolate_y
     integer(c_int) function ga_set_sensitivity(s, np, p, p_scale, depends) &
          bind(C, name="ga_set_sensitivity")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: np
       type(c_ptr), value :: p  ! the array the callbacks read: perturbed in place
       real(c_double), intent(in), optional :: p_scale(*)  ! absent: NULL
       integer(c_int), value :: depends
     end function ga_set_sensitivity
     integer(c_int) function ga_set_parameter_derivatives(s, force_p, mass_p) &
          bind(C, name="ga_set_parameter_derivatives")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: force_p, mass_p
     end function ga_set_parameter_derivatives
     integer(c_int) function ga_set_constraint_parameter_derivative(s, fn) &
          bind(C, name="ga_set_constraint_parameter_derivative")
       import :: c_int, c_ptr, c_funptr
       type(c_ptr), value :: s
       type(c_funptr), value :: fn
     end function ga_set_constraint_parameter_derivative
     integer(c_int) function ga_get_sensitivity_y(s, j, dy, dydot) &
          bind(C, name="ga_get_sensitivity_y")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: j
       real(c_double), intent(out), optional :: dy(*), dydot(*)  ! absent: NULL
     end function ga_get_sensitivity_y
     integer(c_int) function ga_set_sensitivity_start(s, j, dq0, dv0) &
          bind(C, name="ga_set_sensitivity_start")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: j
       real(c_double), intent(in), optional :: dq0(*), dv0(*)  ! absent: NULL
     end function ga_set_sensitivity_start
     integer(c_int) function ga_get_sensitivity(s, j, dq, dv, dqdd, dlambda) &
          bind(C, name="ga_get_sensitivity")
       import :: c_int, c_ptr, c_double
       type(c_ptr), value :: s
       integer(c_int), value :: j
       real(c_double), intent(out), optional :: dq(*), dv(*), dqdd(*), dlambda(*)
     end function ga_get_sensitivity
     integer(c_int) function ga_set_sensitivity_method(s, methods, max_steps) &
          bind(C, name="ga_set_sensitivity_method")
       import :: c_int, c_ptr, c_long
       type(c_ptr), value :: s
       integer(c_int), value :: methods
       integer(c_long), value :: max_steps
     end function ga_set_sensitivity_method
     integer(c_int) function ga_set_adjoint_checkpoints(s, interval, count) &
          bind(C, name="ga_set_adjoint_checkpoints")
       import :: c_int, c_ptr, c_long
       type(c_ptr), value :: s
       integer(c_long), value :: interval, count
     end function ga_set_adjoint_checkpoints
     integer(c_int) function ga_adjoint_gradient(s, running, terminal, J, dJ_dp) &
          bind(C, name="ga_adjoint_gradient")
       import :: c_int, c_ptr, c_funptr, c_double
       type(c_ptr), value :: s
       type(c_funptr), value :: running, terminal
       real(c_double), intent(out) :: J, dJ_dp(*)
     end function ga_adjoint_gradient
     ! SO(3) as unit quaternions (w, x, y, z); matrices column-major, as Fortran stores them
     integer(c_int) function ga_so3_exp(count, psi, q) bind(C, name="ga_so3_exp")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: psi(*)
       real(c_double), intent(out) :: q(*)
     end function ga_so3_exp
     integer(c_int) function ga_so3_log(count, q, psi) bind(C, name="ga_so3_log")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: q(*)
       real(c_double), intent(out) :: psi(*)
     end function ga_so3_log
     integer(c_int) function ga_so3_compose(count, a, b, ab) bind(C, name="ga_so3_compose")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: a(*), b(*)
       real(c_double), intent(out) :: ab(*)
     end function ga_so3_compose
     integer(c_int) function ga_so3_matrix(count, q, R) bind(C, name="ga_so3_matrix")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: q(*)
       real(c_double), intent(out) :: R(*)
     end function ga_so3_matrix
     integer(c_int) function ga_so3_tangent(count, psi, T) bind(C, name="ga_so3_tangent")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: psi(*)
       real(c_double), intent(out) :: T(*)
     end function ga_so3_tangent
     integer(c_int) function ga_so3_tangent_inverse(count, psi, T) &
          bind(C, name="ga_so3_tangent_inverse")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: psi(*)
       real(c_double), intent(out) :: T(*)
     end function ga_so3_tangent_inverse
     ! SE(3) as poses (x, quaternion): twists (u, w) 6, poses 7, matrices 6 x 6 column-major
     integer(c_int) function ga_se3_exp(count, xi, p) bind(C, name="ga_se3_exp")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: xi(*)
       real(c_double), intent(out) :: p(*)
     end function ga_se3_exp
     integer(c_int) function ga_se3_log(count, p, xi) bind(C, name="ga_se3_log")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: p(*)
       real(c_double), intent(out) :: xi(*)
     end function ga_se3_log
     integer(c_int) function ga_se3_compose(count, a, b, ab) bind(C, name="ga_se3_compose")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: a(*), b(*)
       real(c_double), intent(out) :: ab(*)
     end function ga_se3_compose
     integer(c_int) function ga_se3_tangent(count, xi, T) bind(C, name="ga_se3_tangent")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: xi(*)
       real(c_double), intent(out) :: T(*)
     end function ga_se3_tangent
     integer(c_int) function ga_se3_tangent_inverse(count, xi, T) &
          bind(C, name="ga_se3_tangent_inverse")
       import :: c_int, c_long, c_double
       integer(c_long), value :: count
       real(c_double), intent(in) :: xi(*)
       real(c_double), intent(out) :: T(*)
     end function ga_se3_tangent_inverse
     function c_strlen(p) bind(C, name="strlen")
       import :: c_ptr, c_size_t
       type(c_ptr), value :: p
       integer(c_size_t) :: c_strlen
     end function c_strlen
  end interface
  public :: ga_version, ga_version_number, ga_strerror, ga_last_error, ga_create, ga_free, &
       ga_create_space, ga_get_space_size, &
       ga_get_size, ga_set_callbacks, ga_set_tangents, ga_set_tangent_mode, &
       ga_set_constraint_accel, ga_set_constraint_dt, ga_set_rho_inf, ga_set_params, &
       ga_get_params, ga_set_newton, &
       ga_set_scaling, ga_set_predictor, ga_set_init_mode, ga_init, ga_step, ga_get_t, &
       ga_get_h_last, ga_get_q, ga_get_v, ga_get_qdd, ga_get_lambda, ga_get_a, &
       ga_state_size, ga_get_state, ga_set_state, ga_get_counter, ga_reset_counters, ga_get_info, &
       ga_set_jacobian_reuse, ga_set_constant_mass, ga_set_pattern, ga_set_pattern_csc, &
       ga_set_linear_solver, &
       ga_linear_solver_name, ga_set_formulation, ga_set_resolution_check, &
       ga_check_derivatives, ga_static_equilibrium, ga_linearize, ga_modes, ga_static_path, &
       ga_modes_damped, ga_modes_near, ga_static_equilibrium_y, ga_state_space, &
       ga_state_space_motion, &
       ga_set_redundant_constraints, &
       ga_get_active_constraints, ga_set_rescale, ga_set_corrected_start, &
       ga_set_tolerances, ga_set_tolerances_vector, ga_set_step_limits, ga_set_initial_step, ga_step_adaptive, ga_advance, &
       ga_interpolate, ga_interpolate_qdd, ga_set_output, ga_set_events, ga_get_event_count, &
       ga_get_event, ga_set_first_order, ga_set_coupling, ga_set_coupling_exact, ga_init_y, &
       ga_get_y, ga_interpolate_y, ga_set_events_y, ga_set_coupling_pattern, &
       ga_set_sensitivity, ga_set_parameter_derivatives, ga_get_sensitivity, &
       ga_set_constraint_parameter_derivative, &
       ga_set_sensitivity_start, ga_get_sensitivity_y, &
       ga_set_sensitivity_method, ga_adjoint_gradient, ga_set_adjoint_checkpoints, &
       ga_set_step_hook, ga_so3_exp, ga_so3_log, ga_so3_compose, ga_so3_matrix, ga_so3_tangent, &
       ga_so3_tangent_inverse, ga_se3_exp, ga_se3_log, ga_se3_compose, ga_se3_tangent, &
       ga_se3_tangent_inverse

  ! ---- the Fortran layer --------------------------------------------------------------------
  type, public :: galpha_solver
     type(c_ptr) :: handle = c_null_ptr
     integer :: n = 0, m = 0, r = 0, np = 0
     integer :: nq = 0  !< q's length: n, or the storage of ga_create_space's blocks
   contains
     procedure :: create => solver_create
     !> create_space(kinds, counts, m): a product of blocks (ga_create_space); n = nv
     procedure :: create_space => solver_create_space
     procedure :: free => solver_free
     procedure, private :: solver_set_callbacks, solver_set_callbacks_funptr
     !> set_callbacks(mass, force, constraint, jacobian, user): either Fortran procedures with
     !> exactly the interfaces ga_mass_fn, ... (arrays as assumed-size (*)), or c_funloc() of
     !> any bind(C) procedures -- the latter lets the model use explicit-shape arrays such as
     !> M(n, n) and J(m, n).
     generic :: set_callbacks => solver_set_callbacks, solver_set_callbacks_funptr
     procedure :: set_tangents => solver_set_tangents
     procedure :: set_constraint_accel => solver_set_constraint_accel
     procedure :: set_constraint_dt => solver_set_constraint_dt
     procedure :: set_rho_inf => solver_set_rho_inf
     procedure :: set_newton => solver_set_newton
     procedure :: init => solver_init
     procedure :: step => solver_step
     procedure :: set_tolerances => solver_set_tolerances
     procedure :: set_tolerances_vector => solver_set_tolerances_vector
     procedure :: set_formulation => solver_set_formulation
     !> set_resolution_check(limit): index 3's velocity-constraint limit (ga_set_resolution_check)
     procedure :: set_resolution_check => solver_set_resolution_check
     !> check_derivatives(t, q, v, worst [, qdd, lambda, y, tol]): the derivative callbacks
     !> against central differences (ga_check_derivatives; tol 1e-6 unless given)
     procedure :: check_derivatives => solver_check_derivatives
     !> static_equilibrium(t, q [, lambda, tol, max_iter]): q (in: the start) becomes the
     !> static equilibrium, lambda its multipliers (ga_static_equilibrium; tol 1e-10, max_iter
     !> 50 unless given)
     procedure :: static_equilibrium => solver_static_equilibrium
     !> static_equilibrium_y(t, q, y [, lambda, tol, max_iter]): the same with the
     !> first-order states y as unknowns too (ga_static_equilibrium_y)
     procedure :: static_equilibrium_y => solver_static_equilibrium_y
     !> state_space(t, q, dim [, y, lambda, basis, a]): the first-order form x' = A x of the
     !> small motions at rest, x = (z, z', y), a(dim, dim), basis(n, dof) (ga_state_space);
     !> without them only dim (call first to size them)
     procedure :: state_space => solver_state_space
     !> state_space_motion(t, q, v, dim [, y, basis, a]): the same about a moving state on
     !> the constraints, x = (z, w, y) (ga_state_space_motion)
     procedure :: state_space_motion => solver_state_space_motion
     !> modes(t, q, omega2 [, lambda, shapes]): the size(omega2) lowest undamped modes at an
     !> equilibrium, shapes(n, size(omega2)) with unit modal mass (ga_modes)
     procedure :: modes => solver_modes
     !> modes_near(t, q, sigma, omega2 [, lambda, shapes]): the size(omega2) undamped modes
     !> whose omega^2 lie nearest sigma, by shift-invert Lanczos on the solver's (sparse)
     !> factorization (ga_modes_near)
     procedure :: modes_near => solver_modes_near
     !> linearize(t, q, dof [, basis, mass, damping, stiffness, lambda]): the small motions at
     !> rest in dof minimal coordinates (ga_linearize): basis(n, dof), the others (dof, dof);
     !> without them only dof (call first to size them)
     procedure :: linearize => solver_linearize
     !> modes_damped(t, q, re, im [, lambda, shapes_re, shapes_im]): the size(re) modes of the
     !> damped system at an equilibrium, s = re + i im by |s| (ga_modes_damped)
     procedure :: modes_damped => solver_modes_damped
     !> static_path(t, load, q, ds, max_points [, lambda, tol, fn, user]): the equilibrium
     !> path in the load factor `load` (a target the callbacks read) through limit points
     !> (ga_static_path); fn: c_funloc of a bind(C) function (load, q, lambda, user)
     procedure :: static_path => solver_static_path
     !> set_pattern(which, rows, cols): the sparsity of GA_MATRIX_MASS, _JACOBIAN, _STIFFNESS or
     !> _DAMPING with Fortran (1-based) row and column numbers; the callback of that matrix then
     !> fills size(rows) values in this order (GA_ERR_ARG, without a message, if rows and cols
     !> differ in size)
     procedure :: set_pattern => solver_set_pattern
     !> set_pattern_csc(which, colptr, rowind): the same in compressed-column form with Fortran
     !> (1-based) numbers, colptr(1) = 1 and size(colptr) = n + 1 (the Harwell-Boeing layout);
     !> the callback fills the values column by column (GA_ERR_ARG, without a message, if
     !> size(colptr) /= n + 1 or rowind is shorter than colptr(n + 1) - 1)
     procedure :: set_pattern_csc => solver_set_pattern_csc
     procedure :: set_constant_mass => solver_set_constant_mass
     procedure :: set_linear_solver => solver_set_linear_solver
     procedure :: linear_solver_name => solver_linear_solver_name
     procedure :: set_redundant_constraints => solver_set_redundant_constraints
     procedure :: get_active_constraints => solver_get_active_constraints
     procedure :: advance => solver_advance
     !> set_output(GA_OUTPUT_CONSISTENT or GA_OUTPUT_STEP): what get_qdd, get_lambda give
     procedure :: set_output => solver_set_output
     !> interpolate(t, q, v, lambda) and interpolate_qdd(t, qdd) inside the last step
     procedure :: interpolate => solver_interpolate
     procedure :: interpolate_qdd => solver_interpolate_qdd
     procedure :: t => solver_t
     procedure :: get_q => solver_get_q
     procedure :: get_v => solver_get_v
     procedure :: get_qdd => solver_get_qdd
     procedure :: get_lambda => solver_get_lambda
     procedure :: counter => solver_counter
     procedure :: message => solver_message
     !> get_size(n, m): the sizes the C solver was created with
     procedure :: get_size => solver_get_size
     procedure :: set_params => solver_set_params
     procedure :: get_params => solver_get_params
     procedure :: set_tangent_mode => solver_set_tangent_mode
     procedure :: set_scaling => solver_set_scaling
     procedure :: set_jacobian_reuse => solver_set_jacobian_reuse
     procedure :: set_predictor => solver_set_predictor
     procedure :: set_rescale => solver_set_rescale
     procedure :: set_corrected_start => solver_set_corrected_start
     procedure :: set_init_mode => solver_set_init_mode
     procedure :: set_step_limits => solver_set_step_limits
     procedure :: set_initial_step => solver_set_initial_step
     procedure :: step_adaptive => solver_step_adaptive
     procedure :: get_a => solver_get_a
     !> h_last(): the last step of Algorithm 1 (NaN if the call fails)
     procedure :: h_last => solver_h_last
     !> state_size(): doubles in a checkpoint (-1 if the call fails); get_state(buf) and
     !> set_state(buf) take a buffer of exactly that size
     procedure :: state_size => solver_state_size
     procedure :: get_state => solver_get_state
     procedure :: set_state => solver_set_state
     procedure :: reset_counters => solver_reset_counters
     !> get_info(key, value): GA_INFO_* of the last step
     procedure :: get_info => solver_get_info
     !> set_events(fn, direction, terminal, with_multipliers): size(direction) event functions
     !> (GA_EVENT_BOTH, _RISING or _FALLING each), terminal(k) true: step, step_adaptive and
     !> advance stop there with GA_EVENT; fn fills g(1:size(direction)). set_events(fn,
     !> [integer(c_int) ::]) removes them
     procedure :: set_events => solver_set_events
     !> event_count(): events logged by the last stepping call (-1 if the call fails);
     !> get_event(i, t, index, direction): the i-th (1-based), index 1-based as well
     !> set_step_hook(fn, user, with_multipliers): fn after each accepted step of step,
     !> step_adaptive and advance (nonzero return: they stop there with GA_STOPPED); user
     !> optional (c_null_ptr), with_multipliers optional (.false.: lambda not passed).
     !> clear_step_hook() removes it
     procedure :: set_step_hook => solver_set_step_hook
     procedure :: clear_step_hook => solver_clear_step_hook
     procedure :: event_count => solver_event_count
     procedure :: get_event => solver_get_event
     !> set_first_order(r, rate, force): r first-order states y' = rate(t, q, v, y), force
     !> (optional) replacing the force callback so that it sees y; before the first start
     procedure :: set_first_order => solver_set_first_order
     !> set_coupling(fn): the coupling blocks by a callback; set_coupling_exact(.false.) leaves
     !> g_q, g_v, f_y out of the iteration matrix
     procedure :: set_coupling => solver_set_coupling
     procedure :: set_coupling_exact => solver_set_coupling_exact
     !> set_coupling_pattern(GA_COUPLING_G_Q or _G_V, rows, cols): where that block may be
     !> nonzero, Fortran (1-based) numbers (GA_ERR_ARG, without a message, if the sizes differ)
     procedure :: set_coupling_pattern => solver_set_coupling_pattern
     !> init_y(t0, q0, v0, y0): init with the initial first-order states
     procedure :: init_y => solver_init_y
     !> get_y(y, ydot) and interpolate_y(t, y, ydot): y, y' at the accepted step or inside
     !> the last one (either optional)
     procedure :: get_y => solver_get_y
     procedure :: interpolate_y => solver_interpolate_y
     !> set_events_y(fn, direction, terminal, with_multipliers): set_events with functions
     !> fn(t, q, v, y, lambda, g, user) of the first-order states as well
     procedure :: set_events_y => solver_set_events_y
     !> set_sensitivity(p, depends, p_scale): forward sensitivities with respect to p, the
     !> (target, contiguous) array the callbacks read and galpha perturbs in place; depends an
     !> ior of GA_DEPENDS_FORCE, _MASS, _RATE and _CONSTRAINT; before init
     procedure :: set_sensitivity => solver_set_sensitivity
     !> set_parameter_derivatives(force_p, mass_p): exact df/dp_j, (dM/dp_j) a (either
     !> optional: central differences)
     procedure :: set_parameter_derivatives => solver_set_parameter_derivatives
     !> set_constraint_parameter_derivative(fn): exact dPhi/dp_j, dPhi_q/dp_j, dPhi_t/dp_j
     !> (absent: central differences)
     procedure :: set_constraint_parameter_derivative => &
          solver_set_constraint_parameter_derivative
     !> get_sensitivity(j, dq, dv, dqdd, dlambda): d/dp_j (j 1-based) of the accepted step's
     !> q, v, qdd, lambda (each optional)
     procedure :: get_sensitivity => solver_get_sensitivity
     !> get_sensitivity_y(j, dy, dydot): d/dp_j of the first-order states and their rates
     procedure :: get_sensitivity_y => solver_get_sensitivity_y
     !> set_sensitivity_start(j, dq0, dv0): dq0/dp_j and dv0/dp_j (j 1-based; either optional:
     !> zero) for every later init
     procedure :: set_sensitivity_start => solver_set_sensitivity_start
     !> set_sensitivity_method(methods, max_steps): an ior of GA_SENSITIVITY_FORWARD and
     !> GA_SENSITIVITY_ADJOINT (the run recorded for adjoint_gradient, up to max_steps steps)
     procedure :: set_sensitivity_method => solver_set_sensitivity_method
     !> set_adjoint_checkpoints(interval, count): the record keeps one segment of interval
     !> steps and a checkpoint after every interval-th step (count of them)
     procedure :: set_adjoint_checkpoints => solver_set_adjoint_checkpoints
     !> adjoint_gradient(J, dJ_dp, running, terminal): the cost and its gradient by the
     !> discrete adjoint of the recorded run (running and terminal optional, one needed)
     procedure :: adjoint_gradient => solver_adjoint_gradient
  end type galpha_solver
  public :: galpha_strerror, galpha_version, galpha_version_number
  public :: galpha_so3_exp, galpha_so3_log, galpha_so3_compose, galpha_so3_matrix, &
       galpha_so3_tangent, galpha_so3_tangent_inverse
  public :: galpha_se3_exp, galpha_se3_log, galpha_se3_compose, galpha_se3_tangent, &
       galpha_se3_tangent_inverse

contains

  ! Fortran string from a NUL-terminated C string.
  function c_to_f(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
       s = ""
       return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
       s(i:i) = chars(i)
    end do
  end function c_to_f

  function galpha_strerror(status) result(s)
    integer(c_int), intent(in) :: status
    character(len=:), allocatable :: s
    s = c_to_f(ga_strerror(status))
  end function galpha_strerror

  function galpha_version() result(s)
    character(len=:), allocatable :: s
    s = c_to_f(ga_version())
  end function galpha_version

  integer function galpha_version_number()
    galpha_version_number = int(ga_version_number())
  end function galpha_version_number

  ! The rotation maps over whole arrays: count = size(input) / its item's width (3 for psi,
  ! 4 for a quaternion); the output holds count items (4, 3 or 9 each, matrices column-major).
  ! GA_ERR_ARG also when an array is not whole items or the output too short.

  ! n_in doubles of items w_in wide, into n_out of items w_out wide: count, whole items, room
  logical function whole_items(n_in, w_in, n_out, w_out, count)
    integer, intent(in) :: n_in, w_in, n_out, w_out
    integer(c_long), intent(out) :: count
    count = int(n_in / w_in, c_long)
    whole_items = mod(n_in, w_in) == 0 .and. n_out >= w_out * count
  end function whole_items

  integer(c_int) function galpha_so3_exp(psi, q) result(status)
    real(c_double), intent(in) :: psi(:)
    real(c_double), intent(out) :: q(:)
    integer(c_long) :: count
    if (.not. whole_items(size(psi), 3, size(q), 4, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_exp(count, psi, q)
  end function galpha_so3_exp

  integer(c_int) function galpha_so3_log(q, psi) result(status)
    real(c_double), intent(in) :: q(:)
    real(c_double), intent(out) :: psi(:)
    integer(c_long) :: count
    if (.not. whole_items(size(q), 4, size(psi), 3, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_log(count, q, psi)
  end function galpha_so3_log

  integer(c_int) function galpha_so3_compose(a, b, ab) result(status)
    real(c_double), intent(in) :: a(:)
    real(c_double), intent(in) :: b(:)
    real(c_double), intent(out) :: ab(:)
    integer(c_long) :: count
    if (size(b) /= size(a) .or. .not. whole_items(size(a), 4, size(ab), 4, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_compose(count, a, b, ab)
  end function galpha_so3_compose

  integer(c_int) function galpha_so3_matrix(q, R) result(status)
    real(c_double), intent(in) :: q(:)
    real(c_double), intent(out) :: R(:)
    integer(c_long) :: count
    if (.not. whole_items(size(q), 4, size(R), 9, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_matrix(count, q, R)
  end function galpha_so3_matrix

  integer(c_int) function galpha_so3_tangent(psi, T) result(status)
    real(c_double), intent(in) :: psi(:)
    real(c_double), intent(out) :: T(:)
    integer(c_long) :: count
    if (.not. whole_items(size(psi), 3, size(T), 9, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_tangent(count, psi, T)
  end function galpha_so3_tangent

  integer(c_int) function galpha_so3_tangent_inverse(psi, T) result(status)
    real(c_double), intent(in) :: psi(:)
    real(c_double), intent(out) :: T(:)
    integer(c_long) :: count
    if (.not. whole_items(size(psi), 3, size(T), 9, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_so3_tangent_inverse(count, psi, T)
  end function galpha_so3_tangent_inverse

  ! The pose maps likewise: twists 6 wide, poses 7, tangents 36 (6 x 6 column-major).
  integer(c_int) function galpha_se3_exp(xi, p) result(status)
    real(c_double), intent(in) :: xi(:)
    real(c_double), intent(out) :: p(:)
    integer(c_long) :: count
    if (.not. whole_items(size(xi), 6, size(p), 7, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_se3_exp(count, xi, p)
  end function galpha_se3_exp

  integer(c_int) function galpha_se3_log(p, xi) result(status)
    real(c_double), intent(in) :: p(:)
    real(c_double), intent(out) :: xi(:)
    integer(c_long) :: count
    if (.not. whole_items(size(p), 7, size(xi), 6, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_se3_log(count, p, xi)
  end function galpha_se3_log

  integer(c_int) function galpha_se3_compose(a, b, ab) result(status)
    real(c_double), intent(in) :: a(:)
    real(c_double), intent(in) :: b(:)
    real(c_double), intent(out) :: ab(:)
    integer(c_long) :: count
    if (size(b) /= size(a) .or. .not. whole_items(size(a), 7, size(ab), 7, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_se3_compose(count, a, b, ab)
  end function galpha_se3_compose

  integer(c_int) function galpha_se3_tangent(xi, T) result(status)
    real(c_double), intent(in) :: xi(:)
    real(c_double), intent(out) :: T(:)
    integer(c_long) :: count
    if (.not. whole_items(size(xi), 6, size(T), 36, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_se3_tangent(count, xi, T)
  end function galpha_se3_tangent

  integer(c_int) function galpha_se3_tangent_inverse(xi, T) result(status)
    real(c_double), intent(in) :: xi(:)
    real(c_double), intent(out) :: T(:)
    integer(c_long) :: count
    if (.not. whole_items(size(xi), 6, size(T), 36, count)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_se3_tangent_inverse(count, xi, T)
  end function galpha_se3_tangent_inverse

  integer(c_int) function solver_create(this, n, m) result(status)
    class(galpha_solver), intent(inout) :: this
    integer, intent(in) :: n, m
    status = ga_create(int(n, c_int), int(m, c_int), this%handle)
    if (status == GA_OK) then
       this%n = n
       this%nq = n
       this%m = m
    end if
  end function solver_create

  integer(c_int) function solver_create_space(this, kinds, counts, m) result(status)
    class(galpha_solver), intent(inout) :: this
    integer, intent(in) :: kinds(:), counts(:), m
    integer(c_int) :: nq, nv
    if (size(kinds) /= size(counts)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_create_space(int(size(kinds), c_int), int(kinds, c_int), int(counts, c_int), &
                             int(m, c_int), this%handle)
    if (status /= GA_OK) return
    status = ga_get_space_size(this%handle, nq, nv)
    this%nq = nq
    this%n = nv
    this%m = m
  end function solver_create_space

  subroutine solver_free(this)
    class(galpha_solver), intent(inout) :: this
    call ga_free(this%handle)
    this%handle = c_null_ptr
  end subroutine solver_free

  integer(c_int) function solver_set_callbacks(this, mass, force, constraint, jacobian, user) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_mass_fn) :: mass
    procedure(ga_force_fn), optional :: force
    procedure(ga_constraint_fn), optional :: constraint, jacobian
    type(c_ptr), intent(in), optional :: user
    type(c_funptr) :: f, c, j
    type(c_ptr) :: u
    f = c_null_funptr
    c = c_null_funptr
    j = c_null_funptr
    u = c_null_ptr
    if (present(force)) f = c_funloc(force)
    if (present(constraint)) c = c_funloc(constraint)
    if (present(jacobian)) j = c_funloc(jacobian)
    if (present(user)) u = user
    status = ga_set_callbacks(this%handle, c_funloc(mass), f, c, j, u)
  end function solver_set_callbacks

  integer(c_int) function solver_set_callbacks_funptr(this, mass, force, constraint, jacobian, &
       user) result(status)
    class(galpha_solver), intent(inout) :: this
    type(c_funptr), intent(in) :: mass, force, constraint, jacobian
    type(c_ptr), intent(in), optional :: user
    type(c_ptr) :: u
    u = c_null_ptr
    if (present(user)) u = user
    status = ga_set_callbacks(this%handle, mass, force, constraint, jacobian, u)
  end function solver_set_callbacks_funptr

  integer(c_int) function solver_set_tangents(this, stiffness, damping) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_stiffness_fn), optional :: stiffness
    procedure(ga_force_fn), optional :: damping
    type(c_funptr) :: k, d
    k = c_null_funptr
    d = c_null_funptr
    if (present(stiffness)) k = c_funloc(stiffness)
    if (present(damping)) d = c_funloc(damping)
    status = ga_set_tangents(this%handle, k, d)
  end function solver_set_tangents

  ! The C arrays of set_events and set_events_y: terminal flags (all terminal when absent) and
  ! the multipliers flag; ok false if terminal and direction differ in size.
  subroutine event_flags(direction, terminal, with_multipliers, flags, lam, ok)
    integer(c_int), intent(in) :: direction(:)
    logical, intent(in), optional :: terminal(:), with_multipliers
    integer(c_int), intent(out) :: flags(:), lam
    logical, intent(out) :: ok
    lam = 0
    if (present(with_multipliers)) then
       if (with_multipliers) lam = 1
    end if
    flags = 1
    ok = .true.
    if (present(terminal)) then
       ok = size(terminal) == size(direction)
       if (.not. ok) return
       flags = 0
       where (terminal) flags(1:size(terminal)) = 1
    end if
  end subroutine event_flags

  integer(c_int) function solver_set_events(this, fn, direction, terminal, with_multipliers) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_event_fn) :: fn
    integer(c_int), intent(in) :: direction(:)
    logical, intent(in), optional :: terminal(:), with_multipliers
    integer(c_int) :: flags(max(size(direction), 1)), lam
    logical :: ok
    status = GA_ERR_ARG
    call event_flags(direction, terminal, with_multipliers, flags, lam, ok)
    if (ok) status = ga_set_events(this%handle, size(direction, kind=c_int), c_funloc(fn), &
         direction, flags, lam)
  end function solver_set_events

  integer(c_int) function solver_set_events_y(this, fn, direction, terminal, with_multipliers) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_event_y_fn) :: fn
    integer(c_int), intent(in) :: direction(:)
    logical, intent(in), optional :: terminal(:), with_multipliers
    integer(c_int) :: flags(max(size(direction), 1)), lam
    logical :: ok
    status = GA_ERR_ARG
    call event_flags(direction, terminal, with_multipliers, flags, lam, ok)
    if (ok) status = ga_set_events_y(this%handle, size(direction, kind=c_int), c_funloc(fn), &
         direction, flags, lam)
  end function solver_set_events_y

  integer(c_int) function solver_set_step_hook(this, fn, user, with_multipliers) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_step_hook_fn) :: fn
    type(c_ptr), intent(in), optional :: user
    logical, intent(in), optional :: with_multipliers
    type(c_ptr) :: u
    integer(c_int) :: lam
    u = c_null_ptr
    if (present(user)) u = user
    lam = 0
    if (present(with_multipliers)) then
       if (with_multipliers) lam = 1
    end if
    status = ga_set_step_hook(this%handle, c_funloc(fn), u, lam)
  end function solver_set_step_hook

  integer(c_int) function solver_clear_step_hook(this) result(status)
    class(galpha_solver), intent(inout) :: this
    status = ga_set_step_hook(this%handle, c_null_funptr, c_null_ptr, 0_c_int)
  end function solver_clear_step_hook

  integer(c_int) function solver_event_count(this) result(count)
    class(galpha_solver), intent(in) :: this
    if (ga_get_event_count(this%handle, count) /= GA_OK) count = -1
  end function solver_event_count

  integer(c_int) function solver_get_event(this, i, t, index, direction) result(status)
    class(galpha_solver), intent(in) :: this
    integer(c_int), intent(in) :: i
    real(c_double), intent(out) :: t
    integer(c_int), intent(out) :: index, direction
    status = ga_get_event(this%handle, i - 1, t, index, direction)
    if (status == GA_OK) index = index + 1
  end function solver_get_event

  integer(c_int) function solver_set_first_order(this, r, rate, force) result(status)
    class(galpha_solver), intent(inout) :: this
    integer, intent(in) :: r
    procedure(ga_force_y_fn) :: rate
    procedure(ga_force_y_fn), optional :: force
    type(c_funptr) :: f
    f = c_null_funptr
    if (present(force)) f = c_funloc(force)
    status = ga_set_first_order(this%handle, int(r, c_int), f, c_funloc(rate))
    if (status == GA_OK) this%r = r
  end function solver_set_first_order

  integer(c_int) function solver_set_coupling(this, fn) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_coupling_fn) :: fn
    status = ga_set_coupling(this%handle, c_funloc(fn))
  end function solver_set_coupling

  integer(c_int) function solver_set_coupling_pattern(this, which, rows, cols) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: which, rows(:), cols(:)
    integer(c_int) :: r0(max(size(rows), 1)), c0(max(size(cols), 1))
    if (size(rows) /= size(cols)) then
       status = GA_ERR_ARG
       return
    end if
    r0(1:size(rows)) = rows - 1
    c0(1:size(cols)) = cols - 1
    status = ga_set_coupling_pattern(this%handle, which, size(rows, kind=c_int), r0, c0)
  end function solver_set_coupling_pattern

  integer(c_int) function solver_set_coupling_exact(this, exact) result(status)
    class(galpha_solver), intent(inout) :: this
    logical, intent(in) :: exact
    status = ga_set_coupling_exact(this%handle, merge(1_c_int, 0_c_int, exact))
  end function solver_set_coupling_exact

  integer(c_int) function solver_init_y(this, t0, q0, v0, y0) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t0, q0(:), v0(:), y0(:)
    if (size(q0) < this%nq .or. size(v0) < this%n .or. size(y0) < this%r) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_init_y(this%handle, t0, q0, v0, y0)
  end function solver_init_y

  integer(c_int) function solver_get_y(this, y, ydot) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out), optional :: y(:), ydot(:)
    real(c_double) :: yy(max(this%r, 1)), dd(max(this%r, 1))
    status = ga_get_y(this%handle, yy, dd)
    if (status /= GA_OK) return
    if (present(y)) y(1:this%r) = yy(1:this%r)
    if (present(ydot)) ydot(1:this%r) = dd(1:this%r)
  end function solver_get_y

  integer(c_int) function solver_interpolate_y(this, t, y, ydot) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t
    real(c_double), intent(out), optional :: y(:), ydot(:)
    real(c_double) :: yy(max(this%r, 1)), dd(max(this%r, 1))
    status = ga_interpolate_y(this%handle, t, yy, dd)
    if (status /= GA_OK) return
    if (present(y)) y(1:this%r) = yy(1:this%r)
    if (present(ydot)) ydot(1:this%r) = dd(1:this%r)
  end function solver_interpolate_y

  integer(c_int) function solver_set_sensitivity(this, p, depends, p_scale) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), target, contiguous, intent(inout) :: p(:)
    integer(c_int), intent(in) :: depends
    real(c_double), intent(in), optional :: p_scale(:)
    if (present(p_scale)) then
       if (size(p_scale) /= size(p)) then
          status = GA_ERR_ARG
          return
       end if
       status = ga_set_sensitivity(this%handle, int(size(p), c_int), c_loc(p), p_scale, depends)
    else
       status = ga_set_sensitivity(this%handle, int(size(p), c_int), c_loc(p), depends=depends)
    end if
    if (status == GA_OK) this%np = size(p)
  end function solver_set_sensitivity

  integer(c_int) function solver_set_parameter_derivatives(this, force_p, mass_p) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_force_p_fn), optional :: force_p
    procedure(ga_mass_p_fn), optional :: mass_p
    type(c_funptr) :: f, m
    f = c_null_funptr
    m = c_null_funptr
    if (present(force_p)) f = c_funloc(force_p)
    if (present(mass_p)) m = c_funloc(mass_p)
    status = ga_set_parameter_derivatives(this%handle, f, m)
  end function solver_set_parameter_derivatives

  integer(c_int) function solver_set_constraint_parameter_derivative(this, fn) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_constraint_p_fn), optional :: fn
    type(c_funptr) :: f
    f = c_null_funptr
    if (present(fn)) f = c_funloc(fn)
    status = ga_set_constraint_parameter_derivative(this%handle, f)
  end function solver_set_constraint_parameter_derivative

  integer(c_int) function solver_get_sensitivity_y(this, j, dy, dydot) result(status)
    class(galpha_solver), intent(in) :: this
    integer, intent(in) :: j
    real(c_double), intent(out), optional :: dy(:), dydot(:)
    real(c_double) :: a(max(this%r, 1)), b(max(this%r, 1))
    status = ga_get_sensitivity_y(this%handle, int(j - 1, c_int), a, b)
    if (status /= GA_OK) return
    if (present(dy)) dy(1:this%r) = a(1:this%r)
    if (present(dydot)) dydot(1:this%r) = b(1:this%r)
  end function solver_get_sensitivity_y

  integer(c_int) function solver_set_sensitivity_start(this, j, dq0, dv0) result(status)
    class(galpha_solver), intent(inout) :: this
    integer, intent(in) :: j
    real(c_double), intent(in), optional :: dq0(:), dv0(:)
    if ((present(dq0) .and. size(dq0) < this%n) .or. (present(dv0) .and. size(dv0) < this%n)) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_set_sensitivity_start(this%handle, int(j - 1, c_int), dq0, dv0)
  end function solver_set_sensitivity_start

  integer(c_int) function solver_get_sensitivity(this, j, dq, dv, dqdd, dlambda) result(status)
    class(galpha_solver), intent(in) :: this
    integer, intent(in) :: j
    real(c_double), intent(out), optional :: dq(:), dv(:), dqdd(:), dlambda(:)
    real(c_double) :: x(max(this%n, 1), 3), l(max(this%m, 1))
    status = ga_get_sensitivity(this%handle, int(j - 1, c_int), x(:, 1), x(:, 2), x(:, 3), l)
    if (status /= GA_OK) return
    if (present(dq)) dq(1:this%n) = x(1:this%n, 1)
    if (present(dv)) dv(1:this%n) = x(1:this%n, 2)
    if (present(dqdd)) dqdd(1:this%n) = x(1:this%n, 3)
    if (present(dlambda)) dlambda(1:this%m) = l(1:this%m)
  end function solver_get_sensitivity

  integer(c_int) function solver_set_sensitivity_method(this, methods, max_steps) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: methods
    integer, intent(in) :: max_steps
    status = ga_set_sensitivity_method(this%handle, methods, int(max_steps, c_long))
  end function solver_set_sensitivity_method

  integer(c_int) function solver_set_adjoint_checkpoints(this, interval, count) result(status)
    class(galpha_solver), intent(inout) :: this
    integer, intent(in) :: interval, count
    status = ga_set_adjoint_checkpoints(this%handle, int(interval, c_long), int(count, c_long))
  end function solver_set_adjoint_checkpoints

  integer(c_int) function solver_adjoint_gradient(this, J, dJ_dp, running, terminal) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(out) :: J, dJ_dp(:)
    procedure(ga_cost_fn), optional :: running, terminal
    type(c_funptr) :: r, g
    real(c_double) :: d(max(this%np, 1))
    r = c_null_funptr
    g = c_null_funptr
    if (present(running)) r = c_funloc(running)
    if (present(terminal)) g = c_funloc(terminal)
    status = ga_adjoint_gradient(this%handle, r, g, J, d)
    if (status == GA_OK) dJ_dp(1:this%np) = d(1:this%np)
  end function solver_adjoint_gradient

  integer(c_int) function solver_set_constraint_accel(this, fn) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_force_fn) :: fn
    status = ga_set_constraint_accel(this%handle, c_funloc(fn))
  end function solver_set_constraint_accel

  integer(c_int) function solver_set_constraint_dt(this, fn) result(status)
    class(galpha_solver), intent(inout) :: this
    procedure(ga_constraint_fn) :: fn
    status = ga_set_constraint_dt(this%handle, c_funloc(fn))
  end function solver_set_constraint_dt

  integer(c_int) function solver_set_rho_inf(this, rho_inf) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: rho_inf
    status = ga_set_rho_inf(this%handle, rho_inf)
  end function solver_set_rho_inf

  integer(c_int) function solver_set_newton(this, tol, max_iter) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: tol
    integer, intent(in) :: max_iter
    status = ga_set_newton(this%handle, tol, int(max_iter, c_int))
  end function solver_set_newton

  integer(c_int) function solver_init(this, t0, q0, v0) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t0, q0(:), v0(:)
    if (size(q0) /= this%nq .or. size(v0) /= this%n) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_init(this%handle, t0, q0, v0)
  end function solver_init

  integer(c_int) function solver_step(this, h) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: h
    status = ga_step(this%handle, h)
  end function solver_step

  integer(c_int) function solver_set_tolerances(this, rtol, atol) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: rtol, atol
    status = ga_set_tolerances(this%handle, rtol, atol)
  end function solver_set_tolerances

  ! atol: 2 n + r entries (positions, velocities, first-order states)
  integer(c_int) function solver_set_tolerances_vector(this, rtol, atol) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: rtol, atol(:)
    if (size(atol) /= 2 * this%n + this%r) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_set_tolerances_vector(this%handle, rtol, atol)
  end function solver_set_tolerances_vector

  integer(c_int) function solver_set_formulation(this, formulation) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: formulation
    status = ga_set_formulation(this%handle, formulation)
  end function solver_set_formulation

  integer(c_int) function solver_check_derivatives(this, t, q, v, worst, qdd, lambda, y, tol) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:), v(:)
    real(c_double), intent(out) :: worst
    real(c_double), intent(in), optional, target :: qdd(:), lambda(:), y(:)
    real(c_double), intent(in), optional :: tol
    type(c_ptr) :: pqdd, plambda, py
    real(c_double) :: tolerance
    pqdd = c_null_ptr
    plambda = c_null_ptr
    py = c_null_ptr
    tolerance = 1d-6
    if (present(qdd)) pqdd = c_loc(qdd)
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(y)) py = c_loc(y)
    if (present(tol)) tolerance = tol
    status = ga_check_derivatives(this%handle, t, q, v, pqdd, plambda, py, tolerance, worst)
  end function solver_check_derivatives

  integer(c_int) function solver_static_equilibrium(this, t, q, lambda, tol, max_iter) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t
    real(c_double), intent(inout) :: q(:)
    real(c_double), intent(inout), optional, target :: lambda(:)
    real(c_double), intent(in), optional :: tol
    integer, intent(in), optional :: max_iter
    type(c_ptr) :: plambda
    real(c_double) :: tolerance
    integer(c_int) :: iterations
    plambda = c_null_ptr
    tolerance = 1d-10
    iterations = 50
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(tol)) tolerance = tol
    if (present(max_iter)) iterations = int(max_iter, c_int)
    status = ga_static_equilibrium(this%handle, t, q, plambda, tolerance, iterations)
  end function solver_static_equilibrium

  integer(c_int) function solver_static_equilibrium_y(this, t, q, y, lambda, tol, max_iter) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t
    real(c_double), intent(inout) :: q(:)
    real(c_double), intent(inout), target :: y(:)
    real(c_double), intent(inout), optional, target :: lambda(:)
    real(c_double), intent(in), optional :: tol
    integer, intent(in), optional :: max_iter
    type(c_ptr) :: plambda, py
    real(c_double) :: tolerance
    integer(c_int) :: iterations
    plambda = c_null_ptr
    py = c_null_ptr
    tolerance = 1d-10
    iterations = 50
    if (size(y) > 0) py = c_loc(y)
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(tol)) tolerance = tol
    if (present(max_iter)) iterations = int(max_iter, c_int)
    status = ga_static_equilibrium_y(this%handle, t, q, py, plambda, tolerance, iterations)
  end function solver_static_equilibrium_y

  integer(c_int) function solver_state_space(this, t, q, dim, y, lambda, basis, a) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:)
    integer, intent(out) :: dim
    real(c_double), intent(in), optional, target :: y(:), lambda(:)
    real(c_double), intent(out), optional, target :: basis(:, :), a(:, :)
    type(c_ptr) :: py, plambda, pbasis, pa
    integer(c_int) :: d, max_dim
    py = c_null_ptr
    plambda = c_null_ptr
    pbasis = c_null_ptr
    pa = c_null_ptr
    max_dim = huge(max_dim)
    if (present(y)) then
       if (size(y) > 0) py = c_loc(y)
    end if
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(basis)) pbasis = c_loc(basis)
    if (present(a)) then
       pa = c_loc(a)
       max_dim = int(size(a, 1), c_int)
    end if
    d = 0
    status = ga_state_space(this%handle, t, q, py, plambda, max_dim, d, pbasis, pa)
    dim = int(d)
  end function solver_state_space

  integer(c_int) function solver_state_space_motion(this, t, q, v, dim, y, basis, a) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:), v(:)
    integer, intent(out) :: dim
    real(c_double), intent(in), optional, target :: y(:)
    real(c_double), intent(out), optional, target :: basis(:, :), a(:, :)
    type(c_ptr) :: py, pbasis, pa
    integer(c_int) :: d, max_dim
    py = c_null_ptr
    pbasis = c_null_ptr
    pa = c_null_ptr
    max_dim = huge(max_dim)
    if (present(y)) then
       if (size(y) > 0) py = c_loc(y)
    end if
    if (present(basis)) pbasis = c_loc(basis)
    if (present(a)) then
       pa = c_loc(a)
       max_dim = int(size(a, 1), c_int)
    end if
    d = 0
    status = ga_state_space_motion(this%handle, t, q, v, py, max_dim, d, pbasis, pa)
    dim = int(d)
  end function solver_state_space_motion

  integer(c_int) function solver_modes(this, t, q, omega2, lambda, shapes) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:)
    real(c_double), intent(out) :: omega2(:)
    real(c_double), intent(in), optional, target :: lambda(:)
    real(c_double), intent(out), optional, target :: shapes(:, :)
    type(c_ptr) :: plambda, pshapes
    plambda = c_null_ptr
    pshapes = c_null_ptr
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(shapes)) pshapes = c_loc(shapes)
    status = ga_modes(this%handle, t, q, plambda, int(size(omega2), c_int), omega2, pshapes)
  end function solver_modes

  integer(c_int) function solver_modes_near(this, t, q, sigma, omega2, lambda, shapes) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:), sigma
    real(c_double), intent(out) :: omega2(:)
    real(c_double), intent(in), optional, target :: lambda(:)
    real(c_double), intent(out), optional, target :: shapes(:, :)
    type(c_ptr) :: plambda, pshapes
    plambda = c_null_ptr
    pshapes = c_null_ptr
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(shapes)) pshapes = c_loc(shapes)
    status = ga_modes_near(this%handle, t, q, plambda, sigma, int(size(omega2), c_int), omega2, &
         pshapes)
  end function solver_modes_near

  integer(c_int) function solver_linearize(this, t, q, dof, basis, mass, damping, stiffness, &
       lambda) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:)
    integer, intent(out) :: dof
    real(c_double), intent(out), optional, target :: basis(:, :), mass(:, :), damping(:, :), &
         stiffness(:, :)
    real(c_double), intent(in), optional, target :: lambda(:)
    type(c_ptr) :: pb, pm, pc, pk, plambda
    integer(c_int) :: d, max_dof
    pb = c_null_ptr
    pm = c_null_ptr
    pc = c_null_ptr
    pk = c_null_ptr
    plambda = c_null_ptr
    max_dof = int(size(q), c_int)
    if (present(basis)) then
       pb = c_loc(basis)
       max_dof = min(max_dof, int(size(basis, 2), c_int))
    end if
    if (present(mass)) then
       pm = c_loc(mass)
       max_dof = min(max_dof, int(size(mass, 1), c_int))
    end if
    if (present(damping)) then
       pc = c_loc(damping)
       max_dof = min(max_dof, int(size(damping, 1), c_int))
    end if
    if (present(stiffness)) then
       pk = c_loc(stiffness)
       max_dof = min(max_dof, int(size(stiffness, 1), c_int))
    end if
    if (present(lambda)) plambda = c_loc(lambda)
    d = 0
    status = ga_linearize(this%handle, t, q, plambda, max_dof, d, pb, pm, pc, pk)
    dof = int(d)
  end function solver_linearize

  integer(c_int) function solver_modes_damped(this, t, q, re, im, lambda, shapes_re, shapes_im) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, q(:)
    real(c_double), intent(out) :: re(:), im(:)
    real(c_double), intent(in), optional, target :: lambda(:)
    real(c_double), intent(out), optional, target :: shapes_re(:, :), shapes_im(:, :)
    type(c_ptr) :: plambda, pr, pi
    plambda = c_null_ptr
    pr = c_null_ptr
    pi = c_null_ptr
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(shapes_re)) pr = c_loc(shapes_re)
    if (present(shapes_im)) pi = c_loc(shapes_im)
    status = GA_ERR_ARG
    if (size(im) < size(re)) return
    status = ga_modes_damped(this%handle, t, q, plambda, int(size(re), c_int), re, im, pr, pi)
  end function solver_modes_damped

  integer(c_int) function solver_static_path(this, t, load, q, ds, max_points, lambda, tol, fn, &
       user) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t, ds
    real(c_double), intent(inout), target :: load
    real(c_double), intent(inout) :: q(:)
    integer, intent(in) :: max_points
    real(c_double), intent(inout), optional, target :: lambda(:)
    real(c_double), intent(in), optional :: tol
    type(c_funptr), intent(in), optional :: fn
    type(c_ptr), intent(in), optional :: user
    type(c_ptr) :: plambda, puser
    type(c_funptr) :: pfn
    real(c_double) :: tolerance
    plambda = c_null_ptr
    puser = c_null_ptr
    pfn = c_null_funptr
    tolerance = 1d-10
    if (present(lambda)) plambda = c_loc(lambda)
    if (present(tol)) tolerance = tol
    if (present(fn)) pfn = fn
    if (present(user)) puser = user
    status = ga_static_path(this%handle, t, c_loc(load), q, plambda, ds, &
         int(max_points, c_int), tolerance, pfn, puser)
  end function solver_static_path

  integer(c_int) function solver_set_resolution_check(this, limit) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: limit
    status = ga_set_resolution_check(this%handle, limit)
  end function solver_set_resolution_check

  integer(c_int) function solver_set_pattern(this, which, rows, cols) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: which
    integer(c_int), intent(in) :: rows(:), cols(:)
    integer(c_int), allocatable :: r0(:), c0(:)
    if (size(rows) /= size(cols)) then
       status = GA_ERR_ARG
       return
    end if
    r0 = rows - 1  ! the C API counts from 0
    c0 = cols - 1
    status = ga_set_pattern(this%handle, which, int(size(rows), c_int), r0, c0)
  end function solver_set_pattern

  integer(c_int) function solver_set_pattern_csc(this, which, colptr, rowind) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: which
    integer(c_int), intent(in) :: colptr(:), rowind(:)
    integer(c_int), allocatable :: p0(:), r0(:)
    integer(c_int) :: n, m
    status = ga_get_size(this%handle, n, m)
    if (status /= GA_OK) return
    if (size(colptr) /= n + 1) then
       status = GA_ERR_ARG
       return
    end if
    if (size(rowind) < colptr(n + 1) - 1) then
       status = GA_ERR_ARG
       return
    end if
    p0 = colptr - 1  ! the C API counts from 0
    r0 = rowind - 1
    if (size(r0) == 0) r0 = [0_c_int]  ! a valid address for an empty pattern
    status = ga_set_pattern_csc(this%handle, which, p0, r0)
  end function solver_set_pattern_csc

  integer(c_int) function solver_set_constant_mass(this, on) result(status)
    class(galpha_solver), intent(inout) :: this
    logical, intent(in) :: on
    status = ga_set_constant_mass(this%handle, merge(1_c_int, 0_c_int, on))
  end function solver_set_constant_mass

  integer(c_int) function solver_set_linear_solver(this, solver) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: solver
    status = ga_set_linear_solver(this%handle, solver)
  end function solver_set_linear_solver

  function solver_linear_solver_name(this) result(name)
    class(galpha_solver), intent(in) :: this
    character(len=:), allocatable :: name
    name = c_to_f(ga_linear_solver_name(this%handle))
  end function solver_linear_solver_name

  integer(c_int) function solver_set_redundant_constraints(this, mode) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: mode
    status = ga_set_redundant_constraints(this%handle, mode)
  end function solver_set_redundant_constraints

  integer(c_int) function solver_get_active_constraints(this, active) result(status)
    class(galpha_solver), intent(in) :: this
    integer(c_int), intent(out) :: active(:)
    status = ga_get_active_constraints(this%handle, active)
  end function solver_get_active_constraints

  integer(c_int) function solver_advance(this, t_out) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t_out
    status = ga_advance(this%handle, t_out)
  end function solver_advance

  integer(c_int) function solver_set_output(this, mode) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: mode
    status = ga_set_output(this%handle, mode)
  end function solver_set_output

  integer(c_int) function solver_interpolate(this, t, q, v, lambda) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t
    real(c_double), intent(out), optional :: q(:), v(:), lambda(:)
    status = GA_ERR_ARG
    if (present(q)) then
       if (size(q) < this%nq) return
    end if
    if (present(v)) then
       if (size(v) < this%n) return
    end if
    if (present(lambda)) then
       if (size(lambda) < this%m) return
    end if
    ! an absent argument reaches C as NULL (Fortran 2018, optional in bind(C) interfaces)
    status = ga_interpolate(this%handle, t, q, v, lambda)
  end function solver_interpolate

  integer(c_int) function solver_interpolate_qdd(this, t, qdd) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t
    real(c_double), intent(out) :: qdd(:)
    if (size(qdd) < this%n) then
       status = GA_ERR_ARG
       return
    end if
    status = ga_interpolate_qdd(this%handle, t, qdd)
  end function solver_interpolate_qdd

  real(c_double) function solver_t(this) result(t)
    class(galpha_solver), intent(in) :: this
    integer(c_int) :: status
    status = ga_get_t(this%handle, t)
    if (status /= GA_OK) t = ieee_nan()
  end function solver_t

  real(c_double) function ieee_nan()
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    ieee_nan = ieee_value(0.0_c_double, ieee_quiet_nan)
  end function ieee_nan

  integer(c_int) function copy_out(this, fn, x, expected) result(status)
    class(galpha_solver), intent(in) :: this
    interface
       integer(c_int) function fn(s, x) bind(C)
         import :: c_int, c_ptr, c_double
         type(c_ptr), value :: s
         real(c_double), intent(out) :: x(*)
       end function fn
    end interface
    real(c_double), intent(out) :: x(:)
    integer, intent(in) :: expected
    if (size(x) /= expected) then
       status = GA_ERR_ARG
       return
    end if
    status = fn(this%handle, x)
  end function copy_out

  integer(c_int) function solver_get_q(this, q) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: q(:)
    status = copy_out(this, ga_get_q, q, this%nq)
  end function solver_get_q

  integer(c_int) function solver_get_v(this, v) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: v(:)
    status = copy_out(this, ga_get_v, v, this%n)
  end function solver_get_v

  integer(c_int) function solver_get_qdd(this, qdd) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: qdd(:)
    status = copy_out(this, ga_get_qdd, qdd, this%n)
  end function solver_get_qdd

  integer(c_int) function solver_get_lambda(this, lambda) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: lambda(:)
    status = copy_out(this, ga_get_lambda, lambda, this%m)
  end function solver_get_lambda

  integer(c_long_long) function solver_counter(this, key) result(value)
    class(galpha_solver), intent(in) :: this
    integer(c_int), intent(in) :: key
    if (ga_get_counter(this%handle, key, value) /= GA_OK) value = -1
  end function solver_counter

  function solver_message(this) result(s)
    class(galpha_solver), intent(in) :: this
    character(len=:), allocatable :: s
    s = c_to_f(ga_last_error(this%handle))
  end function solver_message

  integer(c_int) function solver_get_size(this, n, m) result(status)
    class(galpha_solver), intent(in) :: this
    integer, intent(out) :: n, m
    integer(c_int) :: cn, cm
    status = ga_get_size(this%handle, cn, cm)
    n = int(cn)
    m = int(cm)
  end function solver_get_size

  integer(c_int) function solver_set_params(this, alpha_m, alpha_f, beta, gamma) &
       result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: alpha_m, alpha_f, beta, gamma
    status = ga_set_params(this%handle, alpha_m, alpha_f, beta, gamma)
  end function solver_set_params

  integer(c_int) function solver_get_params(this, alpha_m, alpha_f, beta, gamma) &
       result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: alpha_m, alpha_f, beta, gamma
    status = ga_get_params(this%handle, alpha_m, alpha_f, beta, gamma)
  end function solver_get_params

  integer(c_int) function solver_set_tangent_mode(this, mode) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: mode
    status = ga_set_tangent_mode(this%handle, mode)
  end function solver_set_tangent_mode

  integer(c_int) function solver_set_scaling(this, on) result(status)
    class(galpha_solver), intent(inout) :: this
    logical, intent(in) :: on
    status = ga_set_scaling(this%handle, merge(1_c_int, 0_c_int, on))
  end function solver_set_scaling

  integer(c_int) function solver_set_jacobian_reuse(this, mode) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: mode
    status = ga_set_jacobian_reuse(this%handle, mode)
  end function solver_set_jacobian_reuse

  integer(c_int) function solver_set_predictor(this, predictor) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: predictor
    status = ga_set_predictor(this%handle, predictor)
  end function solver_set_predictor

  integer(c_int) function solver_set_rescale(this, on) result(status)
    class(galpha_solver), intent(inout) :: this
    logical, intent(in) :: on
    status = ga_set_rescale(this%handle, merge(1_c_int, 0_c_int, on))
  end function solver_set_rescale

  integer(c_int) function solver_set_corrected_start(this, on) result(status)
    class(galpha_solver), intent(inout) :: this
    logical, intent(in) :: on
    status = ga_set_corrected_start(this%handle, merge(1_c_int, 0_c_int, on))
  end function solver_set_corrected_start

  integer(c_int) function solver_set_init_mode(this, mode, init_tol) result(status)
    class(galpha_solver), intent(inout) :: this
    integer(c_int), intent(in) :: mode
    real(c_double), intent(in) :: init_tol
    status = ga_set_init_mode(this%handle, mode, init_tol)
  end function solver_set_init_mode

  integer(c_int) function solver_set_step_limits(this, h_min, h_max) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: h_min, h_max
    status = ga_set_step_limits(this%handle, h_min, h_max)
  end function solver_set_step_limits

  integer(c_int) function solver_set_initial_step(this, h0) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: h0
    status = ga_set_initial_step(this%handle, h0)
  end function solver_set_initial_step

  integer(c_int) function solver_step_adaptive(this, t_stop) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: t_stop
    status = ga_step_adaptive(this%handle, t_stop)
  end function solver_step_adaptive

  integer(c_int) function solver_get_a(this, a) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: a(:)
    status = copy_out(this, ga_get_a, a, this%n)
  end function solver_get_a

  real(c_double) function solver_h_last(this) result(h)
    class(galpha_solver), intent(in) :: this
    if (ga_get_h_last(this%handle, h) /= GA_OK) h = ieee_nan()
  end function solver_h_last

  integer function solver_state_size(this) result(len)
    class(galpha_solver), intent(in) :: this
    integer(c_size_t) :: n
    len = -1
    if (ga_state_size(this%handle, n) == GA_OK) len = int(n)
  end function solver_state_size

  integer(c_int) function solver_get_state(this, buf) result(status)
    class(galpha_solver), intent(in) :: this
    real(c_double), intent(out) :: buf(:)
    status = ga_get_state(this%handle, buf, int(size(buf), c_size_t))
  end function solver_get_state

  integer(c_int) function solver_set_state(this, buf) result(status)
    class(galpha_solver), intent(inout) :: this
    real(c_double), intent(in) :: buf(:)
    status = ga_set_state(this%handle, buf, int(size(buf), c_size_t))
  end function solver_set_state

  integer(c_int) function solver_reset_counters(this) result(status)
    class(galpha_solver), intent(inout) :: this
    status = ga_reset_counters(this%handle)
  end function solver_reset_counters

  integer(c_int) function solver_get_info(this, key, value) result(status)
    class(galpha_solver), intent(in) :: this
    integer(c_int), intent(in) :: key
    real(c_double), intent(out) :: value
    status = ga_get_info(this%handle, key, value)
  end function solver_get_info

end module galpha
