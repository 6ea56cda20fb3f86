#!/usr/bin/python3
"""Throughput of galpha.ensemble: 1 000 slider-crank runs of 1 s simulated time (the model of
examples/python/crank_sweep.py, numba-compiled callbacks and step hook) on each engine with 1
and 2 workers, and the overhead per task (runs one per task against the default chunks). CSV on
stdout: engine, workers, chunk, seconds, runs per second, overhead per run against serial (us),
and whether the results equal the serial run's bit for bit.

Usage: ensemble_scaling.py [RUNS]  (needs numba; Dask and MPI rows if python3-distributed,
python3-mpi4py and mpirun are there)"""
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = os.path.join(HERE, "..", "examples", "python")
PACKAGE = os.path.join(HERE, "..", "bindings", "python")
sys.path[:0] = [EXAMPLES, PACKAGE]
os.environ["PYTHONPATH"] = os.pathsep.join([EXAMPLES, PACKAGE] + [
    x for x in [os.environ.get("PYTHONPATH")] if x])  # for Dask's and MPI's new processes
import galpha.ensemble  # noqa: E402
import crank_sweep  # noqa: E402

RUNS = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
T_END = 1.0
rng = np.random.default_rng(7)
GRID = np.column_stack([rng.uniform(1.0, 5.0, RUNS), rng.uniform(0.1, 1.0, RUNS)])

MPI_SCRIPT = """
import sys, time, numpy as np
import galpha.ensemble, crank_sweep
from mpi4py import MPI
grid = np.load(sys.argv[1])
chunk = int(sys.argv[3]) or None
galpha.ensemble.run(crank_sweep.crank, grid[:4], [1.0], engine="mpi")  # warm-up: compiled model
MPI.COMM_WORLD.Barrier()
t0 = time.perf_counter()
res = galpha.ensemble.run(crank_sweep.crank, grid, [1.0], engine="mpi", chunk_size=chunk)
if res is not None:
    np.savez(sys.argv[2], seconds=time.perf_counter() - t0, q=res.q)
"""


def timed(engine, workers, chunk, client=None):
    # warm-up: each worker builds (and numba compiles) its model once, outside the timing
    galpha.ensemble.run(crank_sweep.crank, GRID[:2 * workers], [T_END], engine=engine,
                        workers=workers, client=client, chunk_size=1)
    t0 = time.perf_counter()
    res = galpha.ensemble.run(crank_sweep.crank, GRID, [T_END], engine=engine, workers=workers,
                              client=client, chunk_size=chunk)
    return time.perf_counter() - t0, res.q


def mpi_timed(workers, chunk):
    with tempfile.TemporaryDirectory() as d:
        np.save(os.path.join(d, "grid.npy"), GRID)
        script = os.path.join(d, "run.py")
        with open(script, "w") as f:
            f.write(MPI_SCRIPT)
        out = os.path.join(d, "out.npz")
        env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                   OMPI_MCA_rmaps_base_oversubscribe="1")
        subprocess.run(["mpirun", "-n", str(workers), sys.executable, script,
                        os.path.join(d, "grid.npy"), out, str(chunk or 0)], env=env, check=True,
                       capture_output=True)
        r = np.load(out)
        return float(r["seconds"]), r["q"]


def main():
    rows = []
    serial_t, serial_q = timed("serial", 1, None)
    rows.append(("serial", 1, "all", serial_t, serial_q))
    for engine in ("threads", "processes"):
        for workers in (1, 2):
            rows.append((engine, workers, "default") + timed(engine, workers, None))
        rows.append((engine, 2, 1) + timed(engine, 2, 1))
    try:
        from distributed import Client, LocalCluster
        for workers in (1, 2):
            with LocalCluster(n_workers=workers, threads_per_worker=1,
                              dashboard_address=None) as cluster, Client(cluster) as client:
                rows.append(("dask", workers, "default") +
                            timed("dask", workers, None, client))
                if workers == 2:
                    rows.append(("dask", 2, 1) + timed("dask", 2, 1, client))
    except ImportError:
        pass
    if shutil.which("mpirun"):
        try:
            import mpi4py  # noqa: F401
            for workers in (1, 2):
                rows.append(("mpi", workers, "default") + mpi_timed(workers, None))
            rows.append(("mpi", 2, 1) + mpi_timed(2, 1))
        except ImportError:
            pass
    print("engine,workers,chunk,seconds,runs_per_second,overhead_us_per_run,same_as_serial")
    for engine, workers, chunk, t, q in rows:
        overhead = (t * workers - serial_t) / RUNS * 1e6  # worker-seconds beyond serial's
        print("%s,%d,%s,%.3f,%.0f,%.0f,%s" % (engine, workers, chunk, t, RUNS / t, overhead,
                                             np.array_equal(q, serial_q)))


if __name__ == "__main__":
    main()
