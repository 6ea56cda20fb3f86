"""galpha.ensemble: one model over many parameter sets on every engine, bit for bit the results
of serial runs; a run on a reused solver (restarted by init) equals one on a fresh solver;
failures are data."""
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.join(HERE, "..", "..", "bindings", "python")
if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, PACKAGE)
sys.path.insert(0, HERE)
import galpha  # noqa: E402
import galpha.ensemble  # noqa: E402
import ensemble_models  # noqa: E402

# What a subprocess needs to import the galpha this process imported (the source tree's, or
# an installed one) and to load the same library: the build tree may lie anywhere.
SUBPROCESS_PATH = os.pathsep.join([HERE, os.path.dirname(os.path.dirname(galpha.__file__))])
SUBPROCESS_LIBRARY = galpha._ffi.path

GRID = np.array([[L, g] for L in (0.5, 1.0, 1.5, 2.0) for g in (9.0, 9.81, 11.0)])
TIMES = [0.0, 0.2, 0.4]


def same(a, b):
    for key in ("times", "q", "v", "lam", "status", "steps"):
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    assert a.message == b.message
    assert a.summary.keys() == b.summary.keys()
    for key in a.summary:
        np.testing.assert_array_equal(a.summary[key], b.summary[key], err_msg=key)


@pytest.fixture(scope="module")
def serial():
    return galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES)


def test_reused_solver_equals_fresh_solvers(serial):
    assert serial.q.shape == (len(GRID), len(TIMES), 2) and not serial.failures
    for i, p in enumerate(GRID):
        fresh = galpha.ensemble.run(ensemble_models.pendulum, p[None, :], TIMES)
        for key in ("q", "v", "lam", "steps"):
            np.testing.assert_array_equal(fresh[key][0], serial[key][i])
    # the runs are what they claim: on the circle of their length, released from 1 rad
    L = GRID[:, 0]
    np.testing.assert_allclose(np.hypot(serial.q[:, :, 0], serial.q[:, :, 1]),
                               np.repeat(L[:, None], len(TIMES), 1), rtol=1e-9)
    np.testing.assert_allclose(serial.q[:, 0, 0], L * np.sin(1.0), rtol=1e-15)
    # energy per unit mass at the end: -g L cos(1) at release
    np.testing.assert_allclose(serial.summary["energy"], -GRID[:, 1] * L * np.cos(1.0),
                               rtol=1e-4)


def subset(res, idx):
    out = galpha.ensemble.EnsembleResult(res)
    for key in ("q", "v", "lam", "status", "steps"):
        out[key] = res[key][idx]
    out["message"] = [res.message[i] for i in idx]
    out["summary"] = {k: x[idx] for k, x in res.summary.items()}
    return out


@pytest.mark.parametrize("engine,workers,chunk", [("processes", 2, None), ("processes", 1, 5)])
def test_processes(serial, engine, workers, chunk):
    same(serial, galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES, engine=engine,
                                     workers=workers, chunk_size=chunk))


def test_threads_with_python_callbacks(serial):
    # (Python callbacks in threads contend for the GIL at every callback: correct, slow)
    idx = [0, 5, 10]
    same(subset(serial, idx), galpha.ensemble.run(ensemble_models.pendulum, GRID[idx], TIMES,
                                                  engine="threads", workers=2, chunk_size=1))


@pytest.mark.parametrize("workers,chunk", [(1, None), (2, None), (3, 1)])
def test_threads_with_compiled_callbacks(workers, chunk):
    pytest.importorskip("numba")
    serial = galpha.ensemble.run(ensemble_models.compiled_pendulum, GRID, TIMES)
    same(serial, galpha.ensemble.run(ensemble_models.compiled_pendulum, GRID, TIMES,
                                     engine="threads", workers=workers, chunk_size=chunk))
    # the compiled model is the Python one, arithmetic for arithmetic
    python = galpha.ensemble.run(ensemble_models.pendulum, GRID[:2], TIMES)
    for key in ("q", "v", "lam", "steps"):
        np.testing.assert_array_equal(python[key], serial[key][:2])
    np.testing.assert_array_equal(python.summary["peak_lambda"],
                                  serial.summary["peak_lambda"][:2])


