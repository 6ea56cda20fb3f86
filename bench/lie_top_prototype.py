#!/usr/bin/env python3
"""Lie-group generalized-alpha on the heavy top, prototyped before it is built (issue 36):
which formulation, and why. Plain numpy, full Newton with difference Jacobians -- a study of
the discretization, not of cost.

The top (docs/algorithms.md sec. 13): m = 15, centroidal inertia diag(0.234375, 0.46875,
0.234375), centre of mass X = (0, 1, 0) in the body, a fixed spherical joint at the origin,
gravity (0, 0, -9.81), body angular velocity (0, 150, -4.61538) at t = 0, R(0) = I.

Formulations, each with right increments R_{n+1} = R_n exp(h Dq), body-frame angular velocity:
  so3        SO(3) alone, the top about its pivot (inertia about the joint), no constraint;
  r3so3      R^3 x SO(3): the centre of mass x in space (R^3, Newmark), the rotation about it
             with the centroidal inertia, the joint as the constraint x - R X = 0 (index 3);
  so3_space  SO(3) alone with the spatial angular velocity (left increments
             R_{n+1} = exp(h Dq) R_n), to see whether the trivialization matters.
Reference: Euler's equations about the pivot with a rotation matrix, DOP853 at rtol 1e-13,
checked by the Lagrange top's invariants (energy, vertical angular momentum, spin).

    /usr/bin/python3 bench/lie_top_prototype.py [out.csv [t_end]]

(t_end 1 compares with tests/c/test_heavy_top, galpha's Euler-parameter top, which prints its
centre-of-mass errors at t = 1.)
"""
import sys

import numpy as np
from scipy.integrate import solve_ivp

M = 15.0
JC = np.diag([0.234375, 0.46875, 0.234375])
X = np.array([0.0, 1.0, 0.0])
G = np.array([0.0, 0.0, -9.81])
OMEGA0 = np.array([0.0, 150.0, -4.61538])
JP = JC + M * (X @ X * np.eye(3) - np.outer(X, X))
T_END = 2.0
RHO = 0.9


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def expm(w):
    th = np.linalg.norm(w)
    K = hat(w)
    if th < 1e-8:
        return np.eye(3) + K + 0.5 * K @ K
    return np.eye(3) + np.sin(th) / th * K + (1 - np.cos(th)) / th**2 * K @ K


def params(rho):
    am = (2 * rho - 1) / (rho + 1)
    af = rho / (rho + 1)
    gamma = 0.5 + af - am
    beta = 0.25 * (gamma + 0.5) ** 2
    return am, af, beta, gamma


def reference():
    def rhs(t, y):
        R = y[:9].reshape(3, 3)
        w = y[9:]
        dR = R @ hat(w)
        dw = np.linalg.solve(JP, -np.cross(w, JP @ w) + np.cross(X, R.T @ (M * G)))
        return np.concatenate([dR.ravel(), dw])

    y0 = np.concatenate([np.eye(3).ravel(), OMEGA0])
    sol = solve_ivp(rhs, (0.0, T_END), y0, method="DOP853", rtol=1e-13, atol=1e-13)
    R = sol.y[:9, -1].reshape(3, 3)
    w = sol.y[9:, -1]

    def invariants(R, w):
        energy = 0.5 * w @ JP @ w - M * G @ (R @ X)
        return energy, (R @ JP @ w)[2], w[1]

    e0, e1 = np.array(invariants(np.eye(3), OMEGA0)), np.array(invariants(R, w))
    drift = np.abs(e1 - e0) / np.abs(e0)
    return R @ X, w, drift


def newton(residual, z0, tol=1e-9, max_iter=30):
    z = z0.copy()
    for _ in range(max_iter):
        r = residual(z)
        J = np.empty((len(r), len(z)))
        for j in range(len(z)):
            e = 1e-7 * max(1.0, abs(z[j]))
            zp, zm = z.copy(), z.copy()
            zp[j] += e
            zm[j] -= e
            J[:, j] = (residual(zp) - residual(zm)) / (2 * e)
        dz = np.linalg.solve(J, -r)
        z += dz
        if np.max(np.abs(dz)) <= tol * max(1.0, np.max(np.abs(z))):
            return z
    raise RuntimeError("Newton did not converge")


