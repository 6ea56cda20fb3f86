"""The Pythonic layer: Solver, integrate, exceptions, checkpoints."""
import math
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

G = 9.81


def mass(t, q, M):
    M[:] = np.eye(2)


def force(t, q, v, f):
    f[:] = (0.0, -G)


def constraint(t, q, phi):
    phi[0] = 0.5 * (q @ q - 1.0)


def jacobian(t, q, J):
    J[0, :] = q


def pendulum(**kw):
    return galpha.Solver(2, 1, mass, force, constraint, jacobian, **kw)


Q0 = np.array([math.sin(1.0), -math.cos(1.0)])
V0 = np.zeros(2)


def test_library_found_and_versioned():
    assert galpha.__version__.count(".") == 2
    assert os.path.exists(galpha.library_path)
    if "GALPHA_PYTHON_INSTALLED" in os.environ:
        # the installed package finds the library installed with it, by itself
        assert "GALPHA_LIBRARY" not in os.environ
        prefix = os.environ["PYTHONPATH"].split("/lib/")[0]
        assert galpha.__file__.startswith(prefix) and galpha.library_path.startswith(prefix)


def test_solver_steps_and_properties():
    with pendulum(rho_inf=0.7, newton=(1e-12, 20)) as s:
        assert s.params == pytest.approx((4 / 17, 7 / 17, 100 / 289, 23 / 34), rel=1e-14)
        s.init(0.0, Q0, V0)
        # consistent start: lambda0 = m (|v|^2 - g y)/L^2 at rest
        assert s.lam[0] == pytest.approx(-G * Q0[1], rel=1e-12)
        for _ in range(100):
            s.step(1e-3)
        assert s.t == pytest.approx(0.1)
        assert abs(s.q @ s.q - 1.0) < 1e-14
        st = s.stats
        assert st["steps"] == 100 and st["newton_iters"] >= 100
        assert s.h_last == 1e-3
        assert s.info(galpha.GA_INFO_RCOND) > 0


def test_callback_exception_is_reraised_and_solver_stays_usable():
    def bad_force(t, q, v, f):
        if t > 0.0045:
            raise ZeroDivisionError("boom in the model")
        f[:] = (0.0, -G)

    with galpha.Solver(2, 1, mass, bad_force, constraint, jacobian) as s:
        s.init(0.0, Q0, V0)
        s.step(1e-3)
        before = s.get_state()
        with pytest.raises(ZeroDivisionError, match="boom in the model") as info:
            for _ in range(10):
                s.step(1e-3)
        # the traceback reaches into the callback
        assert any(tb.name == "bad_force" for tb in info.traceback)
        after_failure = s.get_state()
        assert after_failure[4] == pytest.approx(0.004)  # steps up to the failure were kept
        assert after_failure[4] > before[4]
        with pytest.raises(ZeroDivisionError):  # the same step fails again, cleanly
            s.step(1e-3)
        s.step(4e-4)  # usable after: a step that stays below the fault succeeds
        assert s.stats["failed_steps"] == 2


@pytest.mark.parametrize("rc,expected", [(2**32, galpha.CallbackRetry),
                                         (np.int64(-3), galpha.CallbackError),
                                         (-0.5, galpha.CallbackError), (0.5, galpha.CallbackRetry),
                                         (float("nan"), TypeError), ("ok", TypeError)])
def test_callback_return_value_counts_by_its_sign(rc, expected):
    """0/None succeed, > 0 is recoverable, < 0 fatal, whatever the type: 2**32 must not wrap to
    0 in the C int, -0.5 must not truncate to 0; a value without a sign is an error."""
    def force_returning(t, q, v, f):
        f[:] = (0.0, -G)
        return rc if t > 0 else None

    with galpha.Solver(2, 1, mass, force_returning, constraint, jacobian) as s:
        s.init(0.0, Q0, V0)
        state = s.get_state()
        with pytest.raises(expected):
            s.step(1e-3)
        assert np.array_equal(s.get_state(), state)


def test_close_from_a_callback_is_refused_and_the_solver_stays_open():
    box = {}

    def closing_force(t, q, v, f):
        f[:] = (0.0, -G)
        if t > 0 and not box.get("tried"):
            box["tried"] = True
            box["s"].close()

    s = galpha.Solver(2, 1, mass, closing_force, constraint, jacobian)
    box["s"] = s
    s.init(0.0, Q0, V0)
    state = s.get_state()
    with pytest.raises(galpha.StateError, match="close"):
        s.step(1e-3)
    assert np.array_equal(s.get_state(), state)  # still open, at its last accepted state
    s.step(1e-3)
    assert s.t == pytest.approx(1e-3)
    s.close()
    with pytest.raises(galpha.StateError, match="closed"):
        s.step(1e-3)


