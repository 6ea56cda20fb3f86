#!/usr/bin/python3
"""Cost per step of galpha driven from Python with the model in C, in numba-compiled callbacks
and in Python callbacks: the pendulum and Andrews' squeezer (7 angles), the same arithmetic in
each, interleaved rounds, best of each. Two drivers: one advance() over the whole run (adaptive,
rtol = atol = 1e-6: no Python in a step) and a Python loop of step(h). CSV on stdout.

The same runs with a C driver (bench/c_driver.c: ga_advance, a loop of ga_step; its best of 5,
once in every round) give the reference: ratio_to_c_driver.

Usage: compiled_callbacks.py LIBBENCH_SCENES C_DRIVER  (bench/CMakeLists.txt builds both)
Needs numba (Debian: python3-numba)."""
import csv
import ctypes
import io
import math
import os
import subprocess
import sys
import time

import numpy as np
from numba import carray, cfunc, types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "bindings",
                                "python"))
import galpha  # noqa: E402

dp, vp = types.CPointer(types.float64), types.voidptr
MASS = types.int32(types.float64, dp, dp, vp)
FORCE = types.int32(types.float64, dp, dp, dp, vp)
CONSTRAINT = types.int32(types.float64, dp, dp, vp)


# ---- the pendulum (examples/scenes/pendulum.c; user = (mass, length, gravity)) -------------
@cfunc(MASS)
def pe_mass(t, q, M, user):
    p, out = carray(user, 3, np.float64), carray(M, 4)
    out[0], out[1], out[2], out[3] = p[0], 0.0, 0.0, p[0]
    return 0


@cfunc(FORCE)
def pe_force(t, q, v, f, user):
    p, out = carray(user, 3, np.float64), carray(f, 2)
    out[0], out[1] = 0.0, -p[0] * p[2]
    return 0


@cfunc(CONSTRAINT)
def pe_constraint(t, q, phi, user):
    p, x = carray(user, 3, np.float64), carray(q, 2)
    carray(phi, 1)[0] = 0.5 * (x[0] * x[0] + x[1] * x[1] - p[1] * p[1])
    return 0


@cfunc(CONSTRAINT)
def pe_jacobian(t, q, J, user):
    x, out = carray(q, 2), carray(J, 2)
    out[0], out[1] = x[0], x[1]
    return 0


def pendulum_python(p):
    def mass(t, q, M):
        M[0, 0] = M[1, 1] = p[0]

    def force(t, q, v, f):
        f[1] = -p[0] * p[2]

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p[1] * p[1])

    def jacobian(t, q, J):
        J[0, 0], J[0, 1] = q[0], q[1]
    return mass, force, constraint, jacobian


# ---- Andrews' squeezer in 7 angles (examples/scenes/andrews.c, published parameters) -------
m1, m2, m3, m4, m5, m6, m7 = 0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498
i1, i2, i3, i4, i5, i6, i7 = 2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5
xa, ya, xb, yb, xc, yc = -0.06934, -0.00227, -0.03635, 0.03273, 0.014, 0.072
d, da, e, ea, rr, ra, ss, sa, sb, sc, sd = (0.028, 0.0115, 0.02, 0.01421, 0.007, 0.00092, 0.035,
                                            0.01874, 0.01043, 0.018, 0.02)
ta, tb, u, ua, ub, zf, zt, fa, mom, c0, l0 = (0.02308, 0.00916, 0.04, 0.01228, 0.00449, 0.02,
                                              0.04, 0.01421, 0.033, 4530.0, 0.07785)
Q0 = [-0.0617138900142764496358948458001, 0.0, 0.455279819163070380255912382449,
      0.222668390165885884674473185609, 0.487364979543842550225598953530,
      -0.222668390165885884674473185609, 1.23054744454982119249735015568]


