#!/usr/bin/python3
"""The planar pendulum of examples/pendulum_demo.c, written in Python: same scene, same numbers."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402

MASS, LENGTH, GRAVITY = 1.0, 1.0, 9.81


def mass(t, q, M):
    M[:] = ((MASS, 0.0), (0.0, MASS))


def force(t, q, v, f):
    f[0] = 0.0
    f[1] = -MASS * GRAVITY


def constraint(t, q, phi):
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - LENGTH * LENGTH)


def jacobian(t, q, J):
    J[0, 0] = q[0]
    J[0, 1] = q[1]


def main():
    theta0, omega0, h = 1.0, 0.5, 1e-3
    q0 = [LENGTH * math.sin(theta0), -LENGTH * math.cos(theta0)]
    v0 = [LENGTH * omega0 * math.cos(theta0), LENGTH * omega0 * math.sin(theta0)]
    with galpha.Solver(2, 1, mass, force, constraint, jacobian, rho_inf=0.9) as s:
        s.init(0.0, q0, v0)
        for _ in range(1000):
            s.step(h)
        print("galpha (Python)", galpha.__version__)
        print("final q =", " ".join("%.17e" % x for x in s.q))
        print("final lambda =", " ".join("%.17e" % x for x in s.lam))
        print("steps =", s.stats["steps"])


if __name__ == "__main__":
    np.seterr(all="raise")
    main()