def test_status_maps_to_exception_classes():
    def retry_force(t, q, v, f):
        f[:] = (0.0, -G)
        return 1 if t > 0 else 0  # recoverable failure in every step

    with galpha.Solver(2, 1, mass, retry_force, constraint, jacobian) as s:
        s.init(0.0, Q0, V0)
        state = s.get_state()
        with pytest.raises(galpha.CallbackRetry) as e:
            s.step(1e-3)
        assert isinstance(e.value, galpha.RecoverableError)
        assert "force callback returned 1" in str(e.value)
        assert np.array_equal(s.get_state(), state)
    with pendulum() as s:
        with pytest.raises(galpha.StateError):
            s.step(1e-3)
        with pytest.raises(galpha.ArgumentError, match="outside"):
            s.set_rho_inf(2.0)
        with pytest.raises(galpha.ArgumentError, match="zero-stable"):
            s.set_params(0.6, 0.7, 0.5, 0.6)
        s.init(0.0, Q0, V0)
        s.set_newton(1e-10, 1)
        with pytest.raises(galpha.ConvergenceError):
            s.step(1e-2)
    with pendulum(init_mode=(galpha.GA_INIT_REFUSE, 1e-10)) as s:
        with pytest.raises(galpha.InconsistentError):
            s.init(0.0, [0.3, -1.0], V0)
    s = pendulum()
    s.close()
    with pytest.raises(galpha.StateError):
        s.step(1e-3)
    s.close()  # idempotent


def test_unresolved_fast_rotation_raises_and_keeps_the_state():
    """Index 3 at 0.2 rad per step (the pendulum spun at 20 rad/s, h = 0.01): the step map is
    unstable there; the velocity check raises UnresolvedError (a RecoverableError) before the
    energy is far off, with the state kept; with the check off the run is silently wrong."""
    q0 = np.array([math.sin(1.0), -math.cos(1.0)])
    v0 = 20.0 * np.array([math.cos(1.0), math.sin(1.0)])
    energy = lambda q, v: 0.5 * v @ v + G * q[1]  # noqa: E731
    e0 = energy(q0, v0)
    with pendulum() as s:
        s.init(0.0, q0, v0)
        with pytest.raises(galpha.UnresolvedError, match="velocity constraint 0") as e:
            for _ in range(100):
                state = (s.t, s.q.copy(), s.v.copy(), s.qdd.copy())
                s.step(0.01)
        assert isinstance(e.value, galpha.RecoverableError)
        assert s.t == state[0]
        for now, before in zip((s.q, s.v, s.qdd), state[1:]):
            assert np.array_equal(now, before)
        assert abs(energy(s.q, s.v) / e0 - 1) < 0.1
        assert s.info(galpha.GA_INFO_VELOCITY_RESIDUAL) > 0.02
    with pendulum(resolution_check=math.inf) as s:
        s.init(0.0, q0, v0)
        for _ in range(100):
            s.step(0.01)
        assert abs(energy(s.q, s.v) / e0) > 100.0
    with pytest.raises(galpha.ArgumentError, match="resolution check limit"):
        pendulum(resolution_check=0.0)


@pytest.mark.parametrize("zero_copy", [False, True])
def test_inputs_are_read_only(zero_copy):
    def sneaky_mass(t, q, M):
        q[0] = 0.0

    with galpha.Solver(2, 1, sneaky_mass, force, constraint, jacobian,
                       zero_copy=zero_copy) as s:
        with pytest.raises(ValueError, match="read-only"):
            s.init(0.0, Q0, V0)


def test_views_of_the_library_cannot_be_made_writeable():
    def prying_mass(t, q, M):
        q.flags.writeable = True

    with galpha.Solver(2, 1, prying_mass, force, constraint, jacobian, zero_copy=True) as s:
        with pytest.raises(ValueError, match="WRITEABLE"):
            s.init(0.0, Q0, V0)


