"""Events from Python: Solver.set_events and integrate(events=..., dense_output=...), with
scipy's conventions. References: the pendulum's quarter period from the complete elliptic
integral (arithmetic-geometric mean), the time a whirled rope goes slack by quadrature of the
energy equation, and an RK4 solution of the angle equation -- none of them galpha."""
import math
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

G, L = 9.81, 1.0


def mass(t, q, M):
    M[...] = np.eye(2)


def force(t, q, v, f):
    f[:] = (0.0, -G)


def constraint(t, q, phi):
    phi[0] = 0.5 * (q @ q - L * L)


def jacobian(t, q, J):
    J[0, :] = q


def state(theta, omega):
    return (np.array([L * math.sin(theta), -L * math.cos(theta)]),
            np.array([L * omega * math.cos(theta), L * omega * math.sin(theta)]))


def quarter_period(theta0):
    a, b = 1.0, math.sqrt(1.0 - math.sin(theta0 / 2) ** 2)
    for _ in range(40):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.sqrt(L / G) * math.pi / (2 * a)


def rk4(theta, omega, t_end, steps=20000):
    h = t_end / steps
    f = lambda th, om: (om, -G / L * math.sin(th))  # noqa: E731
    for _ in range(steps):
        k1 = f(theta, omega)
        k2 = f(theta + h / 2 * k1[0], omega + h / 2 * k1[1])
        k3 = f(theta + h / 2 * k2[0], omega + h / 2 * k2[1])
        k4 = f(theta + h * k3[0], omega + h * k3[1])
        theta += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        omega += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return state(theta, omega)


def vertical(t, q, v, lam):
    return q[0]


T4 = quarter_period(math.pi / 2)
Q0, V0 = state(math.pi / 2, 0.0)


def run(**kw):
    return galpha.integrate(mass, force, constraint, jacobian, (0.0, 4.0 * T4), Q0, V0, m=1,
                            **kw)


def test_events_at_the_quarter_periods():
    r = run(h=1e-3, events=[vertical])
    assert r.success and r.status == 0
    t = r.t_events[0]
    assert t.shape == (2,)
    assert abs(t[0] - T4) < 3e-6 and abs(t[1] - 3 * T4) < 1e-5  # 1.7 h^2, 5 h^2 (C suite)
    # the states at the events: at the vertical, at the bottom's speed, moving left then right
    for k in range(2):
        assert abs(r.q_events[0][k][0]) < 1e-12
        assert abs(np.linalg.norm(r.v_events[0][k]) - math.sqrt(2 * G * L)) < 1e-3
    assert r.v_events[0][0][0] < 0 < r.v_events[0][1][0]
    assert np.array_equal(r.y_events[0], np.hstack([r.q_events[0], r.v_events[0]]))
    assert r.lam_events[0].shape == (2, 1)
    assert r.stats["event_evals"] > 0


def test_direction_picks_the_crossings():
    def rising(t, q, v, lam):
        return q[0]
    rising.direction = 1
    def falling(t, q, v, lam):  # noqa: E306
        return q[0]
    falling.direction = -1
    r = run(events=[rising, falling], tolerances=(1e-8, 1e-8),
            formulation=galpha.GA_INDEX2_STABILIZED)
    assert len(r.t_events[0]) == 1 and abs(r.t_events[0][0] - 3 * T4) < 1e-6
    assert len(r.t_events[1]) == 1 and abs(r.t_events[1][0] - T4) < 1e-6


def test_a_terminal_event_ends_the_run_at_its_state():
    vertical.terminal = True
    try:
        r = run(h=1e-3, events=vertical, t_eval=[0.1, 0.5, 1.0])
    finally:
        del vertical.terminal
    assert r.success and r.status == 1 and "terminal" in r.message
    assert len(r.t_events[0]) == 1
    assert list(r.t[:2]) == [0.1, 0.5] and r.t[-1] == r.t_events[0][0]
    assert np.array_equal(r.q[-1], r.q_events[0][0])
    assert np.array_equal(r.v[-1], r.v_events[0][0])


def test_terminal_after_a_count():
    def crossing(t, q, v, lam):
        return q[0]
    crossing.terminal = 2
    r = run(h=1e-3, events=[crossing])
    assert r.status == 1 and len(r.t_events[0]) == 2 and r.t[-1] == r.t_events[0][1]
    crossing.terminal = 0.5
    with pytest.raises(ValueError, match="a bool or a count >= 0"):
        run(h=1e-3, events=[crossing])
    crossing.terminal = -1
    with pytest.raises(ValueError, match="a bool or a count >= 0"):
        run(h=1e-3, events=[crossing])
    # scipy's falsy terminal: 0 never ends the run (it was refused)
    for never in (0, False, None):
        crossing.terminal = never
        r = run(h=1e-3, events=[crossing])
        assert r.status == 0 and len(r.t_events[0]) == 2 and r.t[-1] > r.t_events[0][1]


