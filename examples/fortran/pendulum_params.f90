! Model parameters through `user`: one set of callbacks (params_model.f90), two pendulums of
! lengths 1 and 4 m, each solver with the address of its own parameter record. The quarter
! period is located on the dense output (interpolate with q only) and compared with the
! small-amplitude series T/4 = (pi/2) sqrt(L/g) (1 + theta0^2/16 + 11 theta0^4/3072).

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
