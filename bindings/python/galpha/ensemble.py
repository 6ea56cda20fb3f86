"""One model over many parameter sets (and initial values): parameter sweeps, Monte-Carlo,
the inner loop of an optimization -- on local threads, local processes, a Dask cluster or MPI
ranks, with the same results bit for bit whatever the engine and the number of workers.
For example::

    def crank():                       # module level: workers import it by name
        p = np.zeros(2)                # the array the callbacks read
        return galpha.ensemble.Case(galpha.Solver(3, 2, *model(p), ...), p, q0, v0)

    res = galpha.ensemble.run(crank, grid, times=[0.5, 1.0], engine="processes", workers=2)
    res.q[i, k]    # run i at times[k];  res.status[i] == 0 unless run i failed

A model is a picklable callable without arguments (a module-level function) that builds a Case:
the solver and the array its callbacks read the parameters from. Each worker builds it once and
reuses it: every run writes its parameter set into that array and restarts the solver with
init() (the documented restart: a run does not depend on the runs before it). A failed run is
data (status, message), not an exception that ends the sweep.

Engines: "serial"; "threads" (the C library is re-entrant and ctypes releases the GIL while it
runs, so compiled callbacks run in parallel; Python callbacks take the GIL); "processes"
(concurrent.futures); client=<dask.distributed.Client> (Debian: python3-distributed); "mpi"
(mpi4py, Debian: python3-mpi4py): every rank calls run() with the same arguments, rank 0 gets
the result, the others None -- `mpirun -n 2 python3 -m galpha.ensemble module:model ...` runs a
sweep from the command line. Nothing here imports dask or mpi4py unless asked for.
"""
import concurrent.futures
import inspect
import math
import os
import pickle
import threading
from typing import Any, Callable, Optional, Sequence

import numpy as np

from .errors import GalphaError
from .integrate import _Fields, _progress_bar

__all__ = ["Case", "EnsembleResult", "Interrupted", "run"]


class Case:
    """What a model builds once per worker.

    solver : galpha.Solver
        With its options and callbacks set (a step hook too, for on-line reductions).
    parameters : 1-D float64 array
        The array the callbacks read the model's parameters from; each run writes its set here.
    q0, v0 (, y0), t0
        Initial values of every run, unless run(initial=...) gives them per run.
    start : callable(parameters) -> (t0, q0, v0) or (t0, q0, v0, y0), optional
        Initial values that depend on the parameters (called after they are written, before
        every run; run(initial=...) overrides the values, not t0); also the place to reset
        what a step hook accumulates.
    summary : callable(solver) -> dict of numbers or arrays, optional
        Per-run results after the last output time (a peak recorded by the hook, an energy).
    """

    def __init__(self, solver, parameters, q0=None, v0=None, t0=0.0, y0=None, start=None,
                 summary=None):
        p = parameters
        if not (isinstance(p, np.ndarray) and p.dtype == np.float64 and p.ndim == 1 and
                p.flags.writeable):
            raise ValueError("parameters must be the writeable 1-D float64 array the "
                             "callbacks read")
        if start is None and (q0 is None or v0 is None):
            raise ValueError("give q0 and v0, or start(parameters)")
        self.solver, self.parameters = solver, p
        self.q0, self.v0, self.t0, self.y0 = q0, v0, float(t0), y0
        self.start, self.summary = start, summary


class EnsembleResult(_Fields):
    """times (T,); q, v (runs, T, n); lam (runs, T, m); y (runs, T, r) with first-order states;
    status (runs,) 0, 1 if a terminal event or the step hook ended the run before the last
    output time (what it reached is recorded; Case.summary is called), 2 for a run an
    interrupted sweep did not make (Interrupted.result), or the negative
    ga_status of a failure (-4 for an exception in a callback); message (list of str, "" for
    success); steps (runs,) accepted steps; summary: dict of
    arrays (runs, ...) from Case.summary (NaN for failed runs); failures: [(run, message)].
    Values not reached by a failed run are NaN."""

    def __repr__(self):
        return "EnsembleResult(runs=%d, outputs=%d, failed=%d)" % (
            len(self["status"]), len(self["times"]), int(np.count_nonzero(self["status"] < 0)))


# ---- one worker --------------------------------------------------------------------------
_local = threading.local()  # per thread (and so per process): the cases built here


