! The paper's slider-crank (sec. 5.1) written in Fortran: the model of
! examples/scenes/slider_crank.c, same data, same numbers, for slider_crank.f90 and
! motor_crank.f90. The callbacks are bind(C) procedures with explicit-shape arrays
! (M(10, 10), J(8, 10)), passed with c_funloc.
module slider_crank_model
  use, intrinsic :: iso_c_binding
  implicit none
  integer, parameter :: n = 10, m = 8
  integer, parameter :: X1 = 1, Y1 = 2, X2 = 3, Y2 = 4, TH1 = 5, TH2 = 6, X3 = 7, X4 = 8, &
       X5 = 9, Y5 = 10
  real(c_double), parameter :: k_spring = 1000.0d0, l1 = 0.3d0, l2 = 0.6d0, m1 = 0.36d0, &
       m2 = 0.15d0, m3 = 0.1d0, m4 = 0.7d0, torque = 1.0d0, rest_length = 0.3d0
contains
  integer(c_int) function sc_mass(t, q, M, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n)
    real(c_double), intent(out) :: M(n, n)
    type(c_ptr), value :: user
    M = 0.0d0
    M(X1, X1) = m1; M(Y1, Y1) = m1; M(X2, X2) = m2; M(Y2, Y2) = m2
    M(TH1, TH1) = m1 * l1 * l1 / 12.0d0
    M(TH2, TH2) = m2 * l2 * l2 / 12.0d0
    M(X3, X3) = m3; M(X4, X4) = m4
    sc_mass = 0
  end function sc_mass

  integer(c_int) function sc_force(t, q, v, f, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n), v(n)
    real(c_double), intent(out) :: f(n)
    type(c_ptr), value :: user
    real(c_double) :: spring
    spring = k_spring * (q(X4) - q(X3) - rest_length)
    f = 0.0d0
    f(TH1) = torque
    f(X3) = spring
    f(X4) = -spring
    sc_force = 0
  end function sc_force

  integer(c_int) function sc_constraint(t, q, phi, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n)
    real(c_double), intent(out) :: phi(m)
    type(c_ptr), value :: user
    real(c_double) :: c1, s1, c2, s2
    c1 = cos(q(TH1)); s1 = sin(q(TH1)); c2 = cos(q(TH2)); s2 = sin(q(TH2))
    phi(1) = q(X1) - 0.5d0 * l1 * c1
    phi(2) = q(Y1) - 0.5d0 * l1 * s1
    phi(3) = q(X5) - l1 * c1
    phi(4) = q(Y5) - l1 * s1
    phi(5) = q(X2) - q(X5) - 0.5d0 * l2 * c2
    phi(6) = q(Y2) - q(Y5) - 0.5d0 * l2 * s2
    phi(7) = q(X3) - q(X5) - l2 * c2
    phi(8) = q(Y5) + l2 * s2
    sc_constraint = 0
  end function sc_constraint

  integer(c_int) function sc_jacobian(t, q, J, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n)
    real(c_double), intent(out) :: J(m, n)
    type(c_ptr), value :: user
    real(c_double) :: c1, s1, c2, s2
    c1 = cos(q(TH1)); s1 = sin(q(TH1)); c2 = cos(q(TH2)); s2 = sin(q(TH2))
    J = 0.0d0
    J(1, X1) = 1.0d0; J(1, TH1) = 0.5d0 * l1 * s1
    J(2, Y1) = 1.0d0; J(2, TH1) = -0.5d0 * l1 * c1
    J(3, X5) = 1.0d0; J(3, TH1) = l1 * s1
    J(4, Y5) = 1.0d0; J(4, TH1) = -l1 * c1
    J(5, X2) = 1.0d0; J(5, X5) = -1.0d0; J(5, TH2) = 0.5d0 * l2 * s2
    J(6, Y2) = 1.0d0; J(6, Y5) = -1.0d0; J(6, TH2) = -0.5d0 * l2 * c2
    J(7, X3) = 1.0d0; J(7, X5) = -1.0d0; J(7, TH2) = l2 * s2
    J(8, Y5) = 1.0d0; J(8, TH2) = l2 * c2
    sc_jacobian = 0
  end function sc_jacobian

  integer(c_int) function sc_accel(t, q, v, out, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n), v(n)
    real(c_double), intent(out) :: out(m)
    type(c_ptr), value :: user
    real(c_double) :: c1, s1, c2, s2, w1, w2
    c1 = cos(q(TH1)); s1 = sin(q(TH1)); c2 = cos(q(TH2)); s2 = sin(q(TH2))
    w1 = v(TH1) * v(TH1); w2 = v(TH2) * v(TH2)
    out = [0.5d0 * l1 * c1 * w1, 0.5d0 * l1 * s1 * w1, l1 * c1 * w1, l1 * s1 * w1, &
           0.5d0 * l2 * c2 * w2, 0.5d0 * l2 * s2 * w2, l2 * c2 * w2, -l2 * s2 * w2]
    sc_accel = 0
  end function sc_accel

  integer(c_int) function sc_stiffness(t, q, v, qdd, lambda, K, user) bind(C)
    real(c_double), value :: t
    real(c_double), intent(in) :: q(n), v(n), qdd(n), lambda(m)
    real(c_double), intent(out) :: K(n, n)
    type(c_ptr), value :: user
    real(c_double) :: c1, s1, c2, s2
    c1 = cos(q(TH1)); s1 = sin(q(TH1)); c2 = cos(q(TH2)); s2 = sin(q(TH2))
    K = 0.0d0
    K(TH1, TH1) = 0.5d0 * l1 * c1 * lambda(1) + 0.5d0 * l1 * s1 * lambda(2) + &
                  l1 * c1 * lambda(3) + l1 * s1 * lambda(4)
    K(TH2, TH2) = 0.5d0 * l2 * c2 * lambda(5) + 0.5d0 * l2 * s2 * lambda(6) + &
                  l2 * c2 * lambda(7) - l2 * s2 * lambda(8)
    K(X3, X3) = k_spring; K(X3, X4) = -k_spring; K(X4, X3) = -k_spring; K(X4, X4) = k_spring
    sc_stiffness = 0
  end function sc_stiffness

  ! theta1 = pi/2, at rest, spring undeformed (as sc_initial in the C scene)
  subroutine sc_initial_state(q, v)
    real(c_double), intent(out) :: q(n), v(n)
    real(c_double), parameter :: pi = 3.14159265358979323846d0
    real(c_double) :: hinge_x, hinge_y, theta2
    hinge_x = l1 * cos(pi / 2); hinge_y = l1 * sin(pi / 2)
    theta2 = asin(-hinge_y / l2)
    q = 0.0d0; v = 0.0d0
    q(X1) = 0.5d0 * hinge_x; q(Y1) = 0.5d0 * hinge_y; q(TH1) = pi / 2; q(TH2) = theta2
    q(X5) = hinge_x; q(Y5) = hinge_y
    q(X2) = hinge_x + 0.5d0 * l2 * cos(theta2); q(Y2) = hinge_y + 0.5d0 * l2 * sin(theta2)
    q(X3) = hinge_x + l2 * cos(theta2); q(X4) = q(X3) + rest_length
  end subroutine sc_initial_state
end module slider_crank_model

