#!/usr/bin/python3
"""The pendulum hitting a wall of examples/impact.c, written in Python: the wall a terminal
event (Solver.set_events), the velocity reflected with restitution e at each impact and the run
restarted there with init(); the model is that of pendulum.py. Same scene, same numbers; exits
with 1 if the energy ratios are not e^2 or the first impact is not at the exact quarter
period."""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402
from pendulum import GRAVITY, LENGTH, MASS, constraint, force, jacobian, mass  # noqa: E402


def wall(t, q, v, lam):
    return q[0]


wall.direction, wall.terminal = -1, True


def elliptic_k(k):
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(40):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


def main():
    e, h, impacts, theta0 = 0.8, 1e-3, 6, math.pi / 3.0
    q = np.array([LENGTH * math.sin(theta0), -LENGTH * math.cos(theta0)])
    v = np.zeros(2)
    t_first = elliptic_k(math.sin(0.5 * theta0)) * math.sqrt(LENGTH / GRAVITY)
    kinetic_first = MASS * GRAVITY * LENGTH * (1.0 - math.cos(theta0))
    kinetic, times = [], []
    with galpha.Solver(2, 1, mass, force, constraint, jacobian) as s:
        s.set_events([wall])
        s.init(0.0, q, v)
        for k in range(impacts):
            while not s.step(h):  # steps until the pendulum reaches the wall
                pass
            (t, _, _), = s.events
            q, v, _ = s.interpolate(t)
            kinetic.append(0.5 * MASS * (v[0] * v[0] + v[1] * v[1]))
            times.append(t)
            line = "impact %d at t = %.9f s: kinetic energy %.9f J" % (k + 1, t, kinetic[k])
            if k > 0:
                line += ", %.9f of the one before (e^2 = %.2f)" % (kinetic[k] / kinetic[k - 1],
                                                                   e * e)
            print(line)
            v = -e * v  # the impact law
            s.init(t, q, v)
        print("final q =", " ".join("%.17e" % x for x in s.q))
        print("final lambda =", " ".join("%.17e" % x for x in s.lam))
    worst = max(abs(kinetic[k] / kinetic[k - 1] / (e * e) - 1.0) for k in range(1, impacts))
    dt = abs(times[0] - t_first) / t_first
    dk = abs(kinetic[0] - kinetic_first) / kinetic_first
    print("largest relative deviation from e^2: %.2e; first impact: time %.2e and energy "
          "%.2e off the exact ones (relative)" % (worst, dt, dk))
    return 1 if worst > 1e-6 or dt > 1e-5 or dk > 1e-5 else 0


if __name__ == "__main__":
    np.seterr(all="raise")
    sys.exit(main())