def _case(model):
    cases = getattr(_local, "cases", None)
    if cases is None:
        cases = _local.cases = {}
    try:
        hash(model)
        key = model
    except TypeError:
        key = pickle.dumps(model)
    case = cases.get(key)
    if case is None:
        case = model()
        if not isinstance(case, Case):  # (checked before it is kept: every chunk says so)
            raise TypeError("the model must return a galpha.ensemble.Case, not %s"
                            % type(case).__name__)
        cases[key] = case
    return case


def _one(case, p, init, times, h):
    """One run: (q, v, lam, y) at the times, status, message, steps, summary."""
    s = case.solver
    n, m, r = s.n, s.m, s.r
    out = [np.full((len(times), k), np.nan) for k in (n, n, m, r)]
    if p.shape != case.parameters.shape:
        raise ValueError("a parameter set of %d values for a model of %d parameters"
                         % (p.size, case.parameters.size))
    case.parameters[:] = p
    status, message, summary = 0, "", None
    s.reset_counters()
    try:
        if case.start is not None:  # (called also with per-run initial values: it resets)
            t0, *values = case.start(case.parameters)
        else:
            t0, values = case.t0, (case.q0, case.v0) + ((case.y0,) if r else ())
        if init is not None:
            values = init
        s.init(float(t0), *values)
        for k, t in enumerate(times):
            stopped = False
            if t > s.t:
                if h is None:
                    stopped = s.advance(t)
                else:
                    while s.t < t and not stopped:
                        left = t - s.t
                        stopped = s.step(h if left > h * (1 + 1e-9) else left)
            if stopped and s.t < t:  # a terminal event or the step hook ended the run
                status, message = 1, "stopped at t = %.17g (a terminal event or the step " \
                    "hook)" % s.t
                break
            out[0][k], out[1][k], out[2][k] = s.q, s.v, s.lam
            if r:
                out[3][k] = s.y
        if case.summary is not None:
            summary = case.summary(s)
    except GalphaError as e:
        status, message = e.status, str(e)
    except Exception as e:  # a callback's exception: this run's failure, not the sweep's
        status, message = -4, "%s: %s" % (type(e).__name__, e)
    return out, status, message, s.stats["steps"], summary