def test_dask_local_cluster(serial):
    distributed = pytest.importorskip("distributed")
    # the workers are new processes: they find the test models and galpha by PYTHONPATH
    old = os.environ.get("PYTHONPATH"), os.environ.get("GALPHA_LIBRARY")
    os.environ["PYTHONPATH"] = os.pathsep.join([SUBPROCESS_PATH] + ([old[0]] if old[0] else []))
    os.environ["GALPHA_LIBRARY"] = SUBPROCESS_LIBRARY
    try:
        with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, \
                distributed.Client(cluster) as client:
            same(serial, galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES,
                                             client=client))
            same(serial, galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES,
                                             client=client, chunk_size=1))
    finally:
        for name, value in zip(("PYTHONPATH", "GALPHA_LIBRARY"), old):
            if value is None:
                del os.environ[name]
            else:
                os.environ[name] = value


def test_mpi_two_ranks(serial, tmp_path):
    pytest.importorskip("mpi4py")
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found (Debian: openmpi-bin)")
    np.save(tmp_path / "grid.npy", GRID)
    env = dict(os.environ, PYTHONPATH=SUBPROCESS_PATH, GALPHA_LIBRARY=SUBPROCESS_LIBRARY,
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    out = tmp_path / "res.npz"
    subprocess.run([mpirun, "-n", "2", sys.executable, "-m", "galpha.ensemble",
                    "ensemble_models:pendulum", str(tmp_path / "grid.npy"), "--times",
                    *map(str, TIMES), "--engine", "mpi", "--out", str(out)],
                   env=env, check=True, capture_output=True, timeout=300)
    res = np.load(out)
    for key in ("times", "q", "v", "lam", "status", "steps"):
        np.testing.assert_array_equal(res[key], serial[key], err_msg=key)
    np.testing.assert_array_equal(res["summary_peak_lambda"], serial.summary["peak_lambda"])


def test_failures_are_data(serial):
    grid = GRID.copy()
    grid[3, 1] = -1.0          # a callback raises
    grid[7, 0] = float("nan")  # NaN in the constraint: the library's failure
    res = galpha.ensemble.run(ensemble_models.pendulum, grid, TIMES, engine="processes",
                              workers=2)
    assert [i for i, _ in res.failures] == [3, 7]
    assert res.status[3] == -4 and "negative gravity" in res.message[3]
    assert res.status[7] < 0 and res.message[7]
    assert np.all(np.isnan(res.q[3])) and np.all(np.isnan(res.summary["peak_lambda"][[3, 7]]))
    ok = [i for i in range(len(grid)) if i not in (3, 7)]
    np.testing.assert_array_equal(res.q[ok], serial.q[ok])


def test_fixed_steps_and_initial_values():
    q0 = np.array([[math.sin(0.5), -math.cos(0.5)], [math.sin(1.0), -math.cos(1.0)]])
    v0 = np.zeros((2, 2))
    grid = np.array([[1.0, 9.81], [1.0, 9.81]])
    a = galpha.ensemble.run(ensemble_models.pendulum, grid, [0.25, 0.5], h=1e-3,
                            initial=(q0, v0))
    b = galpha.ensemble.run(ensemble_models.pendulum, grid, [0.25, 0.5], h=1e-3,
                            initial=(q0, v0), engine="threads", workers=2, chunk_size=1)
    same(a, b)
    assert a.steps[0] == 500
    np.testing.assert_array_equal(a.q[1], galpha.ensemble.run(
        ensemble_models.pendulum, grid[:1], [0.25, 0.5], h=1e-3).q[0])


def test_arguments():
    with pytest.raises(ValueError):
        galpha.ensemble.run(ensemble_models.pendulum, GRID, [1.0, 0.5])
    with pytest.raises(ValueError):
        galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES, engine="cloud")
    with pytest.raises(ValueError):
        galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES, engine="dask")
    with pytest.raises(TypeError):
        galpha.ensemble.run(lambda: 42, GRID, TIMES)


