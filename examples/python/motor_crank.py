#!/usr/bin/python3
"""The slider-crank driven by a DC motor under a PI speed controller, in Python: the model of
examples/scenes/slider_crank_motor.c (same data, same numbers as examples/motor_crank.c).
The motor current i and the controller's integral z are first-order states, y = (i, z),
integrated in the same Newton solve as the mechanism:
    L i' = u - R i - Ke w,   u = Kp (w_ref(t) - w) + Ki z,   z' = w_ref(t) - w,
with w the crank speed and the motor torque Kt i on the crank.

Usage: motor_crank.py [--plot FILE.png]  (the chart needs python3-matplotlib)"""
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402
import slider_crank as sc  # noqa: E402

KT, KE, R, L, KP, KI, W_FINAL, TAU = 0.3, 0.3, 0.5, 2e-3, 20.0, 50.0, 4.0 * math.pi, 0.1
I, Z = 0, 1


def reference_speed(t):
    return W_FINAL * (1.0 - math.exp(-t / TAU))


def force_y(t, q, v, y, f):
    sc.force(t, q, v, f)
    f[sc.TH1] = KT * y[I]  # the motor instead of the paper's constant torque


def rate(t, q, v, y, ydot):
    w = v[sc.TH1]
    error = reference_speed(t) - w
    ydot[:] = ((KP * error + KI * y[Z] - R * y[I] - KE * w) / L, error)


def coupling(t, q, v, y, g_q, g_v, g_y, f_y):
    g_v[I, sc.TH1], g_v[Z, sc.TH1] = -(KP + KE) / L, -1.0
    g_y[I, I], g_y[I, Z] = -R / L, KI / L
    f_y[sc.TH1, I] = KT


def main():
    plot = sys.argv[sys.argv.index("--plot") + 1] if "--plot" in sys.argv else None
    q0, v0 = sc.initial_state()
    h, t_end = 1e-3, 2.0
    rows = []
    with galpha.Solver(sc.N, sc.M, sc.mass, None, sc.constraint, sc.jacobian,
                       stiffness=sc.stiffness, constraint_accel=sc.constraint_accel,
                       rho_inf=0.8, r=2, rate=rate, force_y=force_y, coupling=coupling) as s:
        s.init(0.0, q0, v0, np.zeros(2))
        for k in range(1, int(round(t_end / h)) + 1):
            s.step(h)
            t, w, y = s.t, s.v[sc.TH1], s.y
            rows.append((t, w, reference_speed(t), y[I], y[Z]))
        print("Slider-crank driven by a DC motor with a PI speed controller (Python), "
              "rho_inf = 0.8, h = 1e-3, t = 2")
        print("final q =", " ".join("%.17e" % x for x in s.q))
        print("final lambda =", " ".join("%.17e" % x for x in s.lam))
        print("final y =", " ".join("%.17e" % x for x in s.y))
        st = s.stats
        print("steps = %d, Newton iterations = %d" % (st["steps"], st["newton_iters"]))
    data = np.array(rows)
    late = data[:, 0] > 1.0
    print("RMS speed error over [1, 2] s %.3f rad/s; peak current %.1f A"
          % (math.sqrt(np.mean((data[late, 1] - data[late, 2]) ** 2)), np.abs(data[:, 3]).max()))
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5))
        top.plot(data[:, 0], data[:, 2], "k--", label="reference")
        top.plot(data[:, 0], data[:, 1], label="crank speed")
        top.set_ylabel("rad/s")
        top.legend(loc="lower right")
        top.set_title("Slider-crank driven by a DC motor, PI speed control (galpha, h = 1 ms)")
        bottom.plot(data[:, 0], data[:, 3], color="C3")
        bottom.set_ylabel("motor current (A)")
        bottom.set_xlabel("t (s)")
        fig.tight_layout()
        fig.savefig(plot, dpi=90)
        print("chart:", plot)


if __name__ == "__main__":
    main()
