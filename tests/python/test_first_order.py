"""First-order states from Python (Solver(r=, rate=, force_y=, coupling=), init(..., y0),
y, ydot, interpolate_y): the linear electromechanical model of tests/c/test_first_order.c
against its exact solution, a matrix exponential computed here with numpy (scaling and
squaring of the Taylor series) -- not galpha."""
import math
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

# two masses joined rigidly, a spring and damper on the first, a DC motor's force on the
# second; the motor current i and a PI controller's integral z as first-order states
M1, M2, K, C, KT, L, R, KE, KP, KI, XR = 1.0, 0.5, 20.0, 0.5, 2.0, 0.05, 1.0, 2.0, 30.0, 40.0, 1.0


def mass(t, q, M):
    M[...] = np.diag([M1, M2])


def constraint(t, q, phi):
    phi[0] = q[0] - q[1]


def jacobian(t, q, J):
    J[0, :] = (1.0, -1.0)


def force_y(t, q, v, y, f):
    f[:] = (-K * q[0] - C * v[0], KT * y[0])


def rate(t, q, v, y, ydot):
    volt = -KP * (q[1] - XR) - KI * y[1]
    ydot[:] = ((volt - R * y[0] - KE * v[1]) / L, q[1] - XR)


def coupling(t, q, v, y, g_q, g_v, g_y, f_y):
    g_q[1, :] = (0.0, 1.0)
    g_q[0, :] = (0.0, -KP / L)
    g_v[0, :] = (0.0, -KE / L)
    g_y[0, :] = (-R / L, -KI / L)
    f_y[1, 0] = KT


def expm(A):
    s = max(0, int(math.ceil(math.log2(max(np.abs(A).sum(axis=1).max(), 1e-300) / 0.05))))
    B = A / 2.0 ** s
    E, term = np.eye(len(A)), np.eye(len(A))
    for k in range(1, 19):
        term = term @ B / k
        E = E + term
    for _ in range(s):
        E = E @ E
    return E


def exact(T):
    mt = M1 + M2
    A = np.array([[0, 1, 0, 0, 0],
                  [-K / mt, -C / mt, KT / mt, 0, 0],
                  [-KP / L, -KE / L, -R / L, -KI / L, KP * XR / L],
                  [1, 0, 0, 0, -XR],
                  [0, 0, 0, 0, 0]], dtype=float)
    x, v, i, z = expm(A * T)[:4, 4]
    return x, v, np.array([i, z])


def solver(**options):
    return galpha.Solver(2, 1, mass, None, constraint, jacobian, r=2, rate=rate,
                         force_y=force_y, **options)


@pytest.mark.parametrize("formulation", [galpha.GA_INDEX3, galpha.GA_INDEX2_STABILIZED])
def test_order_two_in_y_and_q(formulation):
    errors = []
    for N in (200, 400, 800):
        with solver(formulation=formulation) as s:
            s.init(0.0, np.zeros(2), np.zeros(2), np.zeros(2))
            for _ in range(N):
                s.step(1.0 / N)
            x, v, y = exact(1.0)
            errors.append((abs(s.q[0] - x), abs(s.v[0] - v), np.abs(s.y - y).max()))
    errors = np.array(errors)
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders > 1.9) & (orders < 2.1)), orders


def test_coupling_callback_and_differences_agree_and_dropping_it_costs_iterations():
    runs = {}
    for name, options in (("differences", {}), ("callback", {"coupling": coupling}),
                          ("loose", {"coupling": coupling, "coupling_exact": False})):
        with solver(reuse=galpha.GA_REUSE_NEVER, tangent_mode=galpha.GA_TANGENT_FD,
                    **options) as s:
            s.init(0.0, np.zeros(2), np.zeros(2), np.zeros(2))
            for _ in range(100):
                s.step(0.01)
            runs[name] = (s.y.copy(), s.stats["newton_iters"], s.stats["coupling_evals"])
    y_fd, y_cb, y_loose = (runs[k][0] for k in ("differences", "callback", "loose"))
    assert np.abs(y_fd - y_cb).max() < 1e-8 * np.abs(y_cb).max()
    assert np.abs(y_loose - y_cb).max() < 1e-8 * np.abs(y_cb).max()
    # full Newton: the blocks at every one of the two iterations per step
    assert runs["callback"][1] == 200 and runs["callback"][2] == 200
    assert runs["loose"][1] > 3 * runs["callback"][1]