def test_writing_into_a_copied_input_changes_nothing():
    def prying_mass(t, q, M):
        q.flags.writeable = True  # its own copy: allowed, and harmless
        q[:] = 1e300
        mass(t, q, M)

    with galpha.Solver(2, 1, prying_mass, force, constraint, jacobian) as a, pendulum() as b:
        for s in (a, b):
            s.init(0.0, Q0, V0)
            for _ in range(20):
                s.step(2e-3)
        assert np.array_equal(a.get_state(), b.get_state())


def test_zero_copy_runs_the_same_numbers():
    with pendulum(zero_copy=True) as a, pendulum() as b:
        for s in (a, b):
            s.init(0.0, Q0, V0)
            for _ in range(50):
                s.step_adaptive(1.0)
        assert np.array_equal(a.get_state(), b.get_state())


def test_arrays_a_callback_keeps_stay_its_own():
    """What a callback keeps of its arguments neither changes with later calls nor reaches
    the library: a kept input keeps its values, a kept output written later (also after
    close()) changes nothing in the run, which stays that of a solver whose callbacks keep
    nothing."""
    kept = []

    def keeping_mass(t, q, M):
        kept.append((q, q.copy(), M))
        M[:] = np.eye(2)

    def keeping_jacobian(t, q, J):
        jacobian(t, q, J)
        kept.append((q, q.copy(), J))

    with galpha.Solver(2, 1, keeping_mass, force, constraint, keeping_jacobian) as a, \
            pendulum() as b:
        for s in (a, b):
            s.init(0.0, Q0, V0)
        for k in range(40):
            for s in (a, b):
                s.step(2e-3)
            for q, q_then, out in kept:
                out[...] = 1e300 * k  # written after the call returned
        assert len(kept) > 40
        for q, q_then, _ in kept:
            assert np.array_equal(q, q_then)
        assert np.array_equal(a.get_state(), b.get_state())
    for q, q_then, out in kept:
        out[...] = -1.0  # after close()
        assert np.array_equal(q, q_then)


def test_checkpoint_restart_is_bit_identical():
    with pendulum() as a, pendulum() as b:
        a.init(0.0, Q0, V0)
        for _ in range(50):
            a.step(2e-3)
        ckpt = a.get_state()
        for _ in range(50):
            a.step(2e-3)
        b.set_state(ckpt)
        for _ in range(50):
            b.step(2e-3)
        assert np.array_equal(a.get_state(), b.get_state())


class Boom(Exception):
    """Raised by a model callback at a chosen call."""


class FaultyPendulum:
    """The pendulum's callbacks, counting their calls; call number fail_at raises Boom."""

    def __init__(self):
        self.calls, self.fail_at = 0, 0

    def _count(self, name):
        self.calls += 1
        if self.calls == self.fail_at:
            raise Boom(f"{name} at call {self.calls}")

    def mass(self, t, q, M):
        mass(t, q, M)
        self._count("mass")

    def force(self, t, q, v, f):
        force(t, q, v, f)
        self._count("force")

    def constraint(self, t, q, phi):
        constraint(t, q, phi)
        self._count("constraint")

    def jacobian(self, t, q, J):
        jacobian(t, q, J)
        self._count("jacobian")

    def solver(self, **kw):
        return galpha.Solver(2, 1, self.mass, self.force, self.constraint, self.jacobian, **kw)


@pytest.mark.parametrize("adaptive", [False, True])
def test_exception_at_every_callback_call_of_a_step(adaptive):
    """An exception raised at any callback call of a step (full Newton, so that every
    iteration evaluates the matrices) is re-raised from that step, which leaves t, q, v, qdd,
    lambda and a bit-identical; the run then continues exactly like one restarted from a
    checkpoint of that state."""
    kw = dict(tolerances=(1e-6, 1e-6), reuse=galpha.GA_REUSE_NEVER)

    def advance(s):
        if adaptive:
            s.step_adaptive(10.0)
        else:
            s.step(2e-3)

    def readout(s):
        return np.concatenate(([s.t, s.h_last], s.q, s.v, s.qdd, s.lam, s.a))

    failed_in = set()
    for k in range(1, 100):
        model = FaultyPendulum()
        with model.solver(**kw) as s:
            s.init(0.0, Q0, V0)
            for _ in range(3):
                advance(s)
            before = readout(s)
            model.calls, model.fail_at = 0, k
            try:
                advance(s)
            except Boom as e:
                failed_in.add(str(e).split()[0])
            else:
                assert model.calls < k  # the step made fewer calls: every one was failed
                break
            assert np.array_equal(readout(s), before)
            assert s.stats["failed_steps"] == 1
            model.fail_at = 0
            with FaultyPendulum().solver(**kw) as ref:
                ckpt_source = FaultyPendulum().solver(**kw)
                ckpt_source.init(0.0, Q0, V0)
                for _ in range(3):
                    advance(ckpt_source)
                ref.set_state(ckpt_source.get_state())
                ckpt_source.close()
                advance(s)
                advance(ref)
                assert np.array_equal(readout(s), readout(ref))
    assert k > 4 and failed_in == {"mass", "force", "constraint", "jacobian"}