def _run_chunk(model, indices, P, initial, times, h, cancel=None):
    """Runs the parameter sets P (rows) with this worker's case of the model; with `cancel`
    (threads: a threading.Event) it stops between runs once that is set."""
    case = _case(model)
    results = []
    for k, i in enumerate(indices):
        if cancel is not None and cancel.is_set():
            break
        init = None if initial is None else tuple(x[k] for x in initial)
        results.append((int(i),) + _one(case, P[k], init, times, h))
    return results


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during run(): the pending runs were cancelled and the workers stopped (processes
    terminated); `result` is the EnsembleResult of the runs that finished, those that did not
    with status 2 ("not run") and NaN values."""

    def __init__(self, result):
        super().__init__("ensemble interrupted: %d of %d runs finished"
                         % (int(np.count_nonzero(result.status != 2)), len(result.status)))
        self.result = result


# ---- the whole sweep ---------------------------------------------------------------------
def _chunks(runs, pieces):
    size = max(1, math.ceil(runs / max(1, pieces)))
    return [np.arange(a, min(a + size, runs)) for a in range(0, runs, size)]


def run(model: Callable[[], "Case"], parameters: Any, times: Any, *, initial: Any = None,
        h: Optional[float] = None, engine: str = "serial", workers: Optional[int] = None,
        client: Any = None, chunk_size: Optional[int] = None, comm: Any = None,
        progress: Optional[bool] = None) -> "EnsembleResult":
    """Run `model` once per row of `parameters` (runs x np) and record q, v, lam (and y) at
    `times` (increasing; a time equal to the start records the initial state).

    Parameters
    ----------
    model : callable
        Builds the Case (module level, so that workers import it by name).
    parameters : array (runs, np)
        One parameter set per run.
    times : array
        The output times.
    initial : (q0s, v0s) or (q0s, v0s, y0s), optional
        Per-run initial values (arrays with a row per run) instead of the Case's.
    h : float, optional
        Fixed steps of h (shortened to land on each output time); default adaptive (advance()
        with the solver's tolerances).
    engine : "serial", "threads", "processes", "dask" or "mpi"
        "dask" with client= (a dask.distributed.Client; given a client, engine may be left).
    client : dask.distributed.Client, optional
        The cluster for engine="dask".
    workers : int, optional
        Threads or processes (default: os.cpu_count()).
    chunk_size : int, optional
        Runs per task (default: about four tasks per worker, each worker reusing its case).
    comm : mpi4py communicator, optional
        For engine="mpi" (default COMM_WORLD).
    progress : bool or None, optional
        A progress bar over the runs (tqdm, optional; not under MPI): None shows it on a
        terminal once the sweep has lasted a second, True always, False never.

    Returns
    -------
    EnsembleResult
    """
    # A script without `if __name__ == "__main__":` runs its sweep again in every process that
    # imports it as __mp_main__ (the spawned workers of processes, Dask's LocalCluster): they
    # would start workers of their own, without end (a Dask script hung for over ten minutes).
    caller = inspect.currentframe().f_back
    if caller is not None and caller.f_globals.get("__name__") == "__mp_main__":
        raise RuntimeError("galpha.ensemble.run() called while a worker process imports the "
                           "main script: put the sweep under `if __name__ == \"__main__\":`")
    P = np.ascontiguousarray(parameters, dtype=float)
    if P.ndim == 1:
        P = P[:, None]
    if P.ndim != 2:
        raise ValueError("parameters: one row per run")
    runs = P.shape[0]
    if runs == 0:
        raise ValueError("parameters: no runs")
    times = np.asarray(times, dtype=float).ravel()
    if times.size == 0 or np.any(np.diff(times) <= 0) or not np.all(np.isfinite(times)):
        raise ValueError("times must be finite and increasing")
    if initial is not None:
        initial = tuple(np.asarray(x, dtype=float).reshape(runs, -1) for x in initial)
    if h is not None and not (float(h) > 0 and math.isfinite(float(h))):
        raise ValueError("h must be positive and finite")
    if client is not None:
        engine = "dask"
    if engine not in ("serial", "threads", "processes", "dask", "mpi"):
        raise ValueError("unknown engine %r" % (engine,))
    workers = int(workers or os.cpu_count() or 1)

    def task(idx, cancel=None):
        return (model, idx, P[idx], None if initial is None else tuple(x[idx] for x in initial),
                times, h, cancel)

    if engine == "mpi":
        if comm is None:
            from mpi4py import MPI
            comm = MPI.COMM_WORLD
        size, rank = comm.Get_size(), comm.Get_rank()
        pieces = _chunks(runs, size * 4 if chunk_size is None else math.ceil(runs / chunk_size))
        try:  # a rank that cannot run says so in the gather instead of leaving it hanging
            mine, error = [r for c in pieces[rank::size] for r in _run_chunk(*task(c))], None
        except Exception as e:
            mine, error = [], "rank %d: %s: %s" % (rank, type(e).__name__, e)
        gathered = comm.gather((mine, error), root=0)
        if rank != 0:
            if error:
                raise RuntimeError(error)
            return None
        errors = [e for _, e in gathered if e]
        if errors:
            raise RuntimeError("ensemble under MPI: " + "; ".join(errors))
        results = [r for part, _ in gathered for r in part]
    else:
        if engine == "serial":  # (chunks only for the progress bar)
            pieces = _chunks(runs, math.ceil(runs / (chunk_size or max(1, runs // 100))))
        else:
            pieces = _chunks(runs, workers * 4 if chunk_size is None
                             else math.ceil(runs / chunk_size))
        bar = _progress_bar(progress, 0, runs, unit="run")
        results = []

        def collect(part):
            results.extend(part)
            if bar is not None:
                bar.update(len(part))
        cancel = threading.Event()
        ex = futures = None
        try:
            if engine == "serial":
                for c in pieces:
                    collect(_run_chunk(*task(c)))
            elif engine == "dask":
                if client is None:
                    raise ValueError("engine='dask' needs client= (a dask.distributed.Client)")
                from distributed import as_completed
                futures = [client.submit(_run_chunk, *task(c), pure=False) for c in pieces]
                for f in as_completed(futures):
                    collect(f.result())
            else:
                threads = engine == "threads"
                ex = (concurrent.futures.ThreadPoolExecutor if threads else
                      concurrent.futures.ProcessPoolExecutor)(max_workers=workers)
                futures = [ex.submit(_run_chunk, *task(c, cancel if threads else None))
                           for c in pieces]
                for f in concurrent.futures.as_completed(futures):
                    collect(f.result())
        except KeyboardInterrupt:
            # Stop now: nothing pending runs, running chunks end (threads between runs,
            # processes terminated), and what finished is handed back.
            cancel.set()
            if engine == "dask" and futures:
                client.cancel(futures)
            elif ex is not None:
                for f in futures or ():
                    f.cancel()
                if engine == "threads":  # finished runs of the chunks that stop now
                    ex.shutdown(wait=True)
                    for f in futures or ():
                        if f.done() and not f.cancelled() and f.exception() is None:
                            part = f.result()
                            if part and part[0][0] not in {r[0] for r in results}:
                                collect(part)
                else:
                    _terminate(ex)
                ex = None
            raise Interrupted(_stack(results, runs, times, partial=True)) from None
        finally:
            if ex is not None:
                ex.shutdown(wait=True)
            if bar is not None:
                bar.close()
    return _stack(results, runs, times)


def _terminate(ex):
    """A process pool's workers, running or idle, terminated and reaped."""
    processes = list(getattr(ex, "_processes", {}).values())
    ex.shutdown(wait=False, cancel_futures=True)
    for p in processes:
        if p.is_alive():
            p.terminate()
    for p in processes:
        p.join(timeout=5)


def _stack(results, runs, times, partial=False):
    results = sorted(results, key=lambda r: r[0])
    if partial:  # (an interrupted sweep: the runs not made, as "not run")
        done = {r[0] for r in results}
        shapes = results[0][1] if results else None
        for i in range(runs):
            if i not in done:
                out = ([np.full_like(x, np.nan) for x in shapes] if shapes is not None
                       else [np.full((len(times), 0), np.nan)] * 4)
                results.append((i, out, 2, "not run: the sweep was interrupted", 0, None))
        results = sorted(results, key=lambda r: r[0])
    if [r[0] for r in results] != list(range(runs)):
        raise RuntimeError("ensemble: runs missing from the workers' results")
    q, v, lam, y = (np.stack([r[1][k] for r in results]) for k in range(4))
    status = np.array([r[2] for r in results], dtype=int)
    message = [r[3] for r in results]
    steps = np.array([r[4] for r in results], dtype=np.int64)
    summary = {}
    first = next((r[5] for r in results if r[5] is not None), None)
    for key in (first or {}):
        shape = np.shape(first[key])
        summary[key] = np.stack([np.asarray(r[5][key], dtype=float) if r[5] is not None
                                 else np.full(shape, np.nan) for r in results])
    res = EnsembleResult(times=times, q=q, v=v, lam=lam, status=status, message=message,
                         steps=steps, summary=summary,
                         failures=[(i, message[i]) for i in np.flatnonzero(status < 0)])
    if y.shape[2]:
        res["y"] = y
    return res


# ---- command line: python3 -m galpha.ensemble module:model params.npy --times ... ----------
def main(argv: Optional[Sequence[str]] = None) -> int:
    """`python3 -m galpha.ensemble MODULE:MODEL PARAMETERS.npy ...`: run() from the command
    line (--help lists the options)."""
    import argparse
    import importlib
    parser = argparse.ArgumentParser(
        prog="python3 -m galpha.ensemble",
        description="Run a model over the parameter sets of a .npy file (one row per run) and "
                    "save the stacked results to an .npz file. Under mpirun with --engine mpi, "
                    "each rank takes a share.")
    parser.add_argument("model", help="module:function building a galpha.ensemble.Case")
    parser.add_argument("parameters", help=".npy file, one row per run")
    parser.add_argument("--times", type=float, nargs="+", required=True)
    parser.add_argument("--engine", default="serial",
                        choices=("serial", "threads", "processes", "mpi"))
    parser.add_argument("--workers", type=int)
    parser.add_argument("--h", type=float)
    parser.add_argument("--out", default="ensemble.npz")
    a = parser.parse_args(argv)
    module, _, name = a.model.partition(":")
    model = getattr(importlib.import_module(module), name)
    res = run(model, np.load(a.parameters), a.times, h=a.h, engine=a.engine, workers=a.workers)
    if res is None:  # an MPI rank other than 0
        return 0
    arrays = {k: res[k] for k in ("times", "q", "v", "lam", "status", "steps")}
    arrays.update({"summary_" + k: x for k, x in res.summary.items()})
    if "y" in res:
        arrays["y"] = res.y
    np.savez(a.out, message=np.array(res.message, dtype=str), **arrays)
    print("%d runs, %d failed -> %s" % (len(res.status), len(res.failures), a.out))
    return 0


if __name__ == "__main__":  # run as the package's module, whose Case the models return
    from galpha.ensemble import main as _main
    raise SystemExit(_main())
