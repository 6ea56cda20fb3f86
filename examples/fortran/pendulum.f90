! The planar pendulum of examples/pendulum_demo.c, written in Fortran: same scene, same numbers.
! The callbacks follow the interfaces of module galpha exactly (arrays assumed-size).
module pendulum_model
  use, intrinsic :: iso_c_binding
  implicit none
  real(c_double), parameter :: mass = 1.0d0, length = 1.0d0, gravity = 9.81d0
contains
  integer(c_int) function p_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: M(*)
    type(c_ptr), value :: user
    M(1:4) = [mass, 0.0d0, 0.0d0, mass]
    p_mass = 0
  end function p_mass
  integer(c_int) function p_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    f(1:2) = [0.0d0, -mass * gravity]
    p_force = 0
  end function p_force
  integer(c_int) function p_constraint(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: phi(*)
    type(c_ptr), value :: user
    phi(1) = 0.5d0 * (q(1) * q(1) + q(2) * q(2) - length * length)
    p_constraint = 0
  end function p_constraint
  integer(c_int) function p_jacobian(t, q, J, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: J(*)
    type(c_ptr), value :: user
    J(1:2) = q(1:2)      ! 1 x 2
    p_jacobian = 0
  end function p_jacobian
end module pendulum_model

program pendulum
  use galpha
  use pendulum_model
  implicit none
  type(galpha_solver) :: s
  real(c_double) :: q(2), v(2), lambda(1)
  real(c_double), parameter :: h = 1.0d-3, theta0 = 1.0d0, omega0 = 0.5d0
  integer :: i

  call check(s%create(2, 1), "create")
  call check(s%set_callbacks(p_mass, p_force, p_constraint, p_jacobian), "set_callbacks")
  call check(s%set_rho_inf(0.9d0), "set_rho_inf")
  q = [length * sin(theta0), -length * cos(theta0)]
  v = [length * omega0 * cos(theta0), length * omega0 * sin(theta0)]
  call check(s%init(0.0d0, q, v), "init")
  do i = 1, 1000
     call check(s%step(h), "step")
  end do
  call check(s%get_q(q), "get_q")
  call check(s%get_lambda(lambda), "get_lambda")
  print '(2a)', "galpha (Fortran) ", galpha_version()
  print '(a, 2(1x, es25.17e3))', "final q =", q
  print '(a, 1(1x, es25.17e3))', "final lambda =", lambda
  print '(a, i0)', "steps = ", s%counter(GA_COUNT_STEPS)
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
end program pendulum