def test_integrate_returns_histories():
    sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.003, m=1,
                           rho_inf=0.8)
    assert sol.success and sol.status == 0
    assert sol.t[0] == 0.0 and sol.t[-1] == pytest.approx(0.5, abs=1e-14)
    assert sol.q.shape == (len(sol.t), 2) and sol.lam.shape == (len(sol.t), 1)
    assert np.allclose(np.einsum("ij,ij->i", sol.q, sol.q), 1.0, atol=1e-13)
    assert sol.stats["steps"] == len(sol.t) - 1


def test_integrate_checks_its_times():
    with pytest.raises(ValueError, match="must lie in t_span"):
        galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01, m=1,
                         t_eval=[-0.1, 0.2])
    with pytest.raises(ValueError, match="the end must come after the start"):
        galpha.integrate(mass, force, constraint, jacobian, (0.5, 0.0), Q0, V0, 0.01, m=1)
    sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01, m=1,
                           t_eval=[0.0, 0.25, 0.5])
    assert list(sol.t) == [0.0, 0.25, 0.5]
    assert np.array_equal(sol.q[0], Q0)  # the start itself, not a later state


def test_integrate_reports_method_failure():
    sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.1), Q0, V0, 0.01, m=1,
                           newton=(1e-10, 1))
    assert not sol.success and sol.status == galpha._ffi.GA_ERR_NEWTON
    assert "did not converge" in sol.message and len(sol.t) == 1


def test_unconstrained_oscillator():
    def m1(t, q, M):
        M[0, 0] = 1.0

    def f1(t, q, v, f):
        f[0] = -q[0]

    sol = galpha.integrate(m1, f1, None, None, (0.0, 1.0), [1.0], [0.0], 1e-3)
    assert sol.q[-1, 0] == pytest.approx(math.cos(1.0), abs=1e-6)
    assert sol.lam.shape == (len(sol.t), 0)


def test_every_c_function_is_declared():
    """The low-level layer mirrors the C API one to one."""
    import re
    header = os.path.join(os.path.dirname(__file__), "..", "..", "include", "galpha.h")
    declared = set(re.findall(r"^GA_API[^(]*?\b(ga_\w+)\(", open(header).read(), re.M))
    missing = declared - set(galpha._ffi._SIGNATURES)
    assert not missing, missing
    assert len(declared) > 40


def test_adaptive_integration_and_dense_output():
    t_eval = np.linspace(0.0, 1.0, 11)
    sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 1.0), Q0, V0, m=1,
                           t_eval=t_eval, tolerances=(1e-7, 1e-7),
                           formulation=galpha.GA_INDEX2_STABILIZED)
    assert sol.success
    assert np.array_equal(sol.t, t_eval)
    # dense output keeps the constraint to the interpolation error
    assert np.max(np.abs(np.einsum("ij,ij->i", sol.q, sol.q) - 1.0)) < 1e-5
    assert sol.stats["steps"] > 10
    with pendulum(formulation=galpha.GA_INDEX2_STABILIZED, tolerances=(1e-6, 1e-6)) as s:
        s.init(0.0, Q0, V0)
        s.advance(0.5)
        assert s.t == 0.5
        q, v, lam = s.interpolate(0.5)
        assert np.allclose(q, s.q, atol=1e-15)
        assert "dense" in s.linear_solver_name


def test_fortran_module_declares_every_c_function():
    import re
    root = os.path.join(os.path.dirname(__file__), "..", "..")
    header = open(os.path.join(root, "include", "galpha.h")).read()
    declared = set(re.findall(r"^GA_API[^(]*?\b(ga_\w+)\(", header, re.M))
    fortran = open(os.path.join(root, "bindings", "fortran", "galpha.f90")).read()
    bound = set(re.findall(r'bind\(C, name="(ga_\w+)"\)', fortran))
    assert declared - bound == set()
    # ... and the Fortran layer wraps each of them: a type-bound procedure or a module
    # function that calls it (ga_free through free, ga_get_t through t, ...)
    layer = fortran[fortran.index("! ---- the Fortran layer"):]
    called = set(re.findall(r"\b(ga_\w+)\(", layer))
    called |= set(re.findall(r"copy_out\(this, (ga_\w+),", layer))
    assert declared - called == set()