def andrews_bodies(np_):
    """The four functions on plain arrays, compiled by numba or run by Python alike."""
    def mass(q, M):
        cth, sph, som = math.cos(q[1]), math.sin(q[3]), math.sin(q[5])
        for k in range(49):
            M[k] = 0.0
        M[0] = m1 * ra * ra + m2 * (rr * rr - 2 * da * rr * cth + da * da) + i1 + i2
        M[1] = M[7] = m2 * (da * da - da * rr * cth) + i2
        M[8] = m2 * da * da + i2
        M[16] = m3 * (sa * sa + sb * sb) + i3
        M[24] = m4 * (e - ea) * (e - ea) + i4
        M[25] = M[31] = m4 * ((e - ea) * (e - ea) + zt * (e - ea) * sph) + i4
        M[32] = (m4 * (zt * zt + 2 * zt * (e - ea) * sph + (e - ea) * (e - ea)) +
                 m5 * (ta * ta + tb * tb) + i4 + i5)
        M[40] = m6 * (zf - fa) * (zf - fa) + i6
        M[41] = M[47] = m6 * ((zf - fa) * (zf - fa) - u * (zf - fa) * som) + i6
        M[48] = (m6 * ((zf - fa) * (zf - fa) - 2 * u * (zf - fa) * som + u * u) +
                 m7 * (ua * ua + ub * ub) + i6 + i7)

    def force(q, v, f):
        gam = q[2]
        xd = sd * math.cos(gam) + sc * math.sin(gam) + xb
        yd = sd * math.sin(gam) - sc * math.cos(gam) + yb
        lg = math.hypot(xd - xc, yd - yc)
        s = -c0 * (lg - l0) / lg
        fx, fy = s * (xd - xc), s * (yd - yc)
        sth, cph, com = math.sin(q[1]), math.cos(q[3]), math.cos(q[5])
        f[0] = mom - m2 * da * rr * v[1] * (v[1] + 2 * v[0]) * sth
        f[1] = m2 * da * rr * v[0] * v[0] * sth
        f[2] = (fx * (sc * math.cos(gam) - sd * math.sin(gam)) +
                fy * (sd * math.cos(gam) + sc * math.sin(gam)))
        f[3] = m4 * zt * (e - ea) * v[4] * v[4] * cph
        f[4] = -m4 * zt * (e - ea) * v[3] * (v[3] + 2 * v[4]) * cph
        f[5] = -m6 * u * (zf - fa) * v[6] * v[6] * com
        f[6] = m6 * u * (zf - fa) * v[5] * (v[5] + 2 * v[6]) * com

    def constraint(q, g):
        bt, pd, oe = q[0] + q[1], q[3] + q[4], q[5] + q[6]
        g[0] = rr * math.cos(q[0]) - d * math.cos(bt) - ss * math.sin(q[2]) - xb
        g[1] = rr * math.sin(q[0]) - d * math.sin(bt) + ss * math.cos(q[2]) - yb
        g[2] = (rr * math.cos(q[0]) - d * math.cos(bt) - e * math.sin(pd) -
                zt * math.cos(q[4]) - xa)
        g[3] = (rr * math.sin(q[0]) - d * math.sin(bt) + e * math.cos(pd) -
                zt * math.sin(q[4]) - ya)
        g[4] = (rr * math.cos(q[0]) - d * math.cos(bt) - zf * math.cos(oe) -
                u * math.sin(q[6]) - xa)
        g[5] = (rr * math.sin(q[0]) - d * math.sin(bt) - zf * math.sin(oe) +
                u * math.cos(q[6]) - ya)

    def jacobian(q, G):  # 6 x 7, column-major: G[i + 6 j]
        bt, pd, oe = q[0] + q[1], q[3] + q[4], q[5] + q[6]
        sb_, cb, sbt, cbt = math.sin(q[0]), math.cos(q[0]), math.sin(bt), math.cos(bt)
        for k in range(42):
            G[k] = 0.0
        for r in range(0, 6, 2):
            G[r] = -rr * sb_ + d * sbt
            G[r + 6] = d * sbt
            G[r + 1] = rr * cb - d * cbt
            G[r + 7] = -d * cbt
        G[12] = -ss * math.cos(q[2])
        G[13] = -ss * math.sin(q[2])
        G[2 + 18] = -e * math.cos(pd)
        G[2 + 24] = -e * math.cos(pd) + zt * math.sin(q[4])
        G[3 + 18] = -e * math.sin(pd)
        G[3 + 24] = -e * math.sin(pd) - zt * math.cos(q[4])
        G[4 + 30] = zf * math.sin(oe)
        G[4 + 36] = zf * math.sin(oe) - u * math.cos(q[6])
        G[5 + 30] = -zf * math.cos(oe)
        G[5 + 36] = -zf * math.cos(oe) - u * math.sin(q[6])
    return mass, force, constraint, jacobian


_am, _af, _ac, _aj = (numba_fn for numba_fn in
                      (__import__("numba").njit(f) for f in andrews_bodies(np)))


