#!/usr/bin/python3
"""Cost of driving galpha from Python: time per step of the pendulum with Python callbacks
(galpha.Solver; callbacks on copies, the default, and on views with zero_copy=True) against
the same scene with C callbacks (examples/pendulum_demo), measured in the same run, the three
interleaved. CSV on stdout.

Usage: python_overhead.py PENDULUM_DEMO_BINARY"""
import math
import os
import re
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bindings",
                                "python"))
import galpha  # noqa: E402


def mass(t, q, M):
    M[0, 0] = M[1, 1] = 1.0
    M[0, 1] = M[1, 0] = 0.0


def force(t, q, v, f):
    f[0] = 0.0
    f[1] = -9.81


def constraint(t, q, phi):
    phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - 1.0)


def jacobian(t, q, J):
    J[0, 0] = q[0]
    J[0, 1] = q[1]


def python_per_step(zero_copy, steps=1000, repeats=1):
    best = math.inf
    for _ in range(repeats):
        with galpha.Solver(2, 1, mass, force, constraint, jacobian, rho_inf=0.9,
                           zero_copy=zero_copy) as s:
            s.init(0.0, [math.sin(1.0), -math.cos(1.0)], [0.5 * math.cos(1.0), 0.5 * math.sin(1.0)])
            t0 = time.perf_counter()
            for _ in range(steps):
                s.step(1e-3)
            best = min(best, (time.perf_counter() - t0) / steps)
            calls = sum(s.stats[k] for k in ("mass_evals", "force_evals", "constraint_evals",
                                             "jacobian_evals")) / steps
    return best, calls


def c_per_step(binary, repeats=1):
    best = math.inf
    for _ in range(repeats):
        out = subprocess.run([binary], check=True, capture_output=True, text=True).stdout
        ms = float(re.search(r"CPU = ([0-9.]+) ms", out).group(1))
        steps = int(re.search(r"steps = (\d+)", out).group(1))
        best = min(best, 1e-3 * ms / steps)
    return best


if __name__ == "__main__":
    best = {"copies": math.inf, "views": math.inf, "c": math.inf}
    for _ in range(5):  # interleaved: the machine's speed drifts between runs
        py, calls = python_per_step(False)
        best["copies"] = min(best["copies"], py)
        best["views"] = min(best["views"], python_per_step(True)[0])
        best["c"] = min(best["c"], c_per_step(sys.argv[1]))
    c = best["c"]
    print("binding,us_per_step,callbacks_per_step,ratio_to_c")
    print("c,%.3f,%.2f,1.0" % (1e6 * c, calls))
    print("python_ctypes_copies,%.3f,%.2f,%.1f" % (1e6 * best["copies"], calls,
                                                   best["copies"] / c))
    print("python_ctypes_zero_copy,%.3f,%.2f,%.1f" % (1e6 * best["views"], calls,
                                                      best["views"] / c))
