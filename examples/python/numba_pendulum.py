#!/usr/bin/python3
"""The pendulum of pendulum.py with numba-compiled callbacks: galpha calls them from C, without
Python in the step. The model's parameters (mass, length, gravity) reach them through `user`,
a numpy array passed as void *; a compiled step hook records the peak rod force on the fly.

Needs numba (Debian: python3-numba); galpha itself does not."""
import math
import os
import sys

import numpy as np
from numba import carray, cfunc, types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402

# The C signatures of galpha.h, written once: double *, and void *user last.
dp, vp = types.CPointer(types.float64), types.voidptr
MASS_SIG = types.int32(types.float64, dp, dp, vp)            # ga_mass_fn
FORCE_SIG = types.int32(types.float64, dp, dp, dp, vp)       # ga_force_fn
CONSTRAINT_SIG = types.int32(types.float64, dp, dp, vp)      # ga_constraint_fn, ga_jacobian_fn
HOOK_SIG = types.int32(vp, types.float64, dp, dp, dp, vp)    # ga_step_hook_fn


@cfunc(MASS_SIG)
def mass(t, q, M, user):
    p = carray(user, 4, np.float64)
    out = carray(M, 4)
    out[0], out[1], out[2], out[3] = p[0], 0.0, 0.0, p[0]
    return 0


@cfunc(FORCE_SIG)
def force(t, q, v, f, user):
    p = carray(user, 4, np.float64)
    out = carray(f, 2)
    out[0] = 0.0
    out[1] = -p[0] * p[2]
    return 0


@cfunc(CONSTRAINT_SIG)
def constraint(t, q, phi, user):
    p = carray(user, 4, np.float64)
    x = carray(q, 2)
    carray(phi, 1)[0] = 0.5 * (x[0] * x[0] + x[1] * x[1] - p[1] * p[1])
    return 0


@cfunc(CONSTRAINT_SIG)
def jacobian(t, q, J, user):
    x, out = carray(q, 2), carray(J, 2)
    out[0], out[1] = x[0], x[1]
    return 0


@cfunc(HOOK_SIG)
def peak_force(solver, t, q, v, lam, user):
    # the rod force is lambda |Phi_q| = lambda L; lam is passed (multipliers=True)
    p = carray(user, 4, np.float64)
    p[3] = max(p[3], abs(carray(lam, 1)[0]) * p[1])
    return 0


def main():
    p = np.array([1.0, 1.0, 9.81, 0.0])  # mass, length, gravity, peak rod force (the hook's)
    theta0 = 1.0
    q0 = [math.sin(theta0), -math.cos(theta0)]
    with galpha.Solver(2, 1, mass, force, constraint, jacobian, user=p, rho_inf=0.9,
                       formulation=galpha.GA_INDEX2_STABILIZED, tolerances=(1e-7, 1e-7)) as s:
        s.set_step_hook(peak_force, multipliers=True)
        s.init(0.0, q0, [0.0, 0.0])
        s.advance(10.0)
        # the exact peak, at the bottom: m g (3 - 2 cos theta0)
        exact = p[0] * p[2] * (3.0 - 2.0 * math.cos(theta0))
        print("steps =", s.stats["steps"])
        print("peak rod force = %.9f N (exact %.9f)" % (p[3], exact))


if __name__ == "__main__":
    main()
