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


def test_two_bar_truss_snaps_through_along_its_closed_curve():
    """The shallow von Mises truss, its apex on a rail: mu(y) = 2 EA (L0 - L) y / (L0 L)."""
    a, h, EA = 1.0, 0.2, 1000.0
    L0 = np.hypot(a, h)
    load = np.zeros(1)

    def force(t, q, v, f):
        f[:] = (0.0, -load[0])
        for side in (-1.0, 1.0):
            d = q - (side * a, 0.0)
            L = np.hypot(*d)
            f[:] -= EA * (L - L0) / L0 * d / L

    def closed(y):
        L = np.hypot(a, y)
        return 2.0 * EA * (L0 - L) * y / (L0 * L)
    with galpha.Solver(2, 1, lambda t, q, M: M.__setitem__(slice(None), np.eye(2)), force,
                       lambda t, q, phi: phi.__setitem__(0, q[0]),
                       lambda t, q, J: J.__setitem__(slice(None), [[1.0, 0.0]])) as s:
        path = s.static_path([0.0, h], load, 0.05, tol=1e-12,
                             stop=lambda mu, q, lam: q[1] < -1.5 * h)
    assert path.ended == "stopped" and len(path.load) > 100
    np.testing.assert_allclose(path.load, closed(path.q[:, 1]), atol=1e-10 * 3.0)
    assert np.all(np.diff(path.q[:, 1]) < 0.0)  # through the limit point, down and through
    ys = np.linspace(0.0, h, 20001)
    assert path.load[path.q[:, 1] > 0].max() <= closed(ys).max() * (1 + 1e-9)
    assert load[0] == path.load[-1]


def test_damped_modes_of_a_circulatory_force_flutter():
    """f = -K q, K = [2 1; -1 2]: s^2 = -(2 +- i), a growing pair"""
    def circulatory(t, q, v, f):
        f[:] = -np.array([[2.0, 1.0], [-1.0, 2.0]]) @ q
    with galpha.Solver(2, 0, lambda t, q, M: M.__setitem__(slice(None), np.eye(2)),
                       circulatory) as s:
        with pytest.raises(galpha.ArgumentError, match="not symmetric"):
            s.modes([0.0, 0.0])
        dm = s.damped_modes([0.0, 0.0])
    want = np.concatenate([np.sqrt(-(2 + 1j)) * np.array([1, -1]),
                           np.sqrt(-(2 - 1j)) * np.array([1, -1])])
    assert len(dm.s) == 4
    for root in dm.s:
        assert np.min(np.abs(want - root)) <= 1e-13
    assert np.sum(dm.s.real > 1e-6) == 2
    np.testing.assert_allclose(np.abs(dm.shapes).max(axis=0), 1.0, rtol=1e-14)


def test_modes_near_on_the_sparse_path_equal_the_closed_form():
    """The double pendulum with declared patterns (GA_LINEAR_SPARSE): the static solve on the
    saddle-point factorization and shift-invert Lanczos, against the closed form and `modes`."""
    patterns = {"mass": (np.arange(4), np.arange(4)),
                "jacobian": ([0, 0, 1, 1, 1, 1], [0, 1, 0, 1, 2, 3]),
                "stiffness": (np.tile(np.arange(4), 4), np.repeat(np.arange(4), 4)),
                "damping": ([], [])}

    def mass_v(t, q, M):
        M[:] = (M1, M1, M2, M2)

    def jacobian_v(t, q, J):
        d1, d2 = q[:2], q[2:] - q[:2]
        J[:] = (d1[0], d1[1], -d2[0], -d2[1], d2[0], d2[1])

    def stiffness_v(t, q, v, qdd, lam, K):
        D = np.zeros((4, 4))
        stiffness(t, q, v, qdd, lam, D)
        K[:] = D.ravel(order="F")

    with galpha.Solver(4, 2, mass_v, force, constraint, jacobian_v, stiffness=stiffness_v,
                       patterns=patterns, linear_solver=galpha.GA_LINEAR_SPARSE) as s:
        eq = s.static_equilibrium([0.2, -0.7, -0.3, -2.0])
        np.testing.assert_allclose(eq.q, [0.0, -L1, 0.0, -L1 - L2], atol=1e-14)
        near = s.modes_near(eq.q, count=2)
        assert isinstance(near, galpha.Modes)
        np.testing.assert_allclose(near.omega2, closed_form(), rtol=1e-10)
        Mq = np.diag([M1, M1, M2, M2])
        np.testing.assert_allclose(near.shapes.T @ Mq @ near.shapes, np.eye(2), atol=1e-12)
        # the shift picks the nearer: just below the higher one
        upper = s.modes_near(eq.q, eq.lam, sigma=0.9 * closed_form()[1], count=1)
        np.testing.assert_allclose(upper.omega2, closed_form()[1:], rtol=1e-10)
        with pytest.raises(galpha.InconsistentError, match="not an equilibrium"):
            s.modes_near([L1 * np.sin(0.3), -L1 * np.cos(0.3), L1 * np.sin(0.3),
                          -L1 * np.cos(0.3) - L2], count=1)
        with pytest.raises(galpha.ArgumentError, match="2 degrees of freedom"):
            s.modes_near(eq.q, count=3)


