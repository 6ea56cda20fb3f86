! The heavy top on R^3 x SO(3) from Fortran (issue 36): create_space with a vector block and a
! quaternion, the joint x - R X = 0 as the constraint, the stabilized index 2; order 2 in the
! centre of mass at t = 0.5 against an independent reference written here (RK4 on Euler's
! equations about the pivot with a rotation matrix, 100 000 steps). Exits non-zero on failure.
module lie_top_model
  use, intrinsic :: iso_c_binding
  implicit none
  real(c_double), parameter :: mass = 15.0d0, jc(3) = [0.234375d0, 0.46875d0, 0.234375d0]
  real(c_double), parameter :: xb(3) = [0.0d0, 1.0d0, 0.0d0], g(3) = [0.0d0, 0.0d0, -9.81d0]
  real(c_double), parameter :: omega0(3) = [0.0d0, 150.0d0, -4.61538d0]
contains
  ! (plain loops: gfortran 12 warns about matmul's temporaries at -O2 -Wuninitialized)
  pure function mv(A, x) result(y)
    real(c_double), intent(in) :: A(3, 3), x(3)
    real(c_double) :: y(3)
    integer :: i
    do i = 1, 3
       y(i) = A(i, 1) * x(1) + A(i, 2) * x(2) + A(i, 3) * x(3)
    end do
  end function mv

  pure function mm(A, B) result(C)
    real(c_double), intent(in) :: A(3, 3), B(3, 3)
    real(c_double) :: C(3, 3)
    integer :: j
    do j = 1, 3
       C(:, j) = mv(A, B(:, j))
    end do
  end function mm

  pure function cross(a, b) result(c)
    real(c_double), intent(in) :: a(3), b(3)
    real(c_double) :: c(3)
    c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
  end function cross

  pure function rotation(p) result(R)  ! of a unit quaternion (w, x, y, z)
    real(c_double), intent(in) :: p(4)
    real(c_double) :: R(3, 3)
    associate (w => p(1), x => p(2), y => p(3), z => p(4))
      R = reshape([1 - 2 * (y * y + z * z), 2 * (x * y + w * z), 2 * (x * z - w * y), &
                   2 * (x * y - w * z), 1 - 2 * (x * x + z * z), 2 * (y * z + w * x), &
                   2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], [3, 3])
    end associate
  end function rotation

  integer(c_int) function top_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(7)
    real(c_double), intent(out) :: M(6, 6)
    type(c_ptr), value :: user
    integer :: i
    M = 0.0d0
    do i = 1, 3
       M(i, i) = mass
       M(3 + i, 3 + i) = jc(i)
    end do
    top_mass = 0
  end function top_mass

  integer(c_int) function top_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(7), v(6)
    real(c_double), intent(out) :: f(6)
    type(c_ptr), value :: user
    f(1:3) = mass * g
    f(4:6) = -cross(v(4:6), jc * v(4:6))
    top_force = 0
  end function top_force

  integer(c_int) function top_constraint(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(7)
    real(c_double), intent(out) :: phi(3)
    type(c_ptr), value :: user
    phi = q(1:3) - mv(rotation(q(4:7)), xb)
    top_constraint = 0
  end function top_constraint

  integer(c_int) function top_jacobian(t, q, J, user) bind(C)  ! [I, R X~]
    real(c_double), value :: t
    real(c_double), intent(in) :: q(7)
    real(c_double), intent(out) :: J(3, 6)
    type(c_ptr), value :: user
    real(c_double) :: xh(3, 3)
    integer :: i
    xh = reshape([0.0d0, xb(3), -xb(2), -xb(3), 0.0d0, xb(1), xb(2), -xb(1), 0.0d0], [3, 3])
    J = 0.0d0
    do i = 1, 3
       J(i, i) = 1.0d0
    end do
    J(:, 4:6) = mm(rotation(q(4:7)), xh)
    top_jacobian = 0
  end function top_jacobian

  ! the reference: J_P w' = -w x J_P w + X x R^T m g, R' = R w~ (J_P diagonal here)
  subroutine rates(y, dy)
    real(c_double), intent(in) :: y(12)
    real(c_double), intent(out) :: dy(12)
    real(c_double) :: R(3, 3), w(3), jp(3), wh(3, 3)
    R = reshape(y(1:9), [3, 3])
    w = y(10:12)
    jp = jc + mass * (dot_product(xb, xb) - xb * xb)
    wh = reshape([0.0d0, w(3), -w(2), -w(3), 0.0d0, w(1), w(2), -w(1), 0.0d0], [3, 3])
    dy(1:9) = reshape(mm(R, wh), [9])
    dy(10:12) = (cross(xb, mv(transpose(R), mass * g)) - cross(w, jp * w)) / jp
  end subroutine rates

  function reference_com(t_end, steps) result(com)
    real(c_double), intent(in) :: t_end
    integer, intent(in) :: steps
    real(c_double) :: com(3), y(12), k1(12), k2(12), k3(12), k4(12), h
    integer :: s
    y = [1.0d0, 0.0d0, 0.0d0, 0.0d0, 1.0d0, 0.0d0, 0.0d0, 0.0d0, 1.0d0, omega0]
    h = t_end / steps
    do s = 1, steps
       call rates(y, k1)
       call rates(y + 0.5d0 * h * k1, k2)
       call rates(y + 0.5d0 * h * k2, k3)
       call rates(y + h * k3, k4)
       y = y + h / 6.0d0 * (k1 + 2 * k2 + 2 * k3 + k4)
    end do
    com = mv(reshape(y(1:9), [3, 3]), xb)
  end function reference_com
end module lie_top_model

program test_lie_top
  use galpha
  use lie_top_model
  implicit none
  type(galpha_solver) :: s
  real(c_double) :: q(7), v(6), ref(3), h(3), e(3), order
  integer :: i, k, failures
  type(c_funptr) :: fm, ff, fc, fj
  failures = 0
  fm = c_funloc(top_mass)  ! (assigned at run time: as constants they need text relocations)
  ff = c_funloc(top_force)
  fc = c_funloc(top_constraint)
  fj = c_funloc(top_jacobian)
  ref = reference_com(0.5d0, 100000)
  do i = 1, 3
     h(i) = 1.0d-3 / 2**(i - 1)
     call check(s%create_space([GA_SPACE_VECTOR, GA_SPACE_SO3_QUATERNION], [3, 1], 3), "create")
     if (s%nq /= 7 .or. s%n /= 6) call fail("sizes")
     call check(s%set_callbacks(fm, ff, fc, fj), "callbacks")
     call check(s%set_formulation(GA_INDEX2_STABILIZED), "formulation")
     q = [xb, 1.0d0, 0.0d0, 0.0d0, 0.0d0]
     v = [cross(omega0, xb), omega0]
     call check(s%init(0.0d0, q, v), "init")
     do k = 1, nint(0.5d0 / h(i))
        call check(s%step(h(i)), "step")
     end do
     call check(s%get_q(q), "get_q")
     e(i) = maxval(abs(q(1:3) - ref))
     call s%free()
  end do
  order = log(e(1) / e(3)) / log(h(1) / h(3))
  print '(a, 3es11.3, a, f6.3)', "centre of mass errors", e, ", order", order
  if (order < 1.9d0 .or. order > 2.1d0) call fail("order")
  ! a quaternion of norm 1.1 is refused
  call check(s%create_space([GA_SPACE_VECTOR, GA_SPACE_SO3_QUATERNION], [3, 1], 3), "create")
  call check(s%set_callbacks(fm, ff, fc, fj), "callbacks")
  q = [xb, 1.1d0, 0.0d0, 0.0d0, 0.0d0]
  if (s%init(0.0d0, q, v) /= GA_ERR_ARG) call fail("init with |q| = 1.1")
  if (s%create_space([GA_SPACE_VECTOR], [3, 1], 0) /= GA_ERR_ARG) call fail("sizes differ")
  call s%free()
  if (failures > 0) stop 1
contains
  subroutine check(status, what)
    integer(c_int), intent(in) :: status
    character(*), intent(in) :: what
    if (status /= GA_OK) call fail(what)
  end subroutine check
  subroutine fail(what)
    character(*), intent(in) :: what
    print '(2a)', "FAILED: ", what
    failures = failures + 1
  end subroutine fail
end program test_lie_top
