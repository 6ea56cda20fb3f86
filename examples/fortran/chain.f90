! The chain of examples/chain.c in Fortran, on the sparse path: N rigid links in absolute
! coordinates (x, y, theta per link), sparsity patterns declared with Fortran (1-based) indices,
! callbacks that fill the values of those patterns. 100 steps of 1e-3, index 3. Usage:
! chain_fortran [links] (default 200); prints the final q and lambda with 17 digits, as
! `chain_demo links --print` does, for the cross-language test.
module chain_model
  use, intrinsic :: iso_c_binding
  implicit none
  integer :: links = 200
  real(c_double), parameter :: length = 1.0d0, mass = 1.0d0, gravity = 9.81d0
  real(c_double), parameter :: inertia = mass * length * length / 12.0d0, half = 0.5d0 * length
contains
  integer(c_int) function c_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: M(*)   ! the diagonal: 3 N values
    type(c_ptr), value :: user
    integer :: i
    do i = 0, links - 1
       M(3 * i + 1 : 3 * i + 3) = [mass, mass, inertia]
    end do
    c_mass = 0
  end function c_mass

  integer(c_int) function c_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: f(*)
    type(c_ptr), value :: user
    integer :: i
    do i = 0, links - 1
       f(3 * i + 1 : 3 * i + 3) = [0.0d0, -mass * gravity, 0.0d0]
    end do
    c_force = 0
  end function c_force

  ! joint i: start of link i minus the end of link i-1 (the pin for i = 0)
  integer(c_int) function c_constraint(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: phi(*)
    type(c_ptr), value :: user
    integer :: i
    real(c_double) :: ex, ey
    do i = 0, links - 1
       ex = q(3 * i + 1) - half * cos(q(3 * i + 3))
       ey = q(3 * i + 2) - half * sin(q(3 * i + 3))
       if (i > 0) then
          ex = ex - (q(3 * i - 2) + half * cos(q(3 * i)))
          ey = ey - (q(3 * i - 1) + half * sin(q(3 * i)))
       end if
       phi(2 * i + 1) = ex
       phi(2 * i + 2) = ey
    end do
    c_constraint = 0
  end function c_constraint

  ! values in the order of jacobian_pattern: per joint the x row (x_i, th_i, x_i-1, th_i-1),
  ! then the y row
  integer(c_int) function c_jacobian(t, q, J, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*)
    real(c_double), intent(out) :: J(*)
    type(c_ptr), value :: user
    integer :: i, k
    k = 0
    do i = 0, links - 1
       if (i == 0) then
          J(k + 1 : k + 4) = [1.0d0, half * sin(q(3)), 1.0d0, -half * cos(q(3))]
          k = k + 4
       else
          J(k + 1 : k + 8) = [1.0d0, half * sin(q(3 * i + 3)), -1.0d0, half * sin(q(3 * i)), &
                              1.0d0, -half * cos(q(3 * i + 3)), -1.0d0, -half * cos(q(3 * i))]
          k = k + 8
       end if
    end do
    c_jacobian = 0
  end function c_jacobian

  ! d(Phi_q^T lambda)/dth_i: theta_i enters joint i and joint i+1
  integer(c_int) function c_stiffness(t, q, v, qdd, lambda, K, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*), qdd(*), lambda(*)
    real(c_double), intent(out) :: K(*)
    type(c_ptr), value :: user
    integer :: i
    real(c_double) :: lx, ly
    do i = 0, links - 1
       lx = lambda(2 * i + 1)
       ly = lambda(2 * i + 2)
       if (i + 1 < links) then
          lx = lx + lambda(2 * i + 3)
          ly = ly + lambda(2 * i + 4)
       end if
       K(i + 1) = half * (cos(q(3 * i + 3)) * lx + sin(q(3 * i + 3)) * ly)
    end do
    c_stiffness = 0
  end function c_stiffness

  integer(c_int) function c_constraint_accel(t, q, v, out, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(*), v(*)
    real(c_double), intent(out) :: out(*)
    type(c_ptr), value :: user
    integer :: i
    real(c_double) :: w, wp, ax, ay
    do i = 0, links - 1
       w = v(3 * i + 3) * v(3 * i + 3)
       ax = half * cos(q(3 * i + 3)) * w
       ay = half * sin(q(3 * i + 3)) * w
       if (i > 0) then
          wp = v(3 * i) * v(3 * i)
          ax = ax + half * cos(q(3 * i)) * wp
          ay = ay + half * sin(q(3 * i)) * wp
       end if
       out(2 * i + 1) = ax
       out(2 * i + 2) = ay
    end do
    c_constraint_accel = 0
  end function c_constraint_accel

  ! Phi_q: rows 2i+1 (x) and 2i+2 (y) of joint i, 1-based
  subroutine jacobian_pattern(rows, cols)
    integer(c_int), allocatable, intent(out) :: rows(:), cols(:)
    integer :: i, d, k
    allocate(rows(8 * links - 4), cols(8 * links - 4))
    k = 0
    do i = 0, links - 1
       do d = 1, 2
          rows(k + 1 : k + 2) = 2 * i + d
          cols(k + 1 : k + 2) = [3 * i + d, 3 * i + 3]
          k = k + 2
          if (i > 0) then
             rows(k + 1 : k + 2) = 2 * i + d
             cols(k + 1 : k + 2) = [3 * i - 3 + d, 3 * i]
             k = k + 2
          end if
       end do
    end do
  end subroutine jacobian_pattern
end module chain_model

program chain
  use galpha
  use chain_model
  implicit none
  type(galpha_solver) :: s
  real(c_double), allocatable :: q(:), v(:), lambda(:)
  integer(c_int), allocatable :: rows(:), cols(:), diagonal(:), angles(:), none(:)
  character(len=32) :: arg
  integer :: i, n, m

  if (command_argument_count() >= 1) then
     call get_command_argument(1, arg)
     read (arg, *) links
  end if
  n = 3 * links
  m = 2 * links
  allocate(q(n), v(n), lambda(m), none(0))
  diagonal = [(i, i = 1, n)]
  angles = [(3 * i, i = 1, links)]
  call jacobian_pattern(rows, cols)

  call check(s%create(n, m), "create")
  ! M in compressed-column form, as sparse libraries hold it: column j holds row j
  call check(s%set_pattern_csc(GA_MATRIX_MASS, [(i, i = 1, n + 1)], diagonal), &
       "set_pattern_csc M")
  call check(s%set_pattern(GA_MATRIX_JACOBIAN, rows, cols), "set_pattern Phi_q")
  call check(s%set_pattern(GA_MATRIX_STIFFNESS, angles, angles), "set_pattern K_t")
  call check(s%set_pattern(GA_MATRIX_DAMPING, none, none), "set_pattern C_t")  ! C_t = 0
  call check(s%set_callbacks(c_mass, c_force, c_constraint, c_jacobian), "set_callbacks")
  call check(s%set_tangents(stiffness=c_stiffness), "set_tangents")
  call check(s%set_constraint_accel(c_constraint_accel), "set_constraint_accel")
  call check(s%set_constant_mass(.true.), "set_constant_mass")
  q = 0.0d0
  q(1::3) = [((i - 0.5d0) * length, i = 1, links)]  ! straight, horizontal, at rest
  v = 0.0d0
  call check(s%init(0.0d0, q, v), "init")
  do i = 1, 100
     call check(s%step(1.0d-3), "step")
  end do
  call check(s%get_q(q), "get_q")
  call check(s%get_lambda(lambda), "get_lambda")
  print '(a, i0, 3a)', "chain of ", links, " links in Fortran (", s%linear_solver_name(), ")"
  print '(a, *(1x, es25.17e3))', "final q =", q
  print '(a, *(1x, es25.17e3))', "final lambda =", lambda
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
end program chain