def so3_top(h, spatial=False):
    """SO(3) about the pivot; body (right increments) or spatial (left) angular velocity."""
    am, af, beta, gamma = params(RHO)
    R = np.eye(3)
    w = OMEGA0.copy() if not spatial else R @ OMEGA0  # spatial omega = R Omega

    def accel(R, w):  # body: J W' = -W x J W + X x R^T m g; spatial: I = R J R^T
        if not spatial:
            return np.linalg.solve(JP, -np.cross(w, JP @ w) + np.cross(X, R.T @ (M * G)))
        I = R @ JP @ R.T
        return np.linalg.solve(I, -np.cross(w, I @ w) + np.cross(R @ X, M * G))

    wd = accel(R, w)
    a = wd.copy()
    for _ in range(int(round(T_END / h))):
        def parts(wd1):
            a1 = ((1 - af) * wd1 + af * wd - am * a) / (1 - am)
            dq = w + h * (0.5 - beta) * a + h * beta * a1
            R1 = R @ expm(h * dq) if not spatial else expm(h * dq) @ R
            w1 = w + h * (1 - gamma) * a + h * gamma * a1
            return a1, R1, w1

        def residual(wd1):
            a1, R1, w1 = parts(wd1)
            return wd1 - accel(R1, w1)

        wd1 = newton(residual, wd)
        a, R, w = parts(wd1)[0], parts(wd1)[1], parts(wd1)[2]
        wd = wd1
    w_body = w if not spatial else R.T @ w
    return R @ X, w_body


def r3so3_top(h):
    """R^3 x SO(3): centre of mass x, centroidal rotation, joint x - R X = 0 (index 3)."""
    am, af, beta, gamma = params(RHO)
    R = np.eye(3)
    w = OMEGA0.copy()
    x = R @ X
    u = R @ np.cross(w, X)  # d/dt (R X) = R (W x X)

    def dynamics(R, w, acc, lam):  # [m u' - m g + lam; Jc W' + W x Jc W - X x R^T lam]
        return np.concatenate([M * acc[:3] - M * G + lam,
                               JC @ acc[3:] + np.cross(w, JC @ w) - np.cross(X, R.T @ lam)])

    # consistent start: the equations and the constraint's second derivative,
    # u' - R (W' x X + W x (W x X)) = 0
    def start(z):
        acc, lam = z[:6], z[6:]
        return np.concatenate([dynamics(R, w, acc, lam),
                               acc[:3] - R @ (np.cross(acc[3:], X) + np.cross(w, np.cross(w, X)))])

    z = newton(start, np.zeros(9))
    acc, lam = z[:6], z[6:]
    a = acc.copy()
    for _ in range(int(round(T_END / h))):
        def parts(z1):
            acc1 = z1[:6]
            a1 = ((1 - af) * acc1 + af * acc - am * a) / (1 - am)
            x1 = x + h * u + h * h * ((0.5 - beta) * a[:3] + beta * a1[:3])
            u1 = u + h * ((1 - gamma) * a[:3] + gamma * a1[:3])
            dq = w + h * (0.5 - beta) * a[3:] + h * beta * a1[3:]
            R1 = R @ expm(h * dq)
            w1 = w + h * ((1 - gamma) * a[3:] + gamma * a1[3:])
            return a1, x1, u1, R1, w1

        def residual(z1):
            a1, x1, u1, R1, w1 = parts(z1)
            return np.concatenate([dynamics(R1, w1, z1[:6], z1[6:]),
                                   (x1 - R1 @ X) / (beta * h * h)])

        z1 = newton(residual, np.concatenate([acc, lam]))
        a, x, u, R, w = parts(z1)
        acc, lam = z1[:6], z1[6:]
    return x, w


def main():
    global T_END
    out = sys.argv[1] if len(sys.argv) > 1 else None
    if len(sys.argv) > 2:
        T_END = float(sys.argv[2])
    x_ref, w_ref, drift = reference()
    print("reference: invariants' relative drift (energy, vertical momentum, spin):",
          " ".join("%.1e" % d for d in drift))
    rows = ["formulation,t_end,h,com_error,omega_error"]
    for name, run in (("so3", so3_top), ("so3_space", lambda h: so3_top(h, True)),
                      ("r3so3", r3so3_top)):
        for h in (2e-3, 1e-3, 5e-4, 2.5e-4):
            x, w = run(h)
            ex, ew = np.linalg.norm(x - x_ref), np.linalg.norm(w - w_ref)
            rows.append("%s,%g,%g,%.6e,%.6e" % (name, T_END, h, ex, ew))
            print("%-10s h = %-7g centre of mass %.3e  body angular velocity %.3e"
                  % (name, h, ex, ew))
    if out:
        with open(out, "w") as f:
            f.write("\n".join(rows) + "\n")


if __name__ == "__main__":
    main()