def test_slack_rope_on_the_multiplier():
    """Whirled from the bottom with u^2 = 3.5 g L the rope goes slack at cos theta = -1/2;
    the time to get there is the integral of L / |v| over theta (Simpson)."""
    u = math.sqrt(3.5 * G * L)
    theta_star = math.acos((2 * G * L - u * u) / (3 * G * L))
    th = np.linspace(0.0, theta_star, 20001)
    f = L / np.sqrt(u * u - 2 * G * L * (1 - np.cos(th)))
    d = th[1] - th[0]
    t_star = d / 3 * (f[0] + f[-1] + 4 * f[1:-1:2].sum() + 2 * f[2:-1:2].sum())

    def tension(t, q, v, lam):
        return lam[0]
    tension.terminal, tension.direction, tension.multipliers = True, -1, True
    q0, v0 = state(0.0, u / L)
    errors = []
    for h in (4e-3, 2e-3, 1e-3):
        r = galpha.integrate(mass, force, constraint, jacobian, (0.0, 2.0), q0, v0, h=h, m=1,
                             events=[tension])
        assert r.status == 1
        assert abs(r.lam_events[0][0][0]) < 1e-9
        errors.append(abs(r.t_events[0][0] - t_star))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(orders > 1.8) and np.all(orders < 2.2), (errors, orders)


def test_whole_run_interpolant():
    r = run(tolerances=(1e-7, 1e-7), formulation=galpha.GA_INDEX2_STABILIZED,
            dense_output=True)
    sol = r.sol
    assert sol.t_min == 0.0 and sol.t_max == r.t[-1]
    # at the steps: the recorded values
    y = sol(r.t)
    assert y.shape == (4, len(r.t))
    assert np.allclose(y[:2].T, r.q, rtol=0, atol=1e-15)
    # between them: the exact motion to the run's accuracy
    worst = 0.0
    for t in np.linspace(0.05, 3.9 * T4, 23):
        q, v = rk4(math.pi / 2, 0.0, t)
        worst = max(worst, np.abs(sol.q(t) - q).max(), np.abs(sol.v(t) - v).max() / 10)
        assert sol(t).shape == (4,)
    assert worst < 1e-4, worst
    with pytest.raises(ValueError, match="outside the run"):
        sol(5.0 * T4)


def test_solver_level_events_and_failures():
    with galpha.Solver(2, 1, mass, force, constraint, jacobian, tolerances=(1e-8, 1e-8),
                       formulation=galpha.GA_INDEX2_STABILIZED) as s:
        s.init(0.0, Q0, V0)
        vertical.terminal = True
        try:
            s.set_events([vertical])
        finally:
            del vertical.terminal
        assert s.advance(10.0) is True
        (te, k, d), = s.events
        assert k == 0 and d == -1 and abs(te - T4) < 1e-6
        q, v, _ = s.interpolate(te)
        assert abs(q[0]) < 1e-12
        # an exception inside an event function: re-raised, the state as it was
        t_before, q_before = s.t, s.q

        def broken(t, q, v, lam):
            raise KeyError("inside the event function")
        s.set_events([broken])
        with pytest.raises(KeyError):
            s.advance(10.0)
        assert s.t == t_before and np.array_equal(s.q, q_before)
        s.set_events([lambda t, q, v, lam: float("nan")])
        with pytest.raises(galpha.NonFiniteError, match="event function"):
            s.step(1e-3)
        s.set_events([])
        assert s.advance(2.0) is False and s.events == []
        with pytest.raises(TypeError):
            s.set_events([3.0])


@pytest.mark.parametrize("value, shown", [(None, "None"), ("0.5", "'0.5'"),
                                          (np.array([0.1, 0.2]), "array")])
def test_an_event_function_returning_no_number_is_named(value, shown):
    """None was reported as "g[0] = nan is not finite", a string "0.5" taken as 0.5, an array of
    two values gave numpy's bare "setting an array element with a sequence"."""
    def odd(t, q, v, lam):
        return value
    with galpha.Solver(2, 1, mass, force, constraint, jacobian) as s:
        s.init(0.0, *state(0.5, 0.0))
        s.set_events([odd])
        with pytest.raises(TypeError, match=r"event function 0 \(odd\) returned %s.*expected "
                           r"one number" % shown):
            s.step(1e-2)