def test_states_dense_output_and_restart():
    with solver() as s:
        s.init(0.0, np.zeros(2), np.zeros(2), np.zeros(2))
        assert s.r == 2
        ydot0 = s.ydot
        assert ydot0 == pytest.approx([KP * XR / L, -XR])
        for _ in range(10):
            s.step(0.01)
        y_mid, ydot_mid = s.interpolate_y(0.095)
        # within the steps' own error at h = 0.01 (about 1e-3 of |i|)
        assert np.abs(y_mid - exact(0.095)[2]).max() < 2e-3 * np.abs(y_mid).max()
        assert ydot_mid.shape == (2,)
        y_before = s.y
        s.init(s.t, s.q, np.zeros(2))  # a restart keeps the states it holds
        assert np.array_equal(s.y, y_before)
        assert "rate_evals" in s.stats


def test_refusals():
    with pytest.raises(galpha.ArgumentError, match="rate"):
        galpha.Solver(2, 1, mass, None, constraint, jacobian, r=2, force_y=force_y)
    with solver() as s:
        with pytest.raises(galpha.StateError, match="ga_init_y"):
            s.init(0.0, np.zeros(2), np.zeros(2))
        with pytest.raises(galpha.ArgumentError, match="y0"):
            s.init(0.0, np.zeros(2), np.zeros(2), np.zeros(3))

        def failing(t, q, v, y, ydot):
            raise ZeroDivisionError("from the rate")
        s2 = galpha.Solver(2, 1, mass, None, constraint, jacobian, r=2, rate=failing)
        with pytest.raises(ZeroDivisionError):
            s2.init(0.0, np.zeros(2), np.zeros(2), np.zeros(2))
        s2.close()


def test_integrate_with_states_and_an_event_on_them():
    # the current reaches 20 A (rising): the time from the exact solution by bisection
    lo, hi = 0.0, 0.095
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if exact(mid)[2][0] < 20.0 else (lo, mid)

    def limit(t, q, v, lam, y):
        return y[0] - 20.0
    limit.terminal, limit.direction = True, 1
    res = galpha.integrate(mass, None, constraint, jacobian, (0.0, 1.0), np.zeros(2),
                           np.zeros(2), m=1, y0=np.zeros(2), r=2, rate=rate, force_y=force_y,
                           events=limit, tolerances=(1e-8, 1e-8),
                           formulation=galpha.GA_INDEX2_STABILIZED)
    assert res.status == 1 and res.states.shape == (len(res.t), 2)
    assert abs(res.t_events[0][0] - 0.5 * (lo + hi)) < 1e-6
    assert res.states_events[0][0][0] == pytest.approx(20.0, abs=1e-9)
    assert res.states[-1][0] == pytest.approx(20.0, abs=1e-9)
    # the recorded states against the exact solution along the run
    worst = max(np.abs(x - exact(t)[2]).max() for t, x in zip(res.t, res.states))
    assert worst < 1e-5

    # at fixed outputs
    res = galpha.integrate(mass, None, constraint, jacobian, (0.0, 0.5), np.zeros(2),
                           np.zeros(2), 1e-3, m=1, y0=np.zeros(2), r=2, rate=rate,
                           force_y=force_y, t_eval=[0.0, 0.25, 0.5])
    assert res.states.shape == (3, 2)
    assert np.abs(res.states[1] - exact(0.25)[2]).max() < 1e-3 * np.abs(exact(0.25)[2]).max()


def test_coupling_patterns_give_the_same_run_with_fewer_rate_calls():
    runs = []
    for patterns in (None, {"g_q": ([0, 1], [1, 1]), "g_v": ([0], [1])}):
        with solver(coupling_patterns=patterns) as s:
            s.init(0.0, np.zeros(2), np.zeros(2), np.zeros(2))
            for _ in range(50):
                s.step(0.01)
            runs.append((s.y.copy(), s.stats["rate_evals"], s.stats["coupling_evals"]))
    (y0, rates0, blocks0), (y1, rates1, blocks1) = runs
    assert np.array_equal(y0, y1) and blocks0 == blocks1
    # each evaluation: 2 n = 4 columns by differences, 2 with the patterns
    assert rates0 - rates1 == 2 * blocks0
    with pytest.raises(ValueError, match="coupling block"):
        solver(coupling_patterns={"f_y": ([0], [0])})
