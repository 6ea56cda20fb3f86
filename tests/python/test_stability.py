"""Stability and accuracy facts of the scheme as oracles (docs/algorithms.md sec. 6): the
amplification matrix of q'' = -omega^2 q, measured by stepping galpha from basis states, has
the spectral radius, damping ratio and period error tabulated there (computed independently
with sympy), and rho_inf at infinity."""
import ctypes
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

OMEGA = 1.0


def mass(t, q, M):
    M[0, 0] = 1.0


def force(t, q, v, f):
    f[0] = -OMEGA * OMEGA * q[0]


def amplification(rho, big_omega):
    """Columns: one step of size h = Omega/omega from y = (q, h v, h^2 a) = unit vectors."""
    h = big_omega / OMEGA
    A = np.zeros((3, 3))
    with galpha.Solver(1, 0, mass, force, rho_inf=rho, newton=(1e-14, 30)) as s:
        for j in range(3):
            y = np.eye(3)[j]
            q, v, a = y[0], y[1] / h, y[2] / h ** 2
            # layout 2: magic, version, n, m, t, h_last, h_next, err_prev, grew, q, v, qdd, a,
            # a_prev (m = 0); qdd consistent with q, h_last = h so that a_n is not rescaled
            s.set_state([26465.0, 2.0, 1, 0, 0.0, h, 0.0, 1.0, 0.0, q, v, -OMEGA ** 2 * q, a, a])
            s.step(h)
            A[:, j] = (s.q[0], h * s.v[0], h * h * s.a[0])
    return A


def principal(A, big_omega):
    lam = np.linalg.eigvals(A)
    root = lam[np.argmax(np.abs(lam.imag))]  # the oscillating pair
    ln = np.log(root)
    return np.max(np.abs(lam)), -ln.real / abs(ln.imag), big_omega / abs(ln.imag) - 1.0


# rho_inf, Omega, spectral radius, damping ratio, period error (docs/algorithms.md 6.4)
TABLE = [
    (0.0, 0.1, 0.99995192, 4.830e-4, 4.501e-3),
    (0.0, 1.0, 0.90656333, 1.224e-1, 2.474e-1),
    (0.5, 1.0, 0.98931279, 1.193e-2, 1.105e-1),
    (0.8, 1.0, 0.99947461, 5.689e-4, 8.260e-2),
    (0.9, 0.1, 0.99999999, 7.277e-8, 8.432e-4),
    (0.9, 1.0, 0.99994226, 6.233e-5, 7.937e-2),
    (0.9, 10.0, 0.98376308, 6.019e-3, 2.677),
]


@pytest.mark.parametrize("rho,big_omega,radius,xi,period", TABLE)
def test_amplification_matrix_matches_the_table(rho, big_omega, radius, xi, period):
    r, x, p = principal(amplification(rho, big_omega), big_omega)
    print("rho %.1f Omega %5.1f: radius %.8f (table %.8f), xi %.3e (%.3e), period error %.3e "
          "(%.3e)" % (rho, big_omega, r, radius, x, xi, p, period))
    assert r == pytest.approx(radius, abs=2e-8)
    assert x == pytest.approx(xi, rel=2e-3, abs=1e-10)
    assert p == pytest.approx(period, rel=2e-3)


@pytest.mark.parametrize("rho", [0.0, 0.3, 0.5, 0.7, 0.9, 1.0])
def test_spectral_radius_at_infinity_is_rho_inf(rho):
    lam = np.linalg.eigvals(amplification(rho, 1e6))
    print("rho_inf %.1f: spectral radius at Omega = 1e6: %.6f" % (rho, np.max(np.abs(lam))))
    assert np.max(np.abs(lam)) == pytest.approx(rho, abs=2e-3)


def test_small_omega_damping_follows_the_series():
    """xi = 1/2 ((1 - rho)/(1 + rho))^3 Omega^3 + O(Omega^5) (docs/algorithms.md 6.3)."""
    for rho in (0.6, 0.8):
        big_omega = 0.05
        _, x, p = principal(amplification(rho, big_omega), big_omega)
        series = 0.5 * ((1 - rho) / (1 + rho)) ** 3 * big_omega ** 3
        period = ((11 * rho ** 4 + 8 * rho ** 3 - 6 * rho ** 2 + 8 * rho + 11) /
                  (24 * (1 + rho) ** 4) * big_omega ** 2)
        assert x == pytest.approx(series, rel=1e-2)
        assert p == pytest.approx(period, rel=1e-2)
