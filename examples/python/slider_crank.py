#!/usr/bin/python3
"""The paper's slider-crank (sec. 5.1) written in Python: the model of
examples/scenes/slider_crank.c, same data, same numbers."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402

N, M = 10, 8
X1, Y1, X2, Y2, TH1, TH2, X3, X4, X5, Y5 = range(N)
K_SPRING, L1, L2, M1, M2, M3, M4, TORQUE, REST = 1000.0, 0.3, 0.6, 0.36, 0.15, 0.1, 0.7, 1.0, 0.3
MASS_DIAG = np.array([M1, M1, M2, M2, M1 * L1 * L1 / 12.0, M2 * L2 * L2 / 12.0, M3, M4, 0.0, 0.0])


def mass(t, q, Mm):
    Mm[:] = np.diag(MASS_DIAG)


def force(t, q, v, f):
    spring = K_SPRING * (q[X4] - q[X3] - REST)
    f[:] = 0.0
    f[TH1] = TORQUE
    f[X3] = spring
    f[X4] = -spring


def constraint(t, q, phi):
    c1, s1, c2, s2 = math.cos(q[TH1]), math.sin(q[TH1]), math.cos(q[TH2]), math.sin(q[TH2])
    phi[:] = (q[X1] - 0.5 * L1 * c1, q[Y1] - 0.5 * L1 * s1, q[X5] - L1 * c1, q[Y5] - L1 * s1,
              q[X2] - q[X5] - 0.5 * L2 * c2, q[Y2] - q[Y5] - 0.5 * L2 * s2,
              q[X3] - q[X5] - L2 * c2, q[Y5] + L2 * s2)


def jacobian(t, q, J):
    c1, s1, c2, s2 = math.cos(q[TH1]), math.sin(q[TH1]), math.cos(q[TH2]), math.sin(q[TH2])
    J[:] = 0.0
    J[0, X1], J[0, TH1] = 1.0, 0.5 * L1 * s1
    J[1, Y1], J[1, TH1] = 1.0, -0.5 * L1 * c1
    J[2, X5], J[2, TH1] = 1.0, L1 * s1
    J[3, Y5], J[3, TH1] = 1.0, -L1 * c1
    J[4, X2], J[4, X5], J[4, TH2] = 1.0, -1.0, 0.5 * L2 * s2
    J[5, Y2], J[5, Y5], J[5, TH2] = 1.0, -1.0, -0.5 * L2 * c2
    J[6, X3], J[6, X5], J[6, TH2] = 1.0, -1.0, L2 * s2
    J[7, Y5], J[7, TH2] = 1.0, L2 * c2


def constraint_accel(t, q, v, out):
    c1, s1, c2, s2 = math.cos(q[TH1]), math.sin(q[TH1]), math.cos(q[TH2]), math.sin(q[TH2])
    w1, w2 = v[TH1] * v[TH1], v[TH2] * v[TH2]
    out[:] = (0.5 * L1 * c1 * w1, 0.5 * L1 * s1 * w1, L1 * c1 * w1, L1 * s1 * w1,
              0.5 * L2 * c2 * w2, 0.5 * L2 * s2 * w2, L2 * c2 * w2, -L2 * s2 * w2)


def stiffness(t, q, v, qdd, lam, K):
    c1, s1, c2, s2 = math.cos(q[TH1]), math.sin(q[TH1]), math.cos(q[TH2]), math.sin(q[TH2])
    K[:] = 0.0
    K[TH1, TH1] = (0.5 * L1 * c1 * lam[0] + 0.5 * L1 * s1 * lam[1] + L1 * c1 * lam[2] +
                   L1 * s1 * lam[3])
    K[TH2, TH2] = (0.5 * L2 * c2 * lam[4] + 0.5 * L2 * s2 * lam[5] + L2 * c2 * lam[6] -
                   L2 * s2 * lam[7])
    K[X3, X3], K[X3, X4], K[X4, X3], K[X4, X4] = K_SPRING, -K_SPRING, -K_SPRING, K_SPRING


def initial_state():
    """theta1 = pi/2, at rest, spring undeformed (as sc_initial in the C scene)."""
    th1 = math.pi / 2
    x5, y5 = L1 * math.cos(th1), L1 * math.sin(th1)
    th2 = math.asin(-y5 / L2)
    q = np.zeros(N)
    q[[X1, Y1, TH1, TH2, X5, Y5]] = 0.5 * x5, 0.5 * y5, th1, th2, x5, y5
    q[X2], q[Y2] = x5 + 0.5 * L2 * math.cos(th2), y5 + 0.5 * L2 * math.sin(th2)
    q[X3] = x5 + L2 * math.cos(th2)
    q[X4] = q[X3] + REST
    return q, np.zeros(N)


def main():
    q0, v0 = initial_state()
    with galpha.Solver(N, M, mass, force, constraint, jacobian, stiffness=stiffness,
                       constraint_accel=constraint_accel, rho_inf=0.7) as s:
        s.init(0.0, q0, v0)
        for _ in range(200):
            s.step(5e-3)
        print("Slider-crank (Python), rho_inf = 0.7, h = 5e-3, t = 1")
        print("final q =", " ".join("%.17e" % x for x in s.q))
        print("final lambda =", " ".join("%.17e" % x for x in s.lam))
        st = s.stats
        print("steps = %d, Newton iterations = %d" % (st["steps"], st["newton_iters"]))


if __name__ == "__main__":
    main()