def test_the_sweep_example_model():
    # examples/python/crank_sweep.py: its compiled crank is identify_crank.py's Python one,
    # bit for bit, on every engine
    pytest.importorskip("numba")
    examples = os.path.join(HERE, "..", "..", "examples", "python")
    sys.path.insert(0, examples)
    try:
        import crank_sweep
        import identify_crank
    finally:
        sys.path.remove(examples)
    grid = np.array([[2.5, 0.4], [4.0, 0.2], [1.0, 1.0]])
    res = galpha.ensemble.run(crank_sweep.crank, grid, [0.5, 1.0], engine="threads", workers=2)
    q0, v0 = identify_crank.initial_state()
    for i, p in enumerate(grid):
        with galpha.Solver(3, 2, *identify_crank.model(p), tolerances=(1e-6, 1e-6),
                           formulation=galpha.GA_INDEX2_STABILIZED) as s:
            s.init(0.0, q0, v0)
            peak = [0.0]
            s.set_step_hook(lambda t, q, v, lam: peak.__setitem__(0, max(peak[0], abs(
                0.5 * np.sin(q[0]) * lam[0] - 0.5 * np.cos(q[0]) * lam[1]))), multipliers=True)
            for k, t in enumerate((0.5, 1.0)):
                s.advance(t)
                np.testing.assert_array_equal(res.q[i, k], s.q)
        np.testing.assert_allclose(res.summary["peak_torque"][i], peak[0], rtol=1e-14)
        assert res.summary["angle"][i] == res.q[i, 1, 0]


def test_progress_bar(capsys, serial):
    pytest.importorskip("tqdm")
    res = galpha.ensemble.run(ensemble_models.pendulum, GRID[:4], TIMES, engine="threads",
                              workers=2, chunk_size=1, progress=True)
    err = capsys.readouterr().err
    assert "galpha:" in err and "/4" in err
    same(subset(serial, [0, 1, 2, 3]), res)


def test_runs_ended_by_the_hook():
    grid = np.array([[0.5], [1.0], [2.0]])
    res = galpha.ensemble.run(ensemble_models.stopping_pendulum, grid, [0.1, 5.0],
                              engine="threads", workers=2)
    assert list(res.status) == [1, 1, 1] and not res.failures
    assert all("stopped at t" in m for m in res.message)
    assert np.all(np.isfinite(res.q[:, 0])) and np.all(np.isnan(res.q[:, 1]))
    # it ended just past the vertical: a quarter period, sqrt(L/g) K(sin 1/2) (K by the AGM)
    a, b = 1.0, math.cos(0.5)
    for _ in range(8):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    quarter = np.sqrt(grid[:, 0] / 9.81) * math.pi / (2 * a)
    t_stop = res.summary["t_stop"]
    assert np.all(t_stop >= quarter) and np.all(t_stop < quarter + 0.05 * quarter)


def test_first_order_states():
    grid = np.array([[1.0], [4.0]])
    times = [0.5, 1.0]
    res = galpha.ensemble.run(ensemble_models.driven_decay, grid, times)
    same(res, galpha.ensemble.run(ensemble_models.driven_decay, grid, times,
                                  engine="processes", workers=2, chunk_size=1))
    np.testing.assert_array_equal(res.y, galpha.ensemble.run(
        ensemble_models.driven_decay, grid, times, engine="threads", workers=2).y)
    assert res.y.shape == (2, 2, 1)
    np.testing.assert_allclose(res.y[:, :, 0], np.exp(-2 * np.array([times, times])),
                               rtol=1e-5)
    # x = (cos(w t) - e^{-2 t}) / (w^2 + 4) + 2 sin(w t) / (w (w^2 + 4)), w^2 = k
    for i, k in enumerate(grid[:, 0]):
        w = math.sqrt(k)
        for j, t in enumerate(times):
            x = ((math.exp(-2 * t) - math.cos(w * t)) * 1 / (k + 4) +
                 2 * math.sin(w * t) / (w * (k + 4)))
            assert abs(res.q[i, j, 0] - x) < 1e-5