def test_redundant_constraint_dropped():
    """The pendulum constraint twice: refused by default, dropped on request; the motion and
    the constraint force are those of the pendulum with the constraint once."""
    def twice(t, q, phi):
        phi[:] = 0.5 * (q @ q - 1.0)

    def twice_jacobian(t, q, J):
        J[0, :] = q
        J[1, :] = q

    with galpha.Solver(2, 2, mass, force, twice, twice_jacobian) as s:
        with pytest.raises(galpha.SingularMatrixError, match="depend on the ones before them: 1"):
            s.init(0.0, Q0, V0)
    with galpha.Solver(2, 2, mass, force, twice, twice_jacobian,
                       redundant=galpha.GA_REDUNDANT_DROP) as s, pendulum() as one:
        s.init(0.0, Q0, V0)
        one.init(0.0, Q0, V0)
        for _ in range(200):
            s.step(1e-3)
            one.step(1e-3)
        assert list(s.active_constraints) == [True, False]
        assert np.max(np.abs(s.q - one.q)) < 1e-12
        assert s.lam[0] == pytest.approx(one.lam[0], rel=1e-9)
        assert s.lam[1] == 0.0


def test_constraint_dt_callback_spares_the_differences():
    """Phi_t = 0 for the pendulum: with the callback the index-2 steps give the same motion
    without the four constraint calls per Newton iteration that differences in t cost."""
    def zero_dt(t, q, out):
        out[:] = 0.0

    runs = []
    for dt in (None, zero_dt):
        with pendulum(formulation=galpha.GA_INDEX2_STABILIZED, constraint_dt=dt,
                      newton=(1e-12, 20)) as s:
            s.init(0.0, Q0, V0)
            for _ in range(100):
                s.step(1e-3)
            runs.append((s.q.copy(), s.stats))
    (q_fd, fd), (q_cb, cb) = runs
    assert np.max(np.abs(q_fd - q_cb)) < 1e-12
    assert cb["constraint_dt_evals"] >= cb["residuals"]
    assert fd["constraint_evals"] - 4 * fd["constraint_dt_evals"] - fd["residuals"] == \
        cb["constraint_evals"] - cb["residuals"]


def sparse_mass(t, q, M):
    assert M.shape == (2,)  # the values of the declared diagonal, not a 2 x 2 matrix
    M[:] = 1.0


def sparse_jacobian(t, q, J):
    assert J.shape == (2,)  # entries (0, 0), (0, 1)
    J[:] = q


def test_declared_patterns_take_the_sparse_path():
    patterns = {"mass": ([0, 1], [0, 1]), "jacobian": ([0, 0], [0, 1]),
                "stiffness": ([0, 1], [0, 1]), "damping": ([], [])}
    runs = {}
    for name, kw in (("dense", {}),
                     ("sparse", dict(patterns=patterns, linear_solver=galpha.GA_LINEAR_SPARSE))):
        sparse = name == "sparse"
        with galpha.Solver(2, 1, sparse_mass if sparse else mass, force, constraint,
                           sparse_jacobian if sparse else jacobian, **kw) as s:
            s.init(0.0, Q0, V0)
            for _ in range(200):
                s.step(5e-3)
            runs[name] = (s.q, s.lam, s.linear_solver_name, s.stats)
    assert runs["sparse"][2] == "sparse KLU"
    assert runs["dense"][2] != "sparse KLU"
    # the same discrete solution through either linear algebra
    assert np.max(np.abs(runs["sparse"][0] - runs["dense"][0])) < 1e-10
    assert abs(runs["sparse"][1][0] - runs["dense"][1][0]) < 1e-8 * abs(runs["dense"][1][0])
    # the empty damping pattern declares C_t = 0: never computed
    assert runs["sparse"][3]["damping_evals"] == 0


