#!/usr/bin/python3
"""Identifying a spring stiffness k and a damping c from measured crank angles, by Gauss-Newton
with galpha's forward sensitivities.

The slider-crank of SUNDIALS' IDAS sensitivity example (examples/scenes/crank_spring_damper.h,
written here in Python): crank angle theta, slider position x and rod angle phi, two
constraints, a spring-damper (k, c) between crank and rod and a constant force on the rod.
The "measurements" are crank angles every 0.1 s over 10 s from a finer run with k = 2.5,
c = 0.4, with noise of 1e-4 rad. Starting from k = c = 1, each iteration runs the model once
with sensitivities (d theta / dk, d theta / dc at every step: one extra solve per parameter),
and takes the Gauss-Newton step (J^T J) dp = -J^T r.

Usage: identify_crank.py [--plot FILE.png]  (the chart needs python3-matplotlib)"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402

A, J1, M2, J2, L0, F = 0.5, 1.0, 1.0, 2.0, 1.0, 1.0
TRUE = (2.5, 0.4)
T_END, EVERY = 10.0, 0.1


def model(p):
    """Callbacks of the crank reading k = p[0], c = p[1] at every call."""
    def mass(t, q, M):
        M[:] = np.diag([J1, M2, J2])

    def force(t, q, v, f):
        th, x, ph = q
        l2 = x * x - x * (math.cos(ph) + A * math.cos(th)) + 0.25 * (1 + A * A) + \
            0.5 * A * math.cos(ph - th)
        g = np.array([A * x * math.sin(th) + 0.5 * A * math.sin(ph - th),
                      2 * x - math.cos(ph) - A * math.cos(th),
                      x * math.sin(ph) - 0.5 * A * math.sin(ph - th)])  # d(l^2)/dq
        l = math.sqrt(l2)
        # (g . v written out: numpy's g @ v is the system BLAS's ddot, whose order of
        # summation, and so whose last bit, differs from one BLAS to another)
        tension = p[0] * (l - L0) + p[1] * (g[0] * v[0] + g[1] * v[1] + g[2] * v[2]) / (2 * l)
        f[:] = -tension * g / (2 * l)
        f[1] += F
        f[2] -= F * math.sin(ph)

    def constraint(t, q, phi):
        phi[:] = (q[1] - math.cos(q[2]) - A * math.cos(q[0]), -math.sin(q[2]) - A * math.sin(q[0]))

    def jacobian(t, q, J):
        J[:] = [[A * math.sin(q[0]), 1.0, math.sin(q[2])], [-A * math.cos(q[0]), 0.0, -math.cos(q[2])]]

    return mass, force, constraint, jacobian


def initial_state():
    ph = math.asin(-A)
    return np.array([math.pi / 2, math.cos(ph), ph]), np.zeros(3)


def crank_angles(p, h, sensitivities, t_end=T_END):
    """theta every EVERY seconds (and d theta / dp there) from a run with steps of h."""
    p = np.array(p, dtype=float)
    options = dict(parameters=p) if sensitivities else {}
    q0, v0 = initial_state()
    every = round(EVERY / h)
    angles, slopes = [], []
    with galpha.Solver(3, 2, *model(p), formulation=galpha.GA_INDEX2_STABILIZED,
                       **options) as s:
        s.init(0.0, q0, v0)
        for k in range(1, round(t_end / h) + 1):
            s.step(h)
            if k % every == 0:
                angles.append(s.q[0])
                if sensitivities:
                    slopes.append(s.sensitivity().dq[0])
        steps = s.stats["steps"]
    return np.array(angles), np.array(slopes), steps


def identify(measured, start=(1.0, 1.0), h=2e-3, max_iterations=10, verbose=True,
             t_end=T_END):
    p = np.array(start)
    for it in range(max_iterations):
        theta, J, steps = crank_angles(p, h, True, t_end)
        r = theta - measured
        dp = np.linalg.lstsq(J, -r, rcond=None)[0]
        if verbose:
            print(f"  iteration {it}: k = {p[0]:.6f}, c = {p[1]:.6f}, |r| = "
                  f"{np.linalg.norm(r):.3e} ({steps} steps with sensitivities)")
        p = p + dp
        if np.all(np.abs(dp) <= 1e-8 * np.abs(p)):
            break
    return p, it + 1


def main():
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    rng = np.random.default_rng(20)
    clean = crank_angles(TRUE, 5e-4, False)[0]
    measured = clean + 1e-4 * rng.standard_normal(clean.size)
    print(f"Identifying k and c of the slider-crank from {measured.size} crank angles "
          f"(true k = {TRUE[0]}, c = {TRUE[1]}; noise 1e-4 rad)")
    p, iterations = identify(measured)
    print(f"identified k = {p[0]:.5f}, c = {p[1]:.5f} in {iterations} Gauss-Newton iterations")
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = EVERY * np.arange(1, measured.size + 1)
        fitted = crank_angles(p, 2e-3, False)[0]
        start = crank_angles((1.0, 1.0), 2e-3, False)[0]
        fig, ax = plt.subplots(figsize=(7, 3.5))
        ax.plot(t, measured, ".", ms=3, label="measured")
        ax.plot(t, start, label="start: k = c = 1")
        ax.plot(t, fitted, label=f"identified: k = {p[0]:.3f}, c = {p[1]:.3f}")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("crank angle [rad]")
        ax.legend()
        fig.tight_layout()
        fig.savefig(plot, dpi=120)
    return p


if __name__ == "__main__":
    main()
