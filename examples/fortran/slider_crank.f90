! The paper's slider-crank (sec. 5.1) in Fortran (the model: slider_crank_model.f90).
program slider_crank
  use galpha
  use slider_crank_model
  implicit none
  type(galpha_solver) :: s
  real(c_double) :: q(n), v(n), lambda(m)
  real(c_double), parameter :: h = 5.0d-3
  type(c_funptr) :: fm, ff, fc, fj
  integer :: i

  call check(s%create(n, m), "create")
  fm = c_funloc(sc_mass)
  ff = c_funloc(sc_force)
  fc = c_funloc(sc_constraint)
  fj = c_funloc(sc_jacobian)
  call check(s%set_callbacks(fm, ff, fc, fj), "set_callbacks")
  call check(ga_set_tangents(s%handle, c_funloc(sc_stiffness), c_null_funptr), "set_tangents")
  call check(ga_set_constraint_accel(s%handle, c_funloc(sc_accel)), "set_constraint_accel")
  call check(s%set_rho_inf(0.7d0), "set_rho_inf")
  call sc_initial_state(q, v)
  call check(s%init(0.0d0, q, v), "init")
  do i = 1, 200
     call check(s%step(h), "step")
  end do
  call check(s%get_q(q), "get_q")
  call check(s%get_lambda(lambda), "get_lambda")
  print '(a)', "Slider-crank (Fortran), rho_inf = 0.7, h = 5e-3, t = 1"
  print '(a, 10(1x, es25.17e3))', "final q =", q
  print '(a, 8(1x, es25.17e3))', "final lambda =", lambda
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
end program slider_crank