@cfunc(MASS)
def an_mass(t, q, M, user):
    _am(carray(q, 7), carray(M, 49))
    return 0


@cfunc(FORCE)
def an_force(t, q, v, f, user):
    _af(carray(q, 7), carray(v, 7), carray(f, 7))
    return 0


@cfunc(CONSTRAINT)
def an_constraint(t, q, g, user):
    _ac(carray(q, 7), carray(g, 6))
    return 0


@cfunc(CONSTRAINT)
def an_jacobian(t, q, G, user):
    _aj(carray(q, 7), carray(G, 42))
    return 0


def andrews_python():
    mass, force, constraint, jacobian = andrews_bodies(np)
    return (lambda t, q, M: mass(q, M.reshape(-1, order="F")),
            lambda t, q, v, f: force(q, v, f),
            lambda t, q, g: constraint(q, g),
            lambda t, q, G: jacobian(q, G.reshape(-1, order="F")))


# ---- timing ---------------------------------------------------------------------------------
def per_step(callbacks, n, m, q0, v0, user, t_end, driver, h):
    # zero_copy: Python callbacks write straight into the library's buffers (the reshape in
    # andrews_python must be a view of them)
    with galpha.Solver(n, m, *callbacks, user=user, tolerances=(1e-6, 1e-6), zero_copy=True,
                       formulation=galpha.GA_INDEX2_STABILIZED) as s:
        s.init(0.0, q0, v0)
        t0 = time.perf_counter()
        if driver == "advance":
            s.advance(t_end)
        else:
            for _ in range(round(t_end / h)):
                s.step(h)
        dt = time.perf_counter() - t0
        return dt / s.stats["steps"], s.q.copy(), s.stats["steps"]


def main(lib_path, c_driver):
    lib = ctypes.CDLL(lib_path)
    address = lambda name: ctypes.cast(getattr(lib, name), ctypes.c_void_p).value  # noqa: E731
    pe_user = np.array([1.0, 1.0, 9.81])
    pe_q0 = [math.sin(1.0), -math.cos(1.0)]
    scenes = {
        "pendulum": (2, 1, pe_q0, [0.0, 0.0], pe_user, 5.0, 1e-3, {
            "c": [address("pendulum_" + k) for k in ("mass", "force", "constraint", "jacobian")],
            "numba": (pe_mass, pe_force, pe_constraint, pe_jacobian),
            "python": pendulum_python(pe_user)}),
        "andrews": (7, 6, Q0, [0.0] * 7, None, 0.03, 1e-5, {
            "c": [address("an7_" + k) for k in ("mass", "force", "constraint", "jacobian")],
            "numba": (an_mass, an_force, an_constraint, an_jacobian),
            "python": andrews_python()}),
    }
    best, native = {}, {}

    def run_c_driver():
        rows = csv.DictReader(io.StringIO(subprocess.run(
            [c_driver], check=True, capture_output=True, text=True).stdout))
        for r in rows:
            key, t = (r["scene"], r["driver"]), 1e-6 * float(r["us_per_step"])
            if key not in native or t < native[key][0]:
                native[key] = (t, int(r["steps"]))
    for _ in range(5):  # interleaved rounds: the machine's speed drifts
        run_c_driver()
        for scene, (n, m, q0, v0, user, t_end, h, models) in scenes.items():
            for driver in ("advance", "step"):
                for kind, cbs in models.items():
                    if kind == "python" and _ > 1:
                        continue  # (slow; three rounds of it are enough)
                    t, q, steps = per_step(cbs, n, m, q0, v0, user, t_end, driver, h)
                    key = (scene, driver, kind)
                    if key not in best or t < best[key][0]:
                        best[key] = (t, q, steps)
    print("scene,driver,callbacks,us_per_step,steps,ratio_to_c_callbacks,ratio_to_c_driver,"
          "max_diff_to_c_callbacks")
    for (scene, driver), (t, steps) in sorted(native.items()):
        print("%s,%s,c_driver,%.3f,%d,,1.00," % (scene, driver, 1e6 * t, steps))
    for (scene, driver, kind), (t, q, steps) in sorted(best.items()):
        c = best[(scene, driver, "c")]
        print("%s,%s,%s,%.3f,%d,%.2f,%.2f,%.1e" % (
            scene, driver, kind, 1e6 * t, steps, t / c[0], t / native[(scene, driver)][0],
            np.max(np.abs(q - c[1]))))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