def test_csc_patterns_run_as_their_triplets():
    # a compressed-column pattern (what scipy.sparse.csc_matrix holds: indptr, indices)
    # declares the entries column by column: the same run as those triplets
    from types import SimpleNamespace
    csc = {"mass": SimpleNamespace(format="csc", indptr=[0, 1, 2], indices=[0, 1]),
           "jacobian": SimpleNamespace(format="csc", indptr=[0, 1, 2], indices=[0, 0]),
           "stiffness": SimpleNamespace(format="csc", indptr=[0, 1, 2], indices=[0, 1]),
           "damping": SimpleNamespace(format="csc", indptr=[0, 0, 0], indices=[])}
    triplets = {"mass": ([0, 1], [0, 1]), "jacobian": ([0, 0], [0, 1]),
                "stiffness": ([0, 1], [0, 1]), "damping": ([], [])}
    runs = []
    for patterns in (csc, triplets):
        with galpha.Solver(2, 1, sparse_mass, force, constraint, sparse_jacobian,
                           patterns=patterns, linear_solver=galpha.GA_LINEAR_SPARSE) as s:
            s.init(0.0, Q0, V0)
            for _ in range(100):
                s.step(5e-3)
            runs.append((s.q.copy(), s.lam.copy(), s.stats["damping_evals"]))
    assert np.array_equal(runs[0][0], runs[1][0]) and np.array_equal(runs[0][1], runs[1][1])
    assert runs[0][2] == 0  # the empty column pointers declare C_t = 0
    with pytest.raises(galpha.ArgumentError, match="colptr decreases"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian,
                      patterns={"mass": SimpleNamespace(indptr=[0, 2, 1], indices=[0, 1])})
    with pytest.raises(ValueError, match="2 column pointers, not n \\+ 1 = 3"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian,
                      patterns={"mass": SimpleNamespace(indptr=[0, 1], indices=[0])})
    with pytest.raises(ValueError, match="format 'csr', not csc"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian,
                      patterns={"mass": SimpleNamespace(format="csr", indptr=[0, 1, 2],
                                                        indices=[0, 1])})


def test_bad_patterns_are_refused():
    with pytest.raises(galpha.ArgumentError, match="outside the 2 x 2 matrix"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian, patterns={"mass": ([0, 2], [0, 1])})
    with pytest.raises(ValueError, match="unknown matrix"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian, patterns={"masses": ([0], [0])})
    with pytest.raises(ValueError, match="2 rows but 1 cols"):
        galpha.Solver(2, 1, mass, force, constraint, jacobian, patterns={"mass": ([0, 1], [0])})


def test_initial_step_and_counter_reset():
    with pendulum(tolerances=(1e-6, 1e-6), initial_step=1e-4) as s:
        s.init(0.0, Q0, V0)
        s.step_adaptive(1.0)
        assert s.h_last == 1e-4  # the first adaptive step is the one asked for
        assert s.stats["steps"] == 1
        s.reset_counters()
        assert all(value == 0 for value in s.stats.values())
        s.step(1e-3)
        assert s.stats["steps"] == 1
    with pytest.raises(galpha.ArgumentError, match="initial step"):
        pendulum(initial_step=-1.0)


def stiffness(t, q, v, qdd, lam, K):
    K[:] = lam[0] * np.eye(2)  # d(Phi_q^T lambda)/dq; M constant, f constant


def damping(t, q, v, C):
    C[:] = 0.0  # f does not depend on v


def constraint_accel(t, q, v, out):
    out[0] = v @ v  # d^2/dt^2 Phi - Phi_q q'' = |v|^2


