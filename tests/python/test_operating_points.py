"""Operating points from Python (Solver.static_equilibrium, linearize, modes): the double
pendulum in Cartesian coordinates against its closed-form frequencies, the refusals as
exceptions."""
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

G = 9.81
M1, M2, L1, L2 = 1.3, 0.6, 0.9, 1.4


def mass(t, q, M):
    M[:] = np.diag([M1, M1, M2, M2])


def force(t, q, v, f):
    f[:] = (0.0, -M1 * G, 0.0, -M2 * G)


def constraint(t, q, phi):
    d1, d2 = q[:2], q[2:] - q[:2]
    phi[:] = (0.5 * (d1 @ d1 - L1 * L1), 0.5 * (d2 @ d2 - L2 * L2))


def jacobian(t, q, J):
    d1, d2 = q[:2], q[2:] - q[:2]
    J[:] = 0.0
    J[0, :2] = d1
    J[1, :2] = -d2
    J[1, 2:] = d2


def stiffness(t, q, v, qdd, lam, K):  # sum of lambda_i Hess(Phi_i)
    K[:] = 0.0
    K[:2, :2] = (lam[0] + lam[1]) * np.eye(2)
    K[2:, 2:] = lam[1] * np.eye(2)
    K[:2, 2:] = K[2:, :2] = -lam[1] * np.eye(2)


def closed_form():
    """det(K - w^2 M) = 0 in the two angles"""
    a = M1 * M2 * L1 ** 2 * L2 ** 2
    b = -(M1 + M2) * M2 * G * L1 * L2 * (L1 + L2)
    c = (M1 + M2) * M2 * G ** 2 * L1 * L2
    return np.sort(np.roots([a, b, c]).real)


@pytest.fixture
def solver():
    with galpha.Solver(4, 2, mass, force, constraint, jacobian, stiffness=stiffness) as s:
        yield s


def test_double_pendulum_rests_and_vibrates_at_its_closed_form(solver):
    eq = solver.static_equilibrium([0.2, -0.7, -0.3, -2.0])
    assert isinstance(eq, galpha.Equilibrium)
    np.testing.assert_allclose(eq.q, [0.0, -L1, 0.0, -L1 - L2], atol=1e-14)
    np.testing.assert_allclose(eq.lam * [L1, L2], [(M1 + M2) * G, M2 * G], rtol=1e-13)
    modes = solver.modes(eq.q, eq.lam)
    np.testing.assert_allclose(modes.omega2, closed_form(), rtol=1e-12)
    np.testing.assert_allclose(modes.omega, np.sqrt(closed_form()), rtol=1e-12)
    # unit modal mass, M-orthogonal
    Mq = np.diag([M1, M1, M2, M2])
    np.testing.assert_allclose(modes.shapes.T @ Mq @ modes.shapes, np.eye(2), atol=1e-12)
    lin = solver.linearize(eq.q, eq.lam)
    assert lin.N.shape == (4, 2) and lin.K.shape == (2, 2)
    J = np.zeros((2, 4))
    jacobian(0.0, eq.q, J)
    np.testing.assert_allclose(J @ lin.N, 0.0, atol=1e-14)
    np.testing.assert_allclose(lin.N.T @ lin.N, np.eye(2), atol=1e-14)
    np.testing.assert_allclose(np.sort(np.linalg.eigvals(np.linalg.solve(lin.M, lin.K)).real),
                               closed_form(), rtol=1e-12)
    np.testing.assert_array_equal(lin.C, 0.0)
    # the inverted pendulum: an equilibrium too, with two unstable directions
    up = solver.modes([0.0, L1, 0.0, L1 + L2])
    assert up.omega2[0] < 0.0 and np.isnan(up.omega[0])


def test_refusals_raise(solver):
    with pytest.raises(galpha.InconsistentError, match="not an equilibrium"):
        solver.modes([L1 * np.sin(0.3), -L1 * np.cos(0.3), L1 * np.sin(0.3),
                      -L1 * np.cos(0.3) - L2])
    with pytest.raises(galpha.ArgumentError, match="2 degrees of freedom"):
        solver.modes([0.0, -L1, 0.0, -L1 - L2], count=3)
    with pytest.raises(ValueError):
        solver.static_equilibrium([0.0, 1.0])


def test_no_equilibrium_is_a_convergence_error():
    def pushed(t, q, v, f):
        f[0] = -(1.0 + q[0] ** 2)
    with galpha.Solver(1, 0, lambda t, q, M: M.fill(1.0), pushed) as s:
        with pytest.raises(galpha.ConvergenceError, match="no equilibrium"):
            s.static_equilibrium([0.25])
