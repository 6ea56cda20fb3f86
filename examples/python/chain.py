#!/usr/bin/python3
"""The chain of examples/chain.c in Python, on the sparse path: N rigid links in absolute
coordinates (x, y, theta per link), declared sparsity patterns, callbacks that fill the values
of those patterns with numpy. Usage: chain.py [links] [--print] (--print: also the final q and
lambda with 17 digits, as the C demo prints them for the cross-language test)."""
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402

LENGTH, MASS, GRAVITY = 1.0, 1.0, 9.81
INERTIA, HALF = MASS * LENGTH * LENGTH / 12.0, 0.5 * LENGTH


def jacobian_entries(links):
    """Which of the 8 entries per joint exist: the first joint (the pin) has no previous link."""
    keep = np.ones((links, 8), dtype=bool)
    keep[0, [2, 3, 6, 7]] = False
    return keep


def patterns(links):
    """Rows and columns of M (diagonal), Phi_q (joint i: x_i, th_i and, for i > 0, x_{i-1},
    th_{i-1} in each of its two rows), K_t (the angles' diagonal) and C_t (empty)."""
    i = np.arange(links)
    rows, cols = [], []
    for d in (0, 1):  # per joint: the x row, then the y row, as examples/scenes/chain.c
        rows.append(np.stack([2 * i + d] * 4, axis=1))
        cols.append(np.stack([3 * i + d, 3 * i + 2, 3 * i - 3 + d, 3 * i - 1], axis=1))
    r = np.stack(rows, axis=1).reshape(links, 8)
    c = np.stack(cols, axis=1).reshape(links, 8)
    keep = jacobian_entries(links)
    theta = 3 * i + 2
    return {"mass": (np.arange(3 * links), np.arange(3 * links)),
            "jacobian": (r[keep], c[keep]),
            "stiffness": (theta, theta),
            "damping": ([], [])}


def cos_sin(th):
    """cos and sin of every angle with the C library's functions: numpy's vectorized ones
    differ from them by an ulp on many arguments, and the multipliers of a 200-link chain
    amplify that to 5e-6 in 100 steps (the cross-language test compares to round-off)."""
    return (np.fromiter(map(math.cos, th), float, th.size),
            np.fromiter(map(math.sin, th), float, th.size))


def model(links):
    keep = jacobian_entries(links)

    def mass(t, q, M):
        M.reshape(links, 3)[:] = (MASS, MASS, INERTIA)

    def force(t, q, v, f):
        f.reshape(links, 3)[:] = (0.0, -MASS * GRAVITY, 0.0)

    def constraint(t, q, phi):
        x, y, th = q.reshape(links, 3).T
        c, s = cos_sin(th)
        ex = x - HALF * c
        ey = y - HALF * s
        ex[1:] -= x[:-1] + HALF * c[:-1]
        ey[1:] -= y[:-1] + HALF * s[:-1]
        phi[0::2], phi[1::2] = ex, ey

    def jacobian(t, q, J):
        c, s = cos_sin(q[2::3])
        s, c = HALF * s, HALF * c
        vals = np.empty((links, 8))
        vals[:, 0], vals[:, 1], vals[:, 4], vals[:, 5] = 1.0, s, 1.0, -c
        vals[1:, 2], vals[1:, 3], vals[1:, 6], vals[1:, 7] = -1.0, s[:-1], -1.0, -c[:-1]
        J[:] = vals[keep]

    def stiffness(t, q, v, qdd, lam, K):
        c, s = cos_sin(q[2::3])
        lx, ly = lam[0::2].copy(), lam[1::2].copy()
        lx[:-1] += lam[2::2]
        ly[:-1] += lam[3::2]
        K[:] = HALF * (c * lx + s * ly)

    def constraint_accel(t, q, v, out):
        (c, s), w = cos_sin(q[2::3]), v[2::3] * v[2::3]
        ax, ay = HALF * c * w, HALF * s * w
        ax[1:] += HALF * c[:-1] * w[:-1]
        ay[1:] += HALF * s[:-1] * w[:-1]
        out[0::2], out[1::2] = ax, ay

    return mass, force, constraint, jacobian, stiffness, constraint_accel


def main():
    links = int(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1][0] != "-" else 2000
    mass, force, constraint, jacobian, stiffness, accel = model(links)
    q0 = np.zeros(3 * links)
    q0[0::3] = (np.arange(links) + 0.5) * LENGTH  # straight, horizontal, at rest
    with galpha.Solver(3 * links, 2 * links, mass, force, constraint, jacobian,
                       stiffness=stiffness, constraint_accel=accel, patterns=patterns(links),
                       constant_mass=True) as s:
        s.init(0.0, q0, np.zeros(3 * links))
        start = time.perf_counter()
        for _ in range(100):
            s.step(1e-3)
        elapsed = time.perf_counter() - start
        q, lam = s.q, s.lam
        phi = np.empty(2 * links)
        constraint(s.t, q, phi)
        print("chain of %d links in Python (%s): t = %g, tip at (%.6f, %.6f), |Phi|_inf = %.1e, "
              "%.2f Newton iterations per step, %.2f ms per step"
              % (links, s.linear_solver_name, s.t, q[-3] + HALF * math.cos(q[-1]),
                 q[-2] + HALF * math.sin(q[-1]), np.max(np.abs(phi)),
                 s.stats["newton_iters"] / 100, 1e3 * elapsed / 100))
        if "--print" in sys.argv:
            print("final q = " + " ".join("%.17e" % x for x in q))
            print("final lambda = " + " ".join("%.17e" % x for x in lam))


if __name__ == "__main__":
    main()