def test_mpi_rank_failure_is_reported(tmp_path):
    # a model that cannot be built: every rank says so, none hangs
    pytest.importorskip("mpi4py")
    mpirun = shutil.which("mpirun")
    if mpirun is None:
        pytest.skip("mpirun not found (Debian: openmpi-bin)")
    np.save(tmp_path / "grid.npy", GRID[:3])
    env = dict(os.environ, PYTHONPATH=SUBPROCESS_PATH, GALPHA_LIBRARY=SUBPROCESS_LIBRARY,
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_rmaps_base_oversubscribe="1")
    out = subprocess.run([mpirun, "-n", "2", sys.executable, "-m", "galpha.ensemble",
                          "ensemble_models:not_a_case", str(tmp_path / "grid.npy"), "--times",
                          "1.0", "--engine", "mpi", "--out", str(tmp_path / "r.npz")],
                         env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode != 0
    assert "must return a galpha.ensemble.Case" in out.stderr


@pytest.mark.parametrize("engine", ["serial", "threads", "processes"])
def test_a_model_that_returns_no_case_is_a_type_error(engine):
    """Every chunk says so (threads and processes cached the wrong object before checking it
    and said AttributeError from the second chunk on)."""
    with pytest.raises(TypeError, match="must return a galpha.ensemble.Case, not int"):
        galpha.ensemble.run(ensemble_models.not_a_case, GRID, TIMES, engine=engine, workers=2,
                            chunk_size=1)


@pytest.mark.parametrize("engine", ["threads", "processes"])
def test_ctrl_c_stops_the_sweep_at_once(engine):
    """Ctrl-C in the middle of a sweep: the pending runs are cancelled, the running ones end
    (threads between runs, worker processes terminated), Interrupted carries what finished;
    no process is left. (It was raised when the whole sweep had finished.)"""
    import multiprocessing
    import signal
    import threading
    import time
    grid = np.repeat(GRID, 100, axis=0)  # 1 200 runs, about 20 s on two workers
    timer = threading.Timer(1.5, signal.pthread_kill,
                            (threading.main_thread().ident, signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(galpha.ensemble.Interrupted) as e:
            galpha.ensemble.run(ensemble_models.pendulum, grid, TIMES, engine=engine,
                                workers=2, chunk_size=4)
    finally:
        timer.cancel()
    elapsed = time.monotonic() - start
    res = e.value.result
    done = np.count_nonzero(res.status != 2)
    print("  %s: interrupted after %.1f s, %d of %d runs finished" % (engine, elapsed, done,
                                                                      len(grid)))
    assert isinstance(e.value, KeyboardInterrupt)
    assert elapsed < 6.0
    assert 0 < done < len(grid)
    assert np.all(res.status[res.status != 2] == 0)
    assert np.all(np.isnan(res.q[res.status == 2]))
    assert all(m == "not run: the sweep was interrupted" for m, st in zip(res.message,
                                                                       res.status) if st == 2)
    assert multiprocessing.active_children() == []


def test_a_sweep_in_a_worker_importing_the_script_is_refused():
    """A script without the __main__ guard is imported as __mp_main__ by spawned workers (Dask's
    LocalCluster): the sweep it would start again there is refused, by name."""
    code = ("import galpha.ensemble, ensemble_models\n"
            "galpha.ensemble.run(ensemble_models.pendulum, GRID, TIMES)\n")
    scope = {"__name__": "__mp_main__", "GRID": GRID, "TIMES": TIMES}
    with pytest.raises(RuntimeError, match=r'if __name__ == "__main__":'):
        exec(code, scope)
