! The planar pendulum with its parameters passed through `user`: the callbacks receive the
! address of a pendulum_params record (c_loc of a bind(C) derived type) and turn it back into
! a Fortran pointer. Used by examples/fortran/pendulum_params.f90 and tests/fortran.
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