def test_every_option_keyword_reaches_its_setter():
    """Options that do not change the discrete solution, all set at once, give the default
    run's steps (to the Newton tolerance); each keyword that is refused names its setter's
    complaint."""
    def run(**kw):
        with pendulum(newton=(1e-12, 30), **kw) as s:
            s.init(0.0, Q0, V0)
            for _ in range(100):
                s.step(1e-2)
            return s.q, s.lam, s.stats
    q0, l0, _ = run()
    q1, l1, stats = run(stiffness=stiffness, damping=damping, constraint_accel=constraint_accel,
                        tangent_mode=galpha.GA_TANGENT_AUTO, scaling=True,
                        predictor=galpha.GA_PREDICTOR_CONSTANT_A, reuse=galpha.GA_REUSE_NEVER,
                        constant_mass=True, linear_solver=galpha.GA_LINEAR_DENSE_LAPACK,
                        init_mode=(galpha.GA_INIT_PROJECT, 1e-12),
                        redundant=galpha.GA_REDUNDANT_DROP, rescale=True,
                        corrected_start=True, step_limits=(0.0, 0.0))
    assert np.max(np.abs(q1 - q0)) < 1e-10
    assert abs(l1[0] - l0[0]) < 1e-8 * abs(l0[0])
    assert stats["stiffness_evals"] > 0 and stats["damping_evals"] > 0  # the callbacks ran
    assert stats["mass_evals"] == 1  # constant mass: evaluated once
    assert stats["factorizations"] >= stats["newton_iters"]  # full Newton
    refused = {"tangent_mode": (7, "unknown tangent mode 7"),
               "predictor": (7, "unknown predictor 7"),
               "reuse": (7, "unknown reuse mode 7"),
               "linear_solver": (99, "unknown linear solver 99"),
               "formulation": (5, "unknown formulation 5"),
               "redundant": (9, "unknown redundancy mode 9"),
               "init_mode": ((galpha.GA_INIT_PROJECT, 0.0), "init_tol = 0 must be positive"),
               "tolerances": ((0.0, 1e-6), "must be positive and finite"),
               "step_limits": ((-1.0, 0.0), "step limits h_min = -1")}
    for key, (value, message) in refused.items():
        with pytest.raises(galpha.ArgumentError, match=message):
            pendulum(**{key: value})


def test_init_checks_the_shapes():
    with pendulum() as s:
        with pytest.raises(galpha.ArgumentError, match=r"shape \(2,\)"):
            s.init(0.0, [0.0, -1.0, 0.0], V0)


def test_missing_library_is_reported_with_where_it_looked():
    import subprocess
    env = dict(os.environ, GALPHA_LIBRARY="/nonexistent/libgalpha.so.0")
    code = ("import sys; sys.path.insert(0, %r)\n"
            "try:\n    import galpha\nexcept OSError as e:\n    print(e)\n"
            % os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True).stdout
    assert "libgalpha not found" in out
    assert "environment variable GALPHA_LIBRARY: /nonexistent/libgalpha.so.0" in out
    assert "Set GALPHA_LIBRARY" in out


def test_output_consistent_by_default_and_the_step_s_on_request():
    """lam and qdd are consistent with q and v by default; output=GA_OUTPUT_STEP gives the
    step's own (at h = 1e-3 both within the run's error of each other); interpolate_qdd."""
    values = []
    for output in (None, galpha.GA_OUTPUT_STEP):
        with pendulum(output=output) as s:
            s.init(0.0, Q0, V0)
            for _ in range(100):
                s.step(1e-3)
            values.append((s.lam.copy(), s.qdd.copy(), s.interpolate_qdd(s.t - 5e-4)))
    (l_c, a_c, i_c), (l_s, a_s, i_s) = values
    assert abs(l_c[0] - l_s[0]) < 1e-4 * abs(l_s[0]) and l_c[0] != l_s[0]
    assert np.max(np.abs(a_c - a_s)) < 1e-3
    assert i_c.shape == (2,) and np.max(np.abs(i_c - i_s)) < 1e-2
    with pytest.raises(galpha.ArgumentError):
        pendulum(output=5)


def test_a_solver_is_neither_copied_nor_pickled():
    """copy.copy(solver) made two objects own one C solver, freed twice (issue 17)."""
    import copy
    import pickle
    with pendulum() as s:
        for make in (copy.copy, copy.deepcopy, pickle.dumps):
            with pytest.raises(TypeError):
                make(s)
        s.init(0.0, Q0, V0)
        s.step(1e-3)  # the original is intact


def test_integrate_refuses_constraints_without_m_and_a_bad_h():
    """integrate() without m dropped the constraint callbacks and reported success; h = nan
    integrated the span in one step (issue 17)."""
    with pytest.raises(ValueError, match="without m"):
        galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01)
    with pytest.raises(ValueError, match="m = 0"):
        galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01, m=0)
    for h in (float("nan"), 0.0, -1e-3, float("inf")):
        with pytest.raises(ValueError, match="positive and finite"):
            galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, h, m=1)


