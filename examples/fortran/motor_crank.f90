! The slider-crank driven by a DC motor under a PI speed controller, in Fortran: the model of
! examples/scenes/slider_crank_motor.c (same data, same numbers as examples/motor_crank.c).
! The motor current i and the controller's integral z are first-order states y = (i, z).
module motor_model
  use, intrinsic :: iso_c_binding
  use slider_crank_model
  implicit none
  integer, parameter :: r = 2, I_ = 1, Z_ = 2
  real(c_double), parameter :: kt = 0.3d0, ke = 0.3d0, res = 0.5d0, ind = 2d-3, &
       kp = 20.0d0, ki = 50.0d0, w_final = 4.0d0 * 3.14159265358979323846d0, tau = 0.1d0
contains
  real(c_double) function reference_speed(t)
    real(c_double), intent(in) :: t
    reference_speed = w_final * (1.0d0 - exp(-t / tau))
  end function reference_speed

  integer(c_int) function motor_force(t, q, v, y, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    motor_force = sc_force(t, q(1:n), v(1:n), f(1:n), user)
    f(TH1) = kt * y(I_)  ! the motor instead of the paper's constant torque
  end function motor_force

  integer(c_int) function motor_rate(t, q, v, y, ydot, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: ydot(*)
    type(c_ptr), value :: user
    real(c_double) :: w, error
    w = v(TH1)
    error = reference_speed(t) - w
    ydot(I_) = (kp * error + ki * y(Z_) - res * y(I_) - ke * w) / ind
    ydot(Z_) = error
    motor_rate = 0
  end function motor_rate

  integer(c_int) function motor_coupling(t, q, v, y, g_q, g_v, g_y, f_y, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), y(*)
    real(c_double), intent(out) :: g_q(*), g_v(*), g_y(*), f_y(*)  ! column-major, r = 2 rows
    type(c_ptr), value :: user
    g_q(1:r * n) = 0.0d0; g_v(1:r * n) = 0.0d0; g_y(1:r * r) = 0.0d0; f_y(1:n * r) = 0.0d0
    g_v(I_ + r * (TH1 - 1)) = -(kp + ke) / ind
    g_v(Z_ + r * (TH1 - 1)) = -1.0d0
    g_y(I_ + r * (I_ - 1)) = -res / ind
    g_y(I_ + r * (Z_ - 1)) = ki / ind
    f_y(TH1 + n * (I_ - 1)) = kt
    motor_coupling = 0
  end function motor_coupling
end module motor_model

program motor_crank
  use galpha
  use slider_crank_model
  use motor_model
  implicit none
  type(galpha_solver) :: s
  real(c_double) :: q(n), v(n), lambda(m), y(r)
  real(c_double), parameter :: h = 1.0d-3
  type(c_funptr) :: fm, fc, fj
  integer :: i

  call check(s%create(n, m), "create")
  fm = c_funloc(sc_mass)
  fc = c_funloc(sc_constraint)
  fj = c_funloc(sc_jacobian)
  call check(s%set_callbacks(fm, c_null_funptr, fc, fj), "set_callbacks")
  call check(ga_set_tangents(s%handle, c_funloc(sc_stiffness), c_null_funptr), "set_tangents")
  call check(ga_set_constraint_accel(s%handle, c_funloc(sc_accel)), "set_constraint_accel")
  call check(s%set_first_order(r, motor_rate, motor_force), "set_first_order")
  call check(s%set_coupling(motor_coupling), "set_coupling")
  call check(s%set_rho_inf(0.8d0), "set_rho_inf")
  call sc_initial_state(q, v)
  call check(s%init_y(0.0d0, q, v, [0.0d0, 0.0d0]), "init_y")
  do i = 1, 2000
     call check(s%step(h), "step")
  end do
  call check(s%get_q(q), "get_q")
  call check(s%get_lambda(lambda), "get_lambda")
  call check(s%get_y(y), "get_y")
  print '(a)', "Slider-crank driven by a DC motor with a PI speed controller (Fortran), " // &
       "rho_inf = 0.8, h = 1e-3, t = 2"
  print '(a, 10(1x, es25.17e3))', "final q =", q
  print '(a, 8(1x, es25.17e3))', "final lambda =", lambda
  print '(a, 2(1x, es25.17e3))', "final y =", y
  print '(a, i0, a, i0)', "steps = ", s%counter(GA_COUNT_STEPS), ", Newton iterations = ", &
       s%counter(GA_COUNT_NEWTON_ITERS)
  call s%free()
contains
  subroutine check(status, what)
    integer(c_int), intent(in) :: status
    character(len=*), intent(in) :: what
    if (status /= GA_OK) then
       print '(5a)', what, ": ", galpha_strerror(status), ": ", s%message()
       error stop 1
    end if
  end subroutine check
end program motor_crank
