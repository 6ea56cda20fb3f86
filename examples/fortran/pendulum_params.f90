! Model parameters through `user`: one set of callbacks, two pendulums of lengths 1 and 4 m.
! Each solver gets the address of its own parameter record (a bind(C) derived type); the
! callbacks turn it back into a Fortran pointer. The quarter period is located on the dense
! output (interpolate with q only) and compared with the small-amplitude series
! T/4 = (pi/2) sqrt(L/g) (1 + theta0^2/16 + 11 theta0^4/3072).
module params_model
  use, intrinsic :: iso_c_binding
  implicit none
  type, bind(C) :: pendulum_params
     real(c_double) :: mass, length, gravity
  end type pendulum_params
contains
  function params(user) result(p)
    type(c_ptr), value :: user
    type(pendulum_params), pointer :: p
    call c_f_pointer(user, p)
  end function params

  integer(c_int) function p_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: M(*)
    type(c_ptr), value :: user
    type(pendulum_params), pointer :: p
    p => params(user)
    M(1:4) = [p%mass, 0.0d0, 0.0d0, p%mass]
    p_mass = 0
  end function p_mass
  integer(c_int) function p_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    type(pendulum_params), pointer :: p
    p => params(user)
    f(1:2) = [0.0d0, -p%mass * p%gravity]
    p_force = 0
  end function p_force
  integer(c_int) function p_constraint(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: phi(*)
    type(c_ptr), value :: user
    type(pendulum_params), pointer :: p
    p => params(user)
    phi(1) = 0.5d0 * (q(1) * q(1) + q(2) * q(2) - p%length * p%length)
    p_constraint = 0
  end function p_constraint
  integer(c_int) function p_jacobian(t, q, J, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: J(*)
    type(c_ptr), value :: user
    J(1:2) = q(1:2)
    p_jacobian = 0
  end function p_jacobian
end module params_model

program pendulum_params_demo
  use galpha
  use params_model
  implicit none
  type(pendulum_params), target :: set(2)
  type(galpha_solver) :: s(2)
  real(c_double), parameter :: theta0 = 0.05d0, h = 1.0d-4
  real(c_double), parameter :: pi = 3.14159265358979323846d0
  real(c_double) :: quarter, expected, worst
  integer :: k

  set(1) = pendulum_params(1.0d0, 1.0d0, 9.81d0)
  set(2) = pendulum_params(1.0d0, 4.0d0, 9.81d0)
  worst = 0.0d0
  do k = 1, 2
     call check(s(k)%create(2, 1))
     call check(s(k)%set_callbacks(p_mass, p_force, p_constraint, p_jacobian, &
                                   user=c_loc(set(k))))
     call check(s(k)%set_rho_inf(0.9d0))
     ! released from rest at theta0 from the downward vertical
     call check(s(k)%init(0.0d0, set(k)%length * [sin(theta0), -cos(theta0)], [0.0d0, 0.0d0]))
     quarter = first_crossing(s(k))
     expected = 0.5d0 * pi * sqrt(set(k)%length / set(k)%gravity) * &
                (1.0d0 + theta0**2 / 16.0d0 + 11.0d0 * theta0**4 / 3072.0d0)
     print '(a, f4.1, a, f12.9, a, f12.9, a, es9.2)', 'L = ', set(k)%length, &
          ' m: quarter period ', quarter, ' s, series ', expected, ' s, relative error ', &
          abs(quarter - expected) / expected
     worst = max(worst, abs(quarter - expected) / expected)
     call s(k)%free()
  end do
  if (worst > 1.0d-7) error stop 'quarter periods off the series'

contains

  subroutine check(status)
    integer(c_int), intent(in) :: status
    if (status /= GA_OK) then
       print '(a)', 'galpha: ' // galpha_strerror(status)
       error stop 1
    end if
  end subroutine check

  ! The time x first reaches 0: steps until x changes sign, then bisection on the dense output.
  real(c_double) function first_crossing(solver) result(tc)
    type(galpha_solver), intent(inout) :: solver
    real(c_double) :: q(2), lo, hi, mid
    integer :: i
    do
       call check(solver%step(h))
       call check(solver%get_q(q))
       if (q(1) <= 0.0d0) exit
    end do
    hi = solver%t()
    lo = hi - solver%h_last()
    do i = 1, 60
       mid = 0.5d0 * (lo + hi)
       call check(solver%interpolate(mid, q=q))
       if (q(1) > 0.0d0) then
          lo = mid
       else
          hi = mid
       end if
    end do
    tc = 0.5d0 * (lo + hi)
  end function first_crossing
end program pendulum_params_demo