def test_first_order_states_at_rest_and_their_state_space():
    """A pendulum pushed horizontally by an actuator state y (y' = -y / tau + k x + u0): its
    rest from a scalar Newton in the angle, and the state space's invariants against the
    closed-form 3 x 3 linearization in (theta, theta', y)."""
    m, L, tau, k, u0, c = 1.3, 0.9, 0.5, 2.0, 3.0, 0.3

    def mass1(t, q, M):
        M[:] = m * np.eye(2)

    def constraint1(t, q, phi):
        phi[0] = 0.5 * (q @ q - L * L)

    def jacobian1(t, q, J):
        J[0, :] = q

    def stiffness1(t, q, v, qdd, lam, K):
        K[:] = lam[0] * np.eye(2)

    def damping1(t, q, v, C):
        C[:] = c * np.eye(2)

    def force_y(t, q, v, y, f):
        f[:] = (y[0] - c * v[0], -m * G - c * v[1])

    def rate(t, q, v, y, ydot):
        ydot[0] = -y[0] / tau + k * q[0] + u0

    th = 0.0
    for _ in range(50):
        F = tau * (k * L * np.sin(th) + u0) * np.cos(th) - m * G * np.sin(th)
        dF = (tau * k * L * np.cos(th) ** 2 - tau * (k * L * np.sin(th) + u0) * np.sin(th)
              - m * G * np.cos(th))
        th -= F / dF
    ystar = tau * (k * L * np.sin(th) + u0)
    with galpha.Solver(2, 1, mass1, None, constraint1, jacobian1, stiffness=stiffness1,
                       damping=damping1, r=1, rate=rate, force_y=force_y) as s:
        eq = s.static_equilibrium_y([0.1, -0.8], [0.0])
        assert isinstance(eq, galpha.EquilibriumY)
        np.testing.assert_allclose(eq.q, [L * np.sin(th), -L * np.cos(th)], atol=1e-13)
        np.testing.assert_allclose(eq.y, [ystar], rtol=1e-12)
        ss = s.state_space(eq.q, eq.y, eq.lam)
        assert ss.A.shape == (3, 3) and ss.N.shape == (2, 1)
        B = np.array([[0.0, 1.0, 0.0],
                      [-(ystar * np.sin(th) + m * G * np.cos(th)) / (m * L), -c / m,
                       np.cos(th) / (m * L)],
                      [k * L * np.cos(th), 0.0, -1.0 / tau]])
        np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(ss.A)),
                                   np.sort_complex(np.linalg.eigvals(B)), rtol=1e-8)
        with pytest.raises(ValueError, match="first-order states"):
            s.state_space(eq.q)


def test_state_space_along_a_motion_at_rest_equals_the_tangent_system(solver):
    """ga_state_space_motion at v = 0 in the equilibrium is ga_state_space's A (the same
    chart coordinates N); off the velocity constraint it raises."""
    eq = solver.static_equilibrium([0.2, -0.7, -0.3, -2.0])
    moving = solver.state_space_motion(eq.q, np.zeros(4))
    rest = solver.state_space(eq.q, lam=eq.lam)
    assert moving.A.shape == (4, 4)
    np.testing.assert_allclose(moving.N, rest.N, atol=1e-14)
    np.testing.assert_allclose(moving.A, rest.A, atol=1e-7 * np.abs(rest.A).max())
    with pytest.raises(galpha.InconsistentError, match="velocity constraint"):
        solver.state_space_motion(eq.q, [0.0, 1.0, 0.0, 0.0])


@pytest.mark.parametrize("q", [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
def test_operating_points_on_a_rotation_space_say_why(q):
    """On a space with rotations the operating points are refused for the space, whatever q
    is: the quaternion's four numbers were refused as "3 values expected, got 4"."""
    def body_mass(t, q, M):
        M[:] = np.eye(3)

    def no_torque(t, q, v, f):
        f[:] = 0.0
    with galpha.Solver(3, 0, body_mass, no_torque, space=[("so3", 1)]) as s:
        for call in (lambda: s.modes(q), lambda: s.static_equilibrium(q),
                     lambda: s.linearize(q)):
            with pytest.raises(galpha.StateError, match="R\\^n only"):
                call()
