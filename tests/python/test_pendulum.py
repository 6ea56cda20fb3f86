"""The planar pendulum through ctypes: order 2 in q, v, qdd and lambda, as in the C suite.

Reference: an independent RK4 solution of the angle equation (numpy, not galpha)."""
import ctypes
import math
import os
import sys

import numpy as np

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
from galpha import _ffi  # noqa: E402

M, L, G = 1.0, 1.0, 9.81
THETA0, OMEGA0, T_END = 1.0, 0.5, 1.0


def view(ptr, n):
    return np.ctypeslib.as_array(ptr, shape=(n,))


@_ffi.MASS_FN
def mass(t, q, out, user):
    view(out, 4)[:] = (M, 0.0, 0.0, M)
    return 0


@_ffi.FORCE_FN
def force(t, q, v, out, user):
    view(out, 2)[:] = (0.0, -M * G)
    return 0


@_ffi.CONSTRAINT_FN
def constraint(t, q, out, user):
    x = view(q, 2)
    out[0] = 0.5 * (x @ x - L * L)
    return 0


@_ffi.JACOBIAN_FN
def jacobian(t, q, out, user):
    view(out, 2)[:] = view(q, 2)
    return 0


def reference(steps=100000):
    th, om, h = THETA0, OMEGA0, T_END / steps
    f = lambda th, om: (om, -G / L * math.sin(th))  # noqa: E731
    for _ in range(steps):
        k1 = f(th, om)
        k2 = f(th + h / 2 * k1[0], om + h / 2 * k1[1])
        k3 = f(th + h / 2 * k2[0], om + h / 2 * k2[1])
        k4 = f(th + h * k3[0], om + h * k3[1])
        th += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        om += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    al = -G / L * math.sin(th)
    q = np.array([L * math.sin(th), -L * math.cos(th)])
    v = np.array([L * om * math.cos(th), L * om * math.sin(th)])
    a = np.array([L * (al * math.cos(th) - om * om * math.sin(th)),
                  L * (al * math.sin(th) + om * om * math.cos(th))])
    lam = M * (v @ v - G * q[1]) / (L * L)
    return q, v, a, lam


def run(h):
    s = ctypes.c_void_p()
    assert _ffi.ga_create(2, 1, ctypes.byref(s)) == _ffi.GA_OK
    try:
        assert _ffi.ga_set_callbacks(s, mass, force, constraint, jacobian, None) == 0
        assert _ffi.ga_set_newton(s, 1e-12, 20) == 0
        q = np.array([L * math.sin(THETA0), -L * math.cos(THETA0)])
        v = np.array([L * OMEGA0 * math.cos(THETA0), L * OMEGA0 * math.sin(THETA0)])
        dp = lambda a: a.ctypes.data_as(_ffi.c_double_p)  # noqa: E731
        assert _ffi.ga_init(s, 0.0, dp(q), dp(v)) == 0
        for _ in range(round(T_END / h)):
            st = _ffi.ga_step(s, h)
            assert st == 0, _ffi.ga_last_error(s).decode()
        out = [np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(1)]
        for fn, arr in zip((_ffi.ga_get_q, _ffi.ga_get_v, _ffi.ga_get_qdd, _ffi.ga_get_lambda),
                           out):
            assert fn(s, dp(arr)) == 0
        return out[0], out[1], out[2], out[3][0]
    finally:
        _ffi.ga_free(s)


def test_pendulum_order_two():
    q_ref, v_ref, a_ref, lam_ref = reference()
    hs = 0.01 / 2.0 ** np.arange(5)
    errors = np.zeros((4, hs.size))
    for k, h in enumerate(hs):
        q, v, a, lam = run(h)
        errors[:, k] = (np.abs(q - q_ref).max(), np.abs(v - v_ref).max(),
                        np.abs(a - a_ref).max(), abs(lam - lam_ref))
    orders = [np.polyfit(np.log(hs), np.log(e), 1)[0] for e in errors]
    print("\nmeasured orders (python/ctypes): q %.3f  v %.3f  qdd %.3f  lambda %.3f" % tuple(orders))
    for p in orders:
        assert 1.9 <= p <= 2.1


def test_version_and_errors():
    assert _ffi.ga_version().decode().count(".") == 2
    assert _ffi.ga_strerror(_ffi.GA_ERR_NEWTON) == b"Newton iteration did not converge"
    s = ctypes.c_void_p()
    assert _ffi.ga_create(0, 0, ctypes.byref(s)) == _ffi.GA_ERR_ARG
