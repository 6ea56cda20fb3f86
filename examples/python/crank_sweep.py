#!/usr/bin/python3
"""A parameter sweep with galpha.ensemble: the slider-crank of identify_crank.py over a grid of
spring stiffness k and damping c, the peak crank torque and the final crank angle of each run,
as heat maps.

The model's callbacks and a step hook are numba-compiled (no Python in a step); the hook keeps
the peak of the torque the rod's joint exerts on the crank, (Phi_q^T lambda)_theta, in the
array the callbacks read (k, c, peak). `crank` builds the model at module level, so that any
engine's workers can import it.

Usage: crank_sweep.py [--n 12] [--t-end 2] [--engine serial|threads|processes|dask|mpi]
                      [--workers 2] [--plot FILE.png]
Needs numba (python3-numba); --engine dask python3-distributed, mpi python3-mpi4py (run under
mpirun), --plot python3-matplotlib."""
import argparse
import math
import os
import sys
import time

import numpy as np
from numba import carray, cfunc, types

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "bindings", "python"))
import galpha  # noqa: E402
import galpha.ensemble  # noqa: E402

A, J1, M2, J2, L0, F = 0.5, 1.0, 1.0, 2.0, 1.0, 1.0
dp, vp = types.CPointer(types.float64), types.voidptr


@cfunc(types.int32(types.float64, dp, dp, vp))
def mass(t, q, M, user):
    out = carray(M, 9)
    for k in range(9):
        out[k] = 0.0
    out[0], out[4], out[8] = J1, M2, J2
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, vp))
def force(t, q, v, f, user):
    p, x, xd, out = carray(user, 3, np.float64), carray(q, 3), carray(v, 3), carray(f, 3)
    th, s, ph = x[0], x[1], x[2]
    l2 = s * s - s * (math.cos(ph) + A * math.cos(th)) + 0.25 * (1 + A * A) + \
        0.5 * A * math.cos(ph - th)
    g0 = A * s * math.sin(th) + 0.5 * A * math.sin(ph - th)  # d(l^2)/dq
    g1 = 2 * s - math.cos(ph) - A * math.cos(th)
    g2 = s * math.sin(ph) - 0.5 * A * math.sin(ph - th)
    l = math.sqrt(l2)
    tension = p[0] * (l - L0) + p[1] * (g0 * xd[0] + g1 * xd[1] + g2 * xd[2]) / (2 * l)
    out[0] = -tension * g0 / (2 * l)
    out[1] = -tension * g1 / (2 * l) + F
    out[2] = -tension * g2 / (2 * l) - F * math.sin(ph)
    return 0


@cfunc(types.int32(types.float64, dp, dp, vp))
def constraint(t, q, phi, user):
    x, out = carray(q, 3), carray(phi, 2)
    out[0] = x[1] - math.cos(x[2]) - A * math.cos(x[0])
    out[1] = -math.sin(x[2]) - A * math.sin(x[0])
    return 0


@cfunc(types.int32(types.float64, dp, dp, vp))
def jacobian(t, q, J, user):
    x, out = carray(q, 3), carray(J, 6)  # 2 x 3, column-major
    out[0], out[1] = A * math.sin(x[0]), -A * math.cos(x[0])
    out[2], out[3] = 1.0, 0.0
    out[4], out[5] = math.sin(x[2]), -math.cos(x[2])
    return 0


@cfunc(types.int32(vp, types.float64, dp, dp, dp, vp))
def peak_torque(solver, t, q, v, lam, user):
    p, x, mu = carray(user, 3, np.float64), carray(q, 3), carray(lam, 2)
    torque = A * math.sin(x[0]) * mu[0] - A * math.cos(x[0]) * mu[1]
    p[2] = max(p[2], abs(torque))
    return 0


def crank():
    """The model: a solver over the compiled callbacks, parameters (k, c) in p[:2]."""
    p = np.array([1.0, 1.0, 0.0])
    ph = math.asin(-A)
    q0 = np.array([math.pi / 2, math.cos(ph), ph])
    s = galpha.Solver(3, 2, mass, force, constraint, jacobian, user=p, tolerances=(1e-6, 1e-6),
                      formulation=galpha.GA_INDEX2_STABILIZED)
    s.set_step_hook(peak_torque, multipliers=True)

    def start(_):
        p[2] = 0.0  # the hook's peak, per run
        return 0.0, q0, np.zeros(3)
    return galpha.ensemble.Case(s, p[:2], start=start,
                                summary=lambda s: {"peak_torque": p[2], "angle": s.q[0]})


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--n", type=int, default=12, help="grid points per parameter")
    a.add_argument("--t-end", type=float, default=2.0)
    a.add_argument("--engine", default="processes",
                   choices=("serial", "threads", "processes", "dask", "mpi"))
    a.add_argument("--workers", type=int, default=2)
    a.add_argument("--plot")
    args = a.parse_args()
    k, c = np.meshgrid(np.linspace(1.0, 5.0, args.n), np.linspace(0.1, 1.0, args.n),
                       indexing="ij")
    grid = np.column_stack([k.ravel(), c.ravel()])
    client = None
    if args.engine == "dask":  # (on a real cluster: Client("scheduler:8786"), the same call)
        from distributed import Client, LocalCluster
        here = os.path.dirname(os.path.abspath(__file__))
        os.environ["PYTHONPATH"] = os.pathsep.join(  # the workers import this module
            [here, os.path.join(here, "..", "..", "bindings", "python")] +
            [x for x in [os.environ.get("PYTHONPATH")] if x])
        client = Client(LocalCluster(n_workers=args.workers, threads_per_worker=1,
                                     dashboard_address=None))
    t0 = time.perf_counter()
    res = galpha.ensemble.run(crank, grid, [args.t_end], engine=args.engine,
                              workers=args.workers, client=client)
    if res is None:  # an MPI rank other than 0
        return
    print("%d runs of %g s in %.1f s (%s, %d workers), %d failed, %d steps in all" % (
        len(grid), args.t_end, time.perf_counter() - t0, args.engine, args.workers,
        len(res.failures), res.steps.sum()))
    torque = res.summary["peak_torque"].reshape(args.n, args.n)
    angle = res.summary["angle"].reshape(args.n, args.n)
    i, j = np.unravel_index(np.nanargmax(torque), torque.shape)
    print("largest peak crank torque %.4f N m at k = %.2f, c = %.2f" % (torque[i, j], k[i, j],
                                                                      c[i, j]))
    if args.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
        extent = (0.1, 1.0, 1.0, 5.0)
        for ax, z, title in ((axes[0], torque, "peak crank torque [N m]"),
                             (axes[1], angle, "crank angle at t = %g s [rad]" % args.t_end)):
            im = ax.imshow(z, origin="lower", extent=extent, aspect="auto")
            ax.set_xlabel("damping c")
            ax.set_ylabel("stiffness k")
            ax.set_title(title)
            fig.colorbar(im, ax=ax)
        fig.savefig(args.plot, dpi=100)
        print("heat maps:", args.plot)
    if client is not None:
        client.close()


if __name__ == "__main__":  # workers find the model as crank_sweep.crank, not __main__.crank
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import crank_sweep
    crank_sweep.main()
