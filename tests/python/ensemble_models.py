"""Models for test_ensemble.py, at module level so that worker processes import them by name."""
import math

import numpy as np

import galpha


def pendulum():
    """A pendulum of length p[0] under gravity p[1], released from 1 rad; Python callbacks. It
    raises for a negative gravity (a run that fails in a callback); the summary is the largest
    multiplier seen by a step hook."""
    p = np.array([1.0, 9.81])
    peak = [0.0]

    def mass(t, q, M):
        M[0, 0] = M[1, 1] = 1.0

    def force(t, q, v, f):
        if p[1] < 0:
            raise ValueError("negative gravity")
        f[1] = -p[1]

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p[0] * p[0])

    def jacobian(t, q, J):
        J[0, 0], J[0, 1] = q[0], q[1]

    def start(p):
        peak[0] = 0.0
        return 0.0, [p[0] * math.sin(1.0), -p[0] * math.cos(1.0)], [0.0, 0.0]

    def hook(t, q, v, lam):
        peak[0] = max(peak[0], abs(lam[0]))

    s = galpha.Solver(2, 1, mass, force, constraint, jacobian, tolerances=(1e-5, 1e-5),
                      formulation=galpha.GA_INDEX2_STABILIZED)
    s.set_step_hook(hook, multipliers=True)
    return galpha.ensemble.Case(s, p, start=start,
                                summary=lambda s: {"peak_lambda": peak[0], "energy": 0.5 *
                                                   float(s.v @ s.v) + p[1] * s.q[1]})


def compiled_pendulum():
    """The same pendulum with numba-compiled callbacks and step hook (no Python in a step):
    p = (length, gravity, peak multiplier), the hook's peak kept in p[2]."""
    from numba import carray, cfunc, types
    dp, vp = types.CPointer(types.float64), types.voidptr
    p = np.array([1.0, 9.81, 0.0])
    mass, force, constraint, jacobian, hook = _compiled(carray, cfunc, types, dp, vp)

    def start(p):
        p[2] = 0.0
        return 0.0, [p[0] * math.sin(1.0), -p[0] * math.cos(1.0)], [0.0, 0.0]

    s = galpha.Solver(2, 1, mass, force, constraint, jacobian, user=p, tolerances=(1e-5, 1e-5),
                      formulation=galpha.GA_INDEX2_STABILIZED)
    s.set_step_hook(hook, multipliers=True)
    # the parameters are p[:2], a view: the callbacks read them in p
    return galpha.ensemble.Case(s, p[:2], start=lambda _: start(p),
                                summary=lambda s: {"peak_lambda": p[2]})


_cfuncs = None


def _compiled(carray, cfunc, types, dp, vp):
    global _cfuncs
    if _cfuncs is not None:
        return _cfuncs

    @cfunc(types.int32(types.float64, dp, dp, vp))
    def mass(t, q, M, user):
        out = carray(M, 4)
        out[0], out[1], out[2], out[3] = 1.0, 0.0, 0.0, 1.0
        return 0

    @cfunc(types.int32(types.float64, dp, dp, dp, vp))
    def force(t, q, v, f, user):
        p, out = carray(user, 3, np.float64), carray(f, 2)
        out[0], out[1] = 0.0, -p[1]
        return 0

    @cfunc(types.int32(types.float64, dp, dp, vp))
    def constraint(t, q, phi, user):
        p, x = carray(user, 3, np.float64), carray(q, 2)
        carray(phi, 1)[0] = 0.5 * (x[0] * x[0] + x[1] * x[1] - p[0] * p[0])
        return 0

    @cfunc(types.int32(types.float64, dp, dp, vp))
    def jacobian(t, q, J, user):
        x, out = carray(q, 2), carray(J, 2)
        out[0], out[1] = x[0], x[1]
        return 0

    @cfunc(types.int32(vp, types.float64, dp, dp, dp, vp))
    def hook(solver, t, q, v, lam, user):
        p = carray(user, 3, np.float64)
        p[2] = max(p[2], abs(carray(lam, 1)[0]))
        return 0

    _cfuncs = (mass, force, constraint, jacobian, hook)
    return _cfuncs


def stopping_pendulum():
    """The pendulum of length p[0] (gravity 9.81), released from 1 rad; its step hook ends the
    run after the step in which it passes the vertical (summary: that step's time)."""
    p = np.array([1.0])

    def mass(t, q, M):
        M[0, 0] = M[1, 1] = 1.0

    def force(t, q, v, f):
        f[1] = -9.81

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p[0] * p[0])

    def jacobian(t, q, J):
        J[0, 0], J[0, 1] = q[0], q[1]

    s = galpha.Solver(2, 1, mass, force, constraint, jacobian, tolerances=(1e-5, 1e-5),
                      formulation=galpha.GA_INDEX2_STABILIZED)
    s.set_step_hook(lambda t, q, v, lam: q[0] < 0.0)
    return galpha.ensemble.Case(
        s, p, start=lambda p: (0.0, [p[0] * math.sin(1.0), -p[0] * math.cos(1.0)], [0.0, 0.0]),
        summary=lambda s: {"t_stop": s.t})


def driven_decay():
    """First-order states: x'' = -p[0] x + y, y' = -2 y; x(0) = 0, x'(0) = 0, y(0) = 1."""
    p = np.array([1.0])

    def mass(t, q, M):
        M[0, 0] = 1.0

    def force_y(t, q, v, y, f):
        f[0] = -p[0] * q[0] + y[0]

    def rate(t, q, v, y, ydot):
        ydot[0] = -2.0 * y[0]

    s = galpha.Solver(1, 0, mass, r=1, rate=rate, force_y=force_y, tolerances=(1e-7, 1e-7))
    return galpha.ensemble.Case(s, p, q0=[0.0], v0=[0.0], y0=[1.0])


def not_a_case():
    """A broken model (for the error path): it returns no Case."""
    return 42