def test_integrate_result_attributes_repr_and_qdd_at_t_eval():
    """A missing attribute is an AttributeError (hasattr, deepcopy), the repr counts steps as
    steps, and qdd at t_eval comes from dense output, not NaN (issue 17)."""
    import copy
    sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01, m=1,
                           t_eval=[0.105, 0.25, 0.5])
    assert not hasattr(sol, "no_such_field")
    copy.deepcopy(sol)
    assert "outputs=3" in repr(sol) and "steps=50" in repr(sol)
    assert np.all(np.isfinite(sol.qdd))
    # the pendulum's acceleration at t_eval against the step's at the same time nearby
    assert sol.qdd.shape == (3, 2)
    # t_eval=[]: no output times, and a repr that says so (it read t[-1])
    empty = galpha.integrate(mass, force, constraint, jacobian, (0.0, 0.5), Q0, V0, 0.01, m=1,
                             t_eval=[])
    assert empty.success and len(empty.t) == 0 and "outputs=0" in repr(empty)


def test_calls_from_two_threads_are_serialized():
    """close() from another thread while a run is inside C waits for it, instead of freeing the
    C solver under it (3 of 3 such processes crashed; issue 17). The run ends, then the
    solver is closed."""
    import threading
    started = threading.Event()

    def force_signalling(t, q, v, f):
        started.set()
        force(t, q, v, f)

    s = galpha.Solver(2, 1, mass, force_signalling, constraint, jacobian, tolerances=(1e-6, 1e-6))
    s.init(0.0, Q0, V0)
    started.clear()
    done = []

    def run():
        s.advance(1.0)  # ends undisturbed (then the solver may be closed at once)
        done.append(1.0)

    th = threading.Thread(target=run)
    th.start()
    started.wait()      # the run is inside C now
    s.close()           # waits for it
    th.join()
    assert done == [1.0]
    with pytest.raises(galpha.StateError):
        s.step(1e-3)


def test_ctrl_c_stops_a_run_every_time():
    """SIGINT at random moments of runs inside C: every one stops the run with
    KeyboardInterrupt (29-39 % were lost when it landed in a ctypes callback before its try),
    and the solver stays usable at its last accepted step (issue 17)."""
    import os
    import random
    import signal
    import threading
    import time
    rng = random.Random(7)
    stopped = 0
    for trial in range(30):
        running = threading.Event()

        def force_running(t, q, v, f):
            running.set()
            force(t, q, v, f)

        def interrupt(delay=rng.uniform(0.0, 0.02)):
            running.wait()  # the run is inside C: the interrupt lands in it
            time.sleep(delay)
            os.kill(os.getpid(), signal.SIGINT)

        with galpha.Solver(2, 1, mass, force_running, constraint, jacobian,
                           tolerances=(1e-8, 1e-8)) as s:
            s.init(0.0, Q0, V0)
            running.clear()
            killer = threading.Thread(target=interrupt)
            killer.start()
            try:
                s.advance(200.0)  # seconds of work: far longer than the delay
            except KeyboardInterrupt:
                stopped += 1
            killer.join()
            t = s.t
            s.step(1e-4)          # consistent: it steps on from the last accepted state
            assert s.t == pytest.approx(t + 1e-4)
    assert stopped == 30


def test_check_derivatives_names_a_wrong_tangent():
    """ga_check_derivatives through the binding: the pendulum's exact K_t = lambda I agrees,
    a sign flipped in it is named with both values (DerivativeError)."""
    def stiffness(t, q, v, qdd, lam, K):
        K[:] = lam[0] * np.eye(2)

    def wrong(t, q, v, qdd, lam, K):
        K[:] = lam[0] * np.eye(2)
        K[1, 1] = -K[1, 1]

    q, v = Q0, np.array([0.3, 0.2])
    with pendulum(stiffness=stiffness) as s:
        worst = s.check_derivatives(0.0, q, v, lam=[2.0])
        assert 0.0 <= worst < 1e-8
    with pendulum(stiffness=wrong) as s:
        with pytest.raises(galpha.DerivativeError, match=r"K_t\(1, 1\) = -2 by the callback"):
            s.check_derivatives(0.0, q, v, lam=[2.0])
    with pendulum() as s:
        with pytest.raises(galpha.DerivativeError, match="constraint 0 has a zero gradient"):
            s.check_derivatives(0.0, [0.0, 0.0], [0.0, 0.0])
        with pytest.raises(ValueError):
            s.check_derivatives(0.0, [1.0], [0.0, 0.0])


def test_sizes_refused_by_name():
    """Solver(2, 3) says why, not only "invalid argument"."""
    with pytest.raises(galpha.ArgumentError, match=r"n=2, m=3.*0 <= m <= n"):
        galpha.Solver(2, 3, mass)
    with pytest.raises(galpha.ArgumentError, match="n >= 1"):
        galpha.Solver(0, 0, mass)
