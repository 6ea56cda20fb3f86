! The Fortran layer (type(galpha_solver)) over the whole C API: each type-bound procedure
! against what the C API or the analysis says, on the unit pendulum of params_model.f90 (its
! parameters through `user`). Stops with a nonzero code at the first failure.

module layer_events
  use, intrinsic :: iso_c_binding
  use galpha, only: GA_OK, ga_get_t, ga_get_q, ga_get_v, ga_get_lambda
  implicit none
  real(c_double), target, save :: stiffness(1) = [4.0d0]
  real(c_double), target, save :: push = 0.0d0  ! the static path's load
  integer :: hook_calls = 0, hook_mismatches = 0, hook_stop_at = 0
contains
  ! g(1) = x: the pendulum passes the vertical
  integer(c_int) function vertical(t, q, v, lambda, g, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), lambda(*)
    real(c_double), intent(out) :: g(*)
    type(c_ptr), value :: user
    g(1) = q(1)
    vertical = 0
  end function vertical

  ! the step hook: counts steps, checks what it is passed against the solver's reads, stops
  ! at call hook_stop_at
  integer(c_int) function watch_steps(s, t, q, v, lambda, user) bind(C)
    type(c_ptr), value :: s
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), lambda(*)
    type(c_ptr), value :: user
    real(c_double) :: tt, qq(2), vv(2), ll(1)
    hook_calls = hook_calls + 1
    if (ga_get_t(s, tt) /= GA_OK .or. ga_get_q(s, qq) /= GA_OK .or. &
        ga_get_v(s, vv) /= GA_OK .or. ga_get_lambda(s, ll) /= GA_OK) then
       hook_mismatches = hook_mismatches + 1
    else if (tt /= t .or. any(qq /= q(1:2)) .or. any(vv /= v(1:2)) .or. &
             ll(1) /= lambda(1)) then
       hook_mismatches = hook_mismatches + 1
    end if
    watch_steps = 0
    if (hook_calls == hook_stop_at) watch_steps = 1
  end function watch_steps

  ! the pendulum's weight and a horizontal push (the static path's load)
  integer(c_int) function pushed_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    f(1) = push
    f(2) = -9.81d0
    pushed_force = 0
  end function pushed_force

  ! first-order states: x'' = -x + y with y' = -2 y (y = exp(-2 t) from y0 = 1)
  integer(c_int) function unit_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: M(*)
    type(c_ptr), value :: user
    M(1) = 1.0d0
    unit_mass = 0
  end function unit_mass
  integer(c_int) function driven(t, q, v, y, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    f(1) = -q(1) + y(1)
    driven = 0
  end function driven
  integer(c_int) function decay(t, q, v, y, ydot, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: ydot(*)
    type(c_ptr), value :: user
    ydot(1) = -2.0d0 * y(1)
    decay = 0
  end function decay
  integer(c_int) function blocks(t, q, v, y, g_q, g_v, g_y, f_y, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: g_q(*), g_v(*), g_y(*), f_y(*)
    type(c_ptr), value :: user
    g_q(1) = 0.0d0
    g_v(1) = 0.0d0
    g_y(1) = -2.0d0
    f_y(1) = 1.0d0
    blocks = 0
  end function blocks
  ! y falls through 1/2 at t = ln(2) / 2
  integer(c_int) function half(t, q, v, y, lambda, g, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*), lambda(*)
    real(c_double), intent(out) :: g(*)
    type(c_ptr), value :: user
    g(1) = y(1) - 0.5d0
    half = 0
  end function half

  ! sensitivities: x'' = -k x, k read from stiffness(1) (the array galpha perturbs)
  integer(c_int) function spring(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    f(1) = -stiffness(1) * q(1)
    spring = 0
  end function spring
  integer(c_int) function spring_p(t, q, v, j, f_p, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    integer(c_int), value :: j
    real(c_double), intent(out) :: f_p(*)
    type(c_ptr), value :: user
    f_p(1) = -q(1)
    spring_p = merge(0, -1, j == 0)
  end function spring_p
  ! the cost J = x(1) at the end
  integer(c_int) function final_position(t, q, v, qdd, lambda, value, d_q, d_v, d_qdd, &
       d_lambda, d_p, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), qdd(*), lambda(*)
    real(c_double), intent(out) :: value, d_q(*), d_v(*), d_qdd(*), d_lambda(*), d_p(*)
    type(c_ptr), value :: user
    value = q(1)
    d_q(1) = 1.0d0
    d_v(1) = 0.0d0
    d_qdd(1) = 0.0d0
    d_p(1) = 0.0d0
    final_position = 0
  end function final_position

  ! a parameter in the constraints: the particle of unit mass on the rail x = c under the
  ! force (-x, -y), so that x = c and lambda = -c for all t: dx/dc = 1, dlambda/dc = -1
  integer(c_int) function plane_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: M(*)
    type(c_ptr), value :: user
    M(1:4) = [1.0d0, 0.0d0, 0.0d0, 1.0d0]
    plane_mass = 0
  end function plane_mass
  integer(c_int) function plane_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    f(1:2) = -q(1:2)
    plane_force = 0
  end function plane_force
  integer(c_int) function rail(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: phi(*)
    type(c_ptr), value :: user
    phi(1) = q(1) - stiffness(1)
    rail = 0
  end function rail
  integer(c_int) function rail_jacobian(t, q, J, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: J(*)
    type(c_ptr), value :: user
    J(1:2) = [1.0d0, 0.0d0]
    rail_jacobian = 0
  end function rail_jacobian
  integer(c_int) function rail_p(t, q, j, phi_p, jac_p, phi_tp, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    integer(c_int), value :: j
    real(c_double), intent(out) :: phi_p(*), jac_p(*)
    type(c_ptr), value :: phi_tp, user
    real(c_double), pointer :: tp(:)
    phi_p(1) = -1.0d0
    jac_p(1:2) = 0.0d0
    if (c_associated(phi_tp)) then
       call c_f_pointer(phi_tp, tp, [1])
       tp(1) = 0.0d0
    end if
    rail_p = merge(0, -1, j == 0)
  end function rail_p
end module layer_events

program test_layer
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  use galpha
  use params_model
  use layer_events
  implicit none
  type(pendulum_params), target :: unit = pendulum_params(1.0d0, 1.0d0, 9.81d0)
  type(galpha_solver) :: s, r
  real(c_double) :: q(2), v(2), a(2), lam(1), q2(2), v2(2), lam2(1), x, am, af, beta, gam
  real(c_double), allocatable :: ckpt(:), back(:)
  real(c_double) :: quarter, ag, bg, ag_next, te, worst
  integer(c_int) :: index, direction
  real(c_double), parameter :: rho = 0.8d0
  integer :: n, m, i, nstate
  character(len=32) :: text

  n = galpha_version_number()
  write (text, '(i0, ".", i0, ".", i0)') n / 10000, mod(n / 100, 100), mod(n, 100)
  call expect(galpha_version() == trim(text), 'version string and number agree')
  call expect(galpha_strerror(GA_ERR_ARG) /= galpha_strerror(GA_OK), 'strerror')

  call ok(s%create(2, 1), 'create')
  call ok(s%get_size(n, m), 'get_size')
  call expect(n == 2 .and. m == 1, 'get_size values')
  call ok(s%set_callbacks(p_mass, p_force, p_constraint, p_jacobian, c_loc(unit)), &
          'set_callbacks')

  ! parameters from rho_inf (Chung-Hulbert): alpha_m = (2 rho - 1)/(rho + 1), alpha_f =
  ! rho/(rho + 1), gamma = 1/2 + alpha_f - alpha_m, beta = (gamma + 1/2)^2 / 4
  call ok(s%set_rho_inf(rho), 'set_rho_inf')
  call ok(s%get_params(am, af, beta, gam), 'get_params')
  call expect(abs(am - (2 * rho - 1) / (rho + 1)) < 1d-15 .and. &
              abs(af - rho / (rho + 1)) < 1d-15 .and. &
              abs(gam - (0.5d0 + af - am)) < 1d-15 .and. &
              abs(beta - 0.25d0 * (gam + 0.5d0)**2) < 1d-15, 'parameters of rho_inf')
  call ok(s%set_params(am, af, beta, gam), 'set_params')
  call expect(s%set_params(0.9d0, 0.1d0, beta, gam) == GA_ERR_ARG, 'set_params refuses')
  call expect(len(s%message()) > 0, 'message after a refusal')

  ! every option setter: accepts a valid value, refuses an invalid one
  call ok(s%set_tangent_mode(GA_TANGENT_AUTO), 'set_tangent_mode')
  call expect(s%set_tangent_mode(99_c_int) == GA_ERR_ARG, 'set_tangent_mode refuses')
  call ok(s%set_scaling(.true.), 'set_scaling')
  call ok(s%set_jacobian_reuse(GA_REUSE_AUTO), 'set_jacobian_reuse')
  call expect(s%set_jacobian_reuse(99_c_int) == GA_ERR_ARG, 'set_jacobian_reuse refuses')
  call ok(s%set_predictor(GA_PREDICTOR_EXTRAPOLATE), 'set_predictor')
  call expect(s%set_predictor(99_c_int) == GA_ERR_ARG, 'set_predictor refuses')
  call ok(s%set_rescale(.true.), 'set_rescale')
  call ok(s%set_corrected_start(.true.), 'set_corrected_start')
  call ok(s%set_init_mode(GA_INIT_PROJECT, 1d-10), 'set_init_mode')
  call expect(s%set_init_mode(GA_INIT_PROJECT, -1d0) == GA_ERR_ARG, 'set_init_mode refuses')
  call ok(s%set_tolerances_vector(1d-6, [1d-6, 1d-6, 1d-6, 1d-6]), 'set_tolerances_vector')
  call expect(s%set_tolerances_vector(1d-6, [1d-6, 1d-6, 1d-6]) == GA_ERR_ARG, &
              'set_tolerances_vector checks the length')
  call expect(s%set_tolerances_vector(1d-6, [1d-6, 0d0, 1d-6, 1d-6]) == GA_ERR_ARG, &
              'set_tolerances_vector refuses a zero entry')
  call ok(s%set_tolerances(1d-6, 1d-6), 'set_tolerances')
  call ok(s%set_step_limits(1d-10, 0.05d0), 'set_step_limits')
  call expect(s%set_step_limits(0.1d0, 0.05d0) == GA_ERR_ARG, 'set_step_limits refuses')
  call ok(s%set_initial_step(1d-3), 'set_initial_step')
  call expect(s%set_initial_step(-1d0) == GA_ERR_ARG, 'set_initial_step refuses')

  ! before ga_init: state queries fail with GA_ERR_STATE, h_last is NaN
  call expect(s%get_a(a) == GA_ERR_STATE, 'get_a before init')
  x = s%h_last()
  call expect(x /= x, 'h_last before init is NaN')
  nstate = s%state_size()
  call expect(nstate > 0, 'state_size')
  allocate (ckpt(nstate), back(nstate))
  call expect(s%get_state(ckpt) == GA_ERR_STATE, 'get_state before init')

  call ok(s%init(0.0d0, [sin(1.0d0), -cos(1.0d0)], [0.0d0, 0.0d0]), 'init')
  call ok(s%get_a(a), 'get_a')
  call expect(s%h_last() == 0.0d0, 'h_last after init')

  ! adaptive steps to t = 1: they land on t_stop, respect h_max, keep |q| = 1
  do while (s%t() < 1.0d0)
     call ok(s%step_adaptive(1.0d0), 'step_adaptive')
     call expect(s%h_last() <= 0.05d0, 'h_max')
  end do
  call expect(s%t() == 1.0d0, 'adaptive steps land on t_stop')
  call ok(s%get_q(q), 'get_q')
  call expect(abs(norm2(q) - 1.0d0) < 1d-10, 'constraint held')
  call ok(s%get_info(GA_INFO_NEWTON_ITERS, x), 'get_info')
  call expect(x >= 1.0d0, 'Newton iterations of the last step')
  call ok(s%get_info(GA_INFO_H_NEXT, x), 'get_info h_next')
  call expect(x > 0.0d0 .and. x <= 0.05d0, 'proposed next step')
  call expect(s%get_info(99_c_int, x) == GA_ERR_ARG, 'get_info refuses an unknown key')
  call expect(s%counter(GA_COUNT_STEPS) > 0, 'steps counted')
  call ok(s%reset_counters(), 'reset_counters')
  call expect(s%counter(GA_COUNT_STEPS) == 0, 'counters reset')

  ! dense output: any output may be omitted, and what is asked for is the same
  x = s%t() - 0.5d0 * s%h_last()
  call ok(s%interpolate(x, q, v, lam), 'interpolate (all)')
  call ok(s%interpolate(x, q=q2), 'interpolate (q only)')
  call ok(s%interpolate(x, v=v2), 'interpolate (v only)')
  call ok(s%interpolate(x, lambda=lam2), 'interpolate (lambda only)')
  call expect(all(q == q2) .and. all(v == v2) .and. all(lam == lam2), 'interpolate parts')
  call expect(s%interpolate(x, q=q2(1:1)) == GA_ERR_ARG, 'interpolate checks sizes')
  call expect(s%interpolate(s%t() + 1.0d0, q=q2) == GA_ERR_ARG, 'interpolate outside the step')

  ! checkpoint: a new solver restored from it repeats the run bit for bit
  call ok(s%get_state(ckpt), 'get_state')
  call expect(s%get_state(ckpt(1:nstate - 1)) == GA_ERR_ARG, 'get_state checks the length')
  call ok(r%create(2, 1), 'create r')
  call ok(r%set_callbacks(p_mass, p_force, p_constraint, p_jacobian, c_loc(unit)), &
          'set_callbacks r')
  call ok(r%set_rho_inf(rho), 'set_rho_inf r')
  call ok(r%set_tolerances(1d-6, 1d-6), 'set_tolerances r')
  call ok(r%set_step_limits(1d-10, 0.05d0), 'set_step_limits r')
  call expect(r%set_state(ckpt(1:nstate - 1)) == GA_ERR_ARG, 'set_state checks the length')
  call ok(r%set_state(ckpt), 'set_state')
  do i = 1, 20
     call ok(s%step_adaptive(2.0d0), 'step_adaptive s')
     call ok(r%step_adaptive(2.0d0), 'step_adaptive r')
  end do
  call ok(s%get_state(ckpt), 'get_state s')
  call ok(r%get_state(back), 'get_state r')
  call expect(all(ckpt == back), 'restart is bit-identical')

  ! events: released horizontally, the pendulum passes the vertical after a quarter period,
  ! sqrt(L/g) K(1/sqrt(2)) with K = pi / (2 AGM(1, 1/sqrt(2)))
  ag = 1.0d0
  bg = sqrt(0.5d0)
  do i = 1, 40
     ag_next = 0.5d0 * (ag + bg)
     bg = sqrt(ag * bg)
     ag = ag_next
  end do
  quarter = sqrt(1.0d0 / 9.81d0) * acos(-1.0d0) / (2.0d0 * ag)
  call ok(s%init(0.0d0, [1.0d0, 0.0d0], [0.0d0, 0.0d0]), 'init for events')
  call expect(s%set_events(vertical, [GA_EVENT_FALLING], [.true., .false.]) == GA_ERR_ARG, &
              'set_events checks the sizes')
  call ok(s%set_events(vertical, [GA_EVENT_FALLING], [.true.]), 'set_events')
  i = GA_OK
  do while (i == GA_OK)
     i = s%step(1d-3)
  end do
  call expect(i == GA_EVENT, 'a terminal event stops ga_step')
  call expect(s%event_count() == 1, 'event_count')
  call ok(s%get_event(1, te, index, direction), 'get_event')
  call expect(index == 1 .and. direction == GA_EVENT_FALLING, 'event index and direction')
  call expect(abs(te - quarter) < 3d-6, 'event at the quarter period (1.7 h^2, C suite)')
  call expect(s%get_event(2, te, index, direction) == GA_ERR_ARG, 'get_event checks i')
  call ok(s%set_events(vertical, [integer(c_int) ::]), 'set_events removes')
  call ok(s%step(1d-3), 'step without events')
  call expect(s%event_count() == 0, 'no events logged')

  ! the step hook, with multipliers: called once per step with what the solver reads give
  hook_stop_at = 10
  call ok(s%set_step_hook(watch_steps, with_multipliers=.true.), 'set_step_hook')
  call expect(s%advance(s%t() + 1.0d0) == GA_STOPPED, 'the hook stops advance')
  call expect(hook_calls == 10 .and. hook_mismatches == 0, 'hook calls and what they see')
  call ok(s%step(1d-3), 'step with the hook')
  call expect(hook_calls == 11, 'one call per step')
  call ok(s%clear_step_hook(), 'clear_step_hook')
  call ok(s%step(1d-3), 'step without the hook')
  call expect(hook_calls == 11, 'no call after clear_step_hook')

  ! first-order states: y = exp(-2 t); the step's error at h = 1e-3 is ~1e-7 (order 2, C suite)
  call r%free()
  call ok(r%create(1, 0), 'create for first-order states')
  call ok(r%set_callbacks(unit_mass), 'callbacks')
  call ok(r%set_first_order(1, decay, driven), 'set_first_order')
  call ok(r%set_coupling(blocks), 'set_coupling')
  call ok(r%set_coupling_pattern(GA_COUPLING_G_Q, [integer(c_int) ::], [integer(c_int) ::]), &
          'set_coupling_pattern: g_q zero')
  call expect(r%set_coupling_pattern(GA_COUPLING_G_V, [1, 1], [1]) == GA_ERR_ARG, &
              'set_coupling_pattern checks the sizes')
  call ok(r%set_coupling_exact(.true.), 'set_coupling_exact')
  call expect(r%init(0.0d0, [0.0d0], [0.0d0]) == GA_ERR_STATE, 'init needs y0 first')
  call ok(r%init_y(0.0d0, [0.0d0], [0.0d0], [1.0d0]), 'init_y')
  do i = 1, 1000
     call ok(r%step(1d-3), 'step with first-order states')
  end do
  call ok(r%get_y(q(1:1), v(1:1)), 'get_y')
  call expect(abs(q(1) - exp(-2.0d0)) < 1d-6, 'y = exp(-2 t) at t = 1')
  call expect(abs(v(1) + 2.0d0 * q(1)) < 1d-9, "y' = -2 y")
  call ok(r%interpolate_y(0.9995d0, q2(1:1)), 'interpolate_y')
  call expect(abs(q2(1) - exp(-1.999d0)) < 1d-6, 'interpolated y')
  call expect(r%counter(GA_COUNT_RATE_EVALS) > 0 .and. r%counter(GA_COUNT_COUPLING_EVALS) > 0, &
              'rate and coupling counters')
  call ok(r%init_y(0.0d0, [0.0d0], [0.0d0], [1.0d0]), 'init_y again')
  call ok(r%set_events_y(half, [GA_EVENT_FALLING]), 'set_events_y')
  i = GA_OK
  do while (i == GA_OK)
     i = r%step(1d-3)
  end do
  call expect(i == GA_EVENT, 'an event on y stops ga_step')
  call ok(r%get_event(1, te, index, direction), 'get_event (y)')
  call expect(abs(te - 0.5d0 * log(2.0d0)) < 1d-6, 'y = 1/2 at t = ln(2) / 2')

  ! sensitivities: d x(1) / dk of x'' = -k x, x(0) = 1, against the exact
  ! -t sin(sqrt(k) t) / (2 sqrt(k)) (O(h^2) apart) and against differences of whole runs
  call r%free()
  x = spring_run(4.0d0 + 1d-4) - spring_run(4.0d0 - 1d-4)
  stiffness(1) = 4.0d0
  call ok(r%create(1, 0), 'create for sensitivities')
  call ok(r%set_callbacks(unit_mass, spring), 'callbacks')
  call ok(r%set_sensitivity(stiffness, GA_DEPENDS_FORCE), 'set_sensitivity')
  call expect(r%get_sensitivity(1, q(1:1)) == GA_ERR_STATE, 'get_sensitivity before init')
  call ok(r%init(0.0d0, [1.0d0], [0.0d0]), 'init with sensitivities')
  do i = 1, 1000
     call ok(r%step(1d-3), 'step with sensitivities')
  end do
  call ok(r%get_sensitivity(1, q(1:1), v(1:1)), 'get_sensitivity')
  call expect(abs(q(1) + sin(2.0d0) / 4.0d0) < 1d-5, 'dx/dk against the exact derivative')
  call expect(abs(q(1) - x / 2d-4) < 1d-7 * abs(q(1)), 'dx/dk against differences of runs')
  call expect(r%get_sensitivity(2, q(1:1)) == GA_ERR_ARG, 'get_sensitivity checks j')
  call expect(r%set_sensitivity_start(2, [1.0d0]) == GA_ERR_ARG, 'set_sensitivity_start checks j')
  call ok(r%get_sensitivity_y(1), 'get_sensitivity_y without first-order states')
  call ok(r%set_sensitivity_start(1), 'set_sensitivity_start: zero seeds')
  call r%free()
  call ok(r%create(1, 0), 'create for derivative callbacks')
  call ok(r%set_callbacks(unit_mass, spring), 'callbacks')
  call ok(r%set_sensitivity(stiffness, GA_DEPENDS_FORCE, [1.0d0]), 'set_sensitivity, scale')
  call ok(r%set_parameter_derivatives(force_p=spring_p), 'set_parameter_derivatives')
  call ok(r%init(0.0d0, [1.0d0], [0.0d0]), 'init')
  do i = 1, 1000
     call ok(r%step(1d-3), 'step with df/dk')
  end do
  call ok(r%get_sensitivity(1, q2(1:1)), 'get_sensitivity (callback)')
  call expect(abs(q2(1) - q(1)) < 1d-9 * abs(q(1)), 'df/dk by callback as by differences')
  ! the adjoint of the same run: J = x(1) at t = 1, dJ/dk = dx/dk
  call r%free()
  call ok(r%create(1, 0), 'create for the adjoint')
  call ok(r%set_callbacks(unit_mass, spring), 'callbacks')
  call ok(r%set_sensitivity(stiffness, GA_DEPENDS_FORCE), 'set_sensitivity')
  call ok(r%set_sensitivity_method(ior(GA_SENSITIVITY_FORWARD, GA_SENSITIVITY_ADJOINT), 1000), &
          'set_sensitivity_method')
  call ok(r%init(0.0d0, [1.0d0], [0.0d0]), 'init')
  do i = 1, 1000
     call ok(r%step(1d-3), 'step with the record')
  end do
  call ok(r%adjoint_gradient(x, q2(1:1), terminal=final_position), 'adjoint_gradient')
  call ok(r%get_sensitivity(1, q(1:1)), 'get_sensitivity')
  call expect(abs(q2(1) - q(1)) < 1d-12 * abs(q(1)), 'adjoint dJ/dk = forward dx/dk')
  ! with checkpoints every 30 steps: the same gradient, bit for bit
  call r%free()
  call ok(r%create(1, 0), 'create for adjoint checkpoints')
  call ok(r%set_callbacks(unit_mass, spring), 'callbacks')
  call ok(r%set_sensitivity(stiffness, GA_DEPENDS_FORCE), 'set_sensitivity')
  call ok(r%set_sensitivity_method(ior(GA_SENSITIVITY_FORWARD, GA_SENSITIVITY_ADJOINT), 1000), &
          'set_sensitivity_method')
  call ok(r%set_adjoint_checkpoints(30, 34), 'set_adjoint_checkpoints')
  call ok(r%init(0.0d0, [1.0d0], [0.0d0]), 'init')
  do i = 1, 1000
     call ok(r%step(1d-3), 'step with checkpoints')
  end do
  call ok(r%adjoint_gradient(am, v2(1:1), terminal=final_position), 'adjoint_gradient (checkpoints)')
  call expect(am == x .and. v2(1) == q2(1), 'checkpointed adjoint = full record')
  ! a parameter in the constraints, by differences and by the callback (index 2)
  do i = 0, 1
     call r%free()
     stiffness(1) = 0.5d0
     call ok(r%create(2, 1), 'create for a constraint parameter')
     call ok(r%set_callbacks(plane_mass, plane_force, rail, rail_jacobian), 'callbacks')
     call ok(r%set_formulation(GA_INDEX2_STABILIZED), 'index 2')
     call ok(r%set_resolution_check(0.02d0), 'set_resolution_check')
     call ok(r%check_derivatives(0.0d0, [0.5d0, 1.0d0], [0.0d0, 0.0d0], worst), &
          'check_derivatives')
     call expect(worst < 1d-6, 'check_derivatives: the callbacks agree with differences')
     call expect(r%set_resolution_check(0.0d0) == GA_ERR_ARG, 'set_resolution_check(0) refused')
     call ok(r%set_sensitivity(stiffness, ior(GA_DEPENDS_FORCE, GA_DEPENDS_CONSTRAINT)), &
          'set_sensitivity (constraint)')
     if (i == 1) call ok(r%set_constraint_parameter_derivative(rail_p), &
          'set_constraint_parameter_derivative')
     call ok(r%init(0.0d0, [0.5d0, 1.0d0], [0.0d0, 0.0d0]), 'init on the rail')
     do index = 1, 100
        call ok(r%step(1d-2), 'step on the rail')
     end do
     call ok(r%get_sensitivity(1, q(1:2), dlambda=v(1:1)), 'get_sensitivity (rail)')
     call expect(abs(q(1) - 1.0d0) < 1d-9 .and. abs(q(2)) < 1d-9, 'dq/dc = (1, 0)')
     call expect(abs(v(1) + 1.0d0) < 1d-8, 'dlambda/dc = -1')
  end do
  stiffness(1) = 4.0d0
  call expect(r%adjoint_gradient(x, q2(1:1)) == GA_ERR_ARG, 'adjoint_gradient needs a cost')
  ! operating points: the unit pendulum rests below its pivot and swings at sqrt(g / L)
  q2 = [0.3d0, -0.6d0]
  call ok(s%static_equilibrium(0.0d0, q2, lam2), 'static_equilibrium')
  call expect(abs(q2(1)) < 1d-14 .and. abs(q2(2) + 1.0d0) < 1d-14, 'equilibrium (0, -1)')
  call expect(abs(lam2(1) - 9.81d0) < 1d-12 * 9.81d0, 'multiplier m g / L')
  call ok(s%modes(0.0d0, q2, v2(1:1), lam2), 'modes')
  call expect(abs(v2(1) - 9.81d0) < 1d-8 * 9.81d0, 'omega^2 = g / L')
  call expect(s%modes(0.0d0, [0.6d0, -0.8d0], v2(1:1)) == GA_ERR_INCONSISTENT, &
       'modes away from an equilibrium refused')
  ! the first-order form at rest: x = (z, z'), A = [0, 1; -g / L, 0]; no states here
  block
    real(c_double) :: ass(2, 2), ynone(0)
    call ok(s%state_space(0.0d0, q2, n), 'state_space: its dimension')
    call expect(n == 2, 'state_space: 2 dof + 0 states')
    call ok(s%state_space(0.0d0, q2, n, lambda=lam2, a=ass), 'state_space')
    call expect(abs(ass(1, 2) - 1.0d0) < 1d-14 .and. abs(ass(2, 1) + 9.81d0) < 1d-8 * 9.81d0 &
         .and. abs(ass(1, 1)) < 1d-14 .and. abs(ass(2, 2)) < 1d-12, 'state_space: A')
    call ok(s%static_equilibrium_y(0.0d0, q2, ynone, lam2), 'static_equilibrium_y without states')
    call ok(s%state_space_motion(0.0d0, q2, [0.0d0, 0.0d0], n, a=ass), 'state_space_motion')
    call expect(abs(ass(2, 1) + 9.81d0) < 1d-7 * 9.81d0, 'state_space_motion at rest: -g / L')
  end block
  ! the same by shift-invert Lanczos (dense here: no patterns); two modes of one refused
  call ok(s%modes_near(0.0d0, q2, 0.0d0, v2(1:1), lam2), 'modes_near')
  call expect(abs(v2(1) - 9.81d0) < 1d-8 * 9.81d0, 'modes_near: omega^2 = g / L')
  call expect(s%modes_near(0.0d0, q2, 0.0d0, v2) == GA_ERR_ARG, &
       'modes_near: more modes than degrees of freedom refused')
  ! undamped: s = +-i sqrt(g / L), the positive imaginary part first
  call ok(s%modes_damped(0.0d0, q2, a, v), 'modes_damped')
  call expect(abs(a(1)) < 1d-12 .and. abs(v(1) - sqrt(9.81d0)) < 1d-8 .and. &
       abs(v(2) + sqrt(9.81d0)) < 1d-8, 'modes_damped: +-i sqrt(g / L)')
  block
    real(c_double) :: basis(2, 1), mr(1, 1), cr(1, 1), kr(1, 1)
    call ok(s%linearize(0.0d0, q2, n), 'linearize: its size')
    call expect(n == 1, 'one degree of freedom')
    call ok(s%linearize(0.0d0, q2, n, basis, mr, cr, kr, lam2), 'linearize')
    call expect(abs(abs(basis(1, 1)) - 1.0d0) < 1d-14 .and. abs(basis(2, 1)) < 1d-14, &
         'the free direction is horizontal')
    call expect(abs(kr(1, 1) / mr(1, 1) - 9.81d0) < 1d-8 * 9.81d0 .and. cr(1, 1) == 0.0d0, &
         'K / M = g / L, no damping')
  end block
  ! the static path: the pendulum under a horizontal load mu, its angle atan(mu / (m g))
  call r%free()
  call ok(r%create(2, 1), 'create for the static path')
  call ok(r%set_callbacks(p_mass, pushed_force, p_constraint, p_jacobian, c_loc(unit)), &
       'callbacks for the static path')
  q2 = [0.0d0, -1.0d0]
  push = 0.0d0
  call ok(r%static_path(0.0d0, push, q2, 0.1d0, 30, lam2), 'static_path')
  call expect(push > 1.0d0 .and. abs(atan2(q2(1), -q2(2)) - atan(push / 9.81d0)) < 1d-10, &
       'static_path: the angle of the horizontal load')

  ! the rotation maps: a quarter turn about z takes the body's x axis to space y (R(:, 1) =
  ! e_y, Fortran's column-major), its logarithm gives the turn back, a NaN is refused
  block
    real(c_double) :: psi(3), qz(4), rz(9), back3(3), tz(9), ti(9), two(8), prod(8)
    psi = [0.0d0, 0.0d0, 2.0d0 * atan(1.0d0)]
    call ok(galpha_so3_exp(psi, qz), 'so3_exp')
    call ok(galpha_so3_matrix(qz, rz), 'so3_matrix')
    call expect(abs(rz(1)) < 1d-15 .and. abs(rz(2) - 1.0d0) < 1d-15 .and. abs(rz(3)) < 1d-15, &
                'so3_matrix column-major')
    call ok(galpha_so3_log(qz, back3), 'so3_log')
    call expect(maxval(abs(back3 - psi)) < 1d-15, 'so3_log inverts so3_exp')
    call ok(galpha_so3_tangent(psi, tz), 'so3_tangent')
    call expect(abs(tz(1) - sin(psi(3)) / psi(3)) < 1d-15, 'so3_tangent T(1, 1)')
    call ok(galpha_so3_tangent_inverse(psi, ti), 'so3_tangent_inverse')
    call expect(abs(sum(reshape(tz, [3, 3]) * transpose(reshape(ti, [3, 3]))) - 3.0d0) < 1d-14, &
                'so3_tangent_inverse: trace of T T^-1')
    ! two quarter turns about z in one call each: their product is a half turn
    two = [qz, qz]
    call ok(galpha_so3_compose(two(1:4), two(5:8), prod(1:4)), 'so3_compose')
    call expect(abs(prod(1)) < 1d-15 .and. abs(abs(prod(4)) - 1.0d0) < 1d-15, 'so3_compose')
    call expect(galpha_so3_compose(two, two(1:4), prod) == GA_ERR_ARG, 'so3_compose sizes')
    call expect(galpha_so3_exp(psi(1:2), qz) == GA_ERR_ARG, 'so3_exp: not whole items')
    psi(2) = ieee_value(psi(2), ieee_quiet_nan)
    call expect(ga_so3_exp(1_c_long, psi, qz) == GA_ERR_ARG, 'so3_exp refuses a NaN')
  end block

  ! the pose maps: a screw of a quarter turn about z with translation 1 along x moves the
  ! origin to (2/pi, 2/pi, 0) (V(w) u, u = e_x); log gives the twist back; T T^-1 = I;
  ! the pose of an unnormalized quaternion and a short array are refused
  block
    real(c_double) :: xi(6), p(7), back6(6), t6(36), ti6(36), pp(7)
    real(c_double), parameter :: two_pi = 8.0d0 * atan(1.0d0)
    xi = [1.0d0, 0.0d0, 0.0d0, 0.0d0, 0.0d0, two_pi / 4.0d0]
    call ok(galpha_se3_exp(xi, p), 'se3_exp')
    call expect(abs(p(1) - 4.0d0 / two_pi) < 1d-15 .and. abs(p(2) - 4.0d0 / two_pi) < 1d-15 &
                .and. abs(p(3)) < 1d-15, 'se3_exp: the screw moves the origin by V(w) u')
    call ok(galpha_se3_log(p, back6), 'se3_log')
    call expect(maxval(abs(back6 - xi)) < 1d-15, 'se3_log inverts se3_exp')
    call ok(galpha_se3_tangent(xi, t6), 'se3_tangent')
    call ok(galpha_se3_tangent_inverse(xi, ti6), 'se3_tangent_inverse')
    call expect(maxval(abs(matmul(reshape(t6, [6, 6]), reshape(ti6, [6, 6])) - &
                reshape([(merge(1.0d0, 0.0d0, mod(index, 7) == 1), index = 1, 36)], [6, 6]))) &
                < 1d-14, 'se3_tangent_inverse inverts se3_tangent')
    call ok(galpha_se3_compose(p, p, pp), 'se3_compose')
    call expect(abs(pp(1)) < 1d-15 .and. abs(pp(2) - 8.0d0 / two_pi) < 1d-15, &
                'se3_compose: two quarter screws, the origin at (0, 4/pi, 0)')
    call expect(galpha_se3_tangent(xi, t6(1:35)) == GA_ERR_ARG, 'se3_tangent: room')
    p(4) = 1.1d0
    call expect(galpha_se3_log(p, back6) == GA_ERR_ARG, 'se3_log refuses a non-unit pose')
  end block

  call s%free()
  call r%free()
  deallocate (ckpt, back)  ! (a main program's allocatables are never freed on their own)
  x = s%h_last()
  call expect(x /= x .and. s%state_size() == -1, 'freed solver')
  print '(a)', 'test_layer: all checks passed'

contains

  ! x(1) at t = 1 of x'' = -k x from x = 1 at rest, 1000 steps, full Newton
  real(c_double) function spring_run(k) result(x1)
    real(c_double), intent(in) :: k
    type(galpha_solver) :: w
    real(c_double) :: xq(1)
    integer :: step
    stiffness(1) = k
    call ok(w%create(1, 0), 'create')
    call ok(w%set_callbacks(unit_mass, spring), 'callbacks')
    call ok(w%set_jacobian_reuse(GA_REUSE_NEVER), 'full Newton')
    call ok(w%init(0.0d0, [1.0d0], [0.0d0]), 'init')
    do step = 1, 1000
       call ok(w%step(1d-3), 'step')
    end do
    call ok(w%get_q(xq), 'get_q')
    x1 = xq(1)
    call w%free()
  end function spring_run

  subroutine ok(status, what)
    integer(c_int), intent(in) :: status
    character(*), intent(in) :: what
    if (status /= GA_OK) then
       print '(a)', what // ': ' // galpha_strerror(status)
       error stop 1
    end if
  end subroutine ok

  subroutine expect(cond, what)
    logical, intent(in) :: cond
    character(*), intent(in) :: what
    if (.not. cond) then
       print '(a)', 'FAILED: ' // what
       error stop 1
    end if
  end subroutine expect
end program test_layer
