"""Compiled callbacks (numba cfunc, ctypes function pointer, int address) with a `user` pointer,
and the step hook, through galpha.Solver: the same arithmetic as Python callbacks gives the
same numbers bit for bit; what the hook sees is what the solver reads give."""
import ctypes
import math
import os
import subprocess
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

numba = pytest.importorskip("numba")
from numba import carray, cfunc, types  # noqa: E402

dp, vp = types.CPointer(types.float64), types.voidptr


@cfunc(types.int32(types.float64, dp, dp, vp))
def c_mass(t, q, M, user):
    p = carray(user, 3, np.float64)
    out = carray(M, 4)
    out[0], out[1], out[2], out[3] = p[0], 0.0, 0.0, p[0]
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, vp))
def c_force(t, q, v, f, user):
    p = carray(user, 3, np.float64)
    out = carray(f, 2)
    out[0] = 0.0
    out[1] = -p[0] * p[2]
    return 0


@cfunc(types.int32(types.float64, dp, dp, vp))
def c_constraint(t, q, phi, user):
    p = carray(user, 3, np.float64)
    x = carray(q, 2)
    carray(phi, 1)[0] = 0.5 * (x[0] * x[0] + x[1] * x[1] - p[1] * p[1])
    return 0


@cfunc(types.int32(types.float64, dp, dp, vp))
def c_jacobian(t, q, J, user):
    x, out = carray(q, 2), carray(J, 2)
    out[0], out[1] = x[0], x[1]
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, dp, vp))
def c_crossing(t, q, v, lam, g, user):
    carray(g, 1)[0] = carray(q, 2)[0]
    return 0


# the step hook: counts calls into user[0], the largest |lambda| into user[1]; stops at
# call user[2] (if positive)
@cfunc(types.int32(vp, types.float64, dp, dp, dp, vp))
def c_hook(solver, t, q, v, lam, user):
    w = carray(user, 3, np.float64)
    w[0] += 1.0
    w[1] = max(w[1], abs(carray(lam, 1)[0]))
    return 1 if w[2] > 0.0 and w[0] == w[2] else 0


def py_model(p):
    def mass(t, q, M):
        M[:] = ((p[0], 0.0), (0.0, p[0]))

    def force(t, q, v, f):
        f[0] = 0.0
        f[1] = -p[0] * p[2]

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q[0] * q[0] + q[1] * q[1] - p[1] * p[1])

    def jacobian(t, q, J):
        J[0, 0], J[0, 1] = q[0], q[1]
    return mass, force, constraint, jacobian


Q0, V0 = [math.sin(1.0), -math.cos(1.0)], [0.3, 0.0]


def run(callbacks, user=None, steps=300, **options):
    with galpha.Solver(2, 1, *callbacks, user=user, **options) as s:
        s.init(0.0, Q0, V0)
        for _ in range(steps):
            s.step(1e-3)
        return s.q.copy(), s.v.copy(), s.lam.copy()


def same(a, b):
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("formulation", [galpha.GA_INDEX3, galpha.GA_INDEX2_STABILIZED])
def test_numba_cfuncs_give_the_python_numbers(formulation):
    p = np.array([1.3, 0.8, 9.81])
    python = run(py_model(p), formulation=formulation)
    compiled = run((c_mass, c_force, c_constraint, c_jacobian), user=p, formulation=formulation)
    same(python, compiled)


def test_ctypes_pointers_and_addresses():
    p = np.array([1.3, 0.8, 9.81])
    reference = run((c_mass, c_force, c_constraint, c_jacobian), user=p)
    as_ctypes = run(tuple(f.ctypes for f in (c_mass, c_force, c_constraint, c_jacobian)),
                    user=p.ctypes.data)
    as_addresses = run(tuple(f.address for f in (c_mass, c_force, c_constraint, c_jacobian)),
                       user=p)
    mixed = run((c_mass, py_model(p)[1], c_constraint.address, c_jacobian.ctypes), user=p)
    for other in (as_ctypes, as_addresses, mixed):
        same(reference, other)


def test_user_from_ctypes_object():
    p = np.array([1.3, 0.8, 9.81])
    arr = (ctypes.c_double * 3)(*p)
    same(run((c_mass, c_force, c_constraint, c_jacobian), user=p),
         run((c_mass, c_force, c_constraint, c_jacobian), user=arr))


def test_the_parameters_are_read_at_each_call():
    # user is the caller's array itself: a change between runs is seen
    p = np.array([1.3, 0.8, 9.81])
    with galpha.Solver(2, 1, c_mass, c_force, c_constraint, c_jacobian, user=p) as s:
        s.init(0.0, Q0, V0)
        s.step(1e-3)
        first = s.lam.copy()
        p[2] = 2 * 9.81
        s.init(0.0, Q0, V0)
        s.step(1e-3)
        assert not np.array_equal(first, s.lam)
    p2 = np.array([1.3, 0.8, 2 * 9.81])
    with galpha.Solver(2, 1, *py_model(p2)) as s:
        s.init(0.0, Q0, V0)
        s.step(1e-3)
        lam_python = s.lam.copy()
    np.testing.assert_array_equal(lam_python, run((c_mass, c_force, c_constraint, c_jacobian),
                                                  user=p, steps=1)[2])


def test_bad_callbacks_and_user():
    with pytest.raises(TypeError):
        galpha.Solver(2, 1, "mass", None, c_constraint, c_jacobian)
    with pytest.raises(ValueError):
        galpha.Solver(2, 1, 0, None, c_constraint, c_jacobian)
    with pytest.raises(TypeError):
        galpha.Solver(2, 1, c_mass, c_force, c_constraint, c_jacobian, user="params")
    with pytest.raises(ValueError):
        galpha.Solver(2, 1, c_mass, c_force, c_constraint, c_jacobian,
                      user=np.zeros((3, 3))[:, 0])


def test_compiled_events_and_hook():
    p = np.array([1.0, 1.0, 9.81])
    w = np.array([0.0, 0.0, 0.0])
    with galpha.Solver(2, 1, c_mass, c_force, c_constraint, c_jacobian, user=p,
                       tolerances=(1e-7, 1e-7)) as s:
        s.set_events(c_crossing, direction=[-1], terminal=[True])
        s.set_step_hook(c_hook, multipliers=True, user=w)
        s.init(0.0, [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0])
        assert s.advance(5.0)
        t_event = s.events[0][0]
        steps = s.stats["steps"]
    # the same events by Python: the same time, bit for bit
    def crossing(t, q, v, lam):
        return q[0]
    crossing.direction, crossing.terminal = -1, True
    with galpha.Solver(2, 1, *py_model(p), tolerances=(1e-7, 1e-7)) as s:
        s.set_events([crossing])
        s.init(0.0, [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0])
        assert s.advance(5.0)
        assert s.events[0][0] == t_event
    assert w[0] == steps
    # released from 1 rad, at most m g (3 - 2 cos 1) / L at the bottom
    assert 0 < w[1] <= 9.81 * (3 - 2 * math.cos(1.0)) * (1 + 1e-6)
    # a quarter period of a 1-rad pendulum: sqrt(L/g) K(sin(1/2)), K by the AGM
    a, b = 1.0, math.cos(0.5)
    for _ in range(8):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    quarter = math.sqrt(1.0 / 9.81) * math.pi / (2 * a)
    assert abs(t_event - quarter) < 1e-5


def test_compiled_hook_stops():
    p = np.array([1.0, 1.0, 9.81])
    w = np.array([0.0, 0.0, 5.0])
    with galpha.Solver(2, 1, c_mass, c_force, c_constraint, c_jacobian, user=p) as s:
        s.set_step_hook(c_hook, multipliers=True, user=w)
        s.init(0.0, Q0, V0)
        assert s.advance(1.0)
        assert w[0] == 5 and s.stats["steps"] == 5 and s.t < 1.0


def test_python_hook():
    p = np.array([1.0, 1.0, 9.81])
    seen = []

    def hook(t, q, v, lam):
        seen.append((t, q, v, lam))
        return len(seen) == 20

    with galpha.Solver(2, 1, *py_model(p), tolerances=(1e-6, 1e-6)) as s:
        s.set_step_hook(hook, multipliers=True)
        s.init(0.0, Q0, V0)
        assert s.advance(1.0)  # stopped by the hook
        assert len(seen) == 20 and s.t == seen[-1][0]
        np.testing.assert_array_equal(s.q, seen[-1][1])
        np.testing.assert_array_equal(s.v, seen[-1][2])
        np.testing.assert_array_equal(s.lam, seen[-1][3])
        assert not s.advance(1.0)
        assert len(seen) == s.stats["steps"] and s.t == 1.0
        # without multipliers lam is None
        s.set_step_hook(lambda t, q, v, lam: seen.append(lam), multipliers=False)
        s.step(1e-3)
        assert seen[-1] is None
        s.set_step_hook(None)
        s.step(1e-3)
        assert seen[-1] is None and len(seen) == s.stats["steps"] - 1


def test_python_hook_exception():
    p = np.array([1.0, 1.0, 9.81])

    def hook(t, q, v, lam):
        if t > 0.05:
            raise RuntimeError("hook failed")

    with galpha.Solver(2, 1, *py_model(p)) as s:
        s.set_step_hook(hook)
        s.init(0.0, Q0, V0)
        with pytest.raises(RuntimeError, match="hook failed"):
            for _ in range(100):
                s.step(1e-2)
        # the step the hook raised after stays accepted: the run is at 0.06
        assert abs(s.t - 0.06) < 1e-12


def test_numba_is_not_imported_by_galpha():
    package = os.path.dirname(os.path.dirname(os.path.abspath(galpha.__file__)))
    code = "import sys; sys.path.insert(0, %r); import galpha; print('numba' in sys.modules)" \
        % package
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "False"


def test_integrate_records_through_the_hook_as_a_step_loop_would():
    # adaptive integrate runs inside one advance() with the step hook recording: the same
    # steps and values as stepping from Python
    p = np.array([1.0, 1.0, 9.81])
    opts = dict(tolerances=(1e-6, 1e-6), formulation=galpha.GA_INDEX2_STABILIZED)
    r = galpha.integrate(*py_model(p), (0.0, 1.5), Q0, V0, m=1, progress=False, **opts)
    ts, qs, lams = [0.0], [np.array(Q0)], []
    with galpha.Solver(2, 1, *py_model(p), **opts) as s:
        s.init(0.0, Q0, V0)
        lams.append(s.lam.copy())
        while s.t < 1.5:
            s.step_adaptive(1.5)
            ts.append(s.t)
            qs.append(s.q.copy())
            lams.append(s.lam.copy())
    np.testing.assert_array_equal(r.t, ts)
    np.testing.assert_array_equal(r.q, qs)
    np.testing.assert_array_equal(r.lam, lams)
    t_eval = np.linspace(0.0, 1.5, 7)
    r2 = galpha.integrate(*py_model(p), (0.0, 1.5), Q0, V0, m=1, t_eval=t_eval, progress=False,
                          **opts)
    np.testing.assert_array_equal(r2.t, t_eval)
    np.testing.assert_array_equal(r2.q[-1], r.q[-1])


def test_integrate_progress_bar(capsys):
    pytest.importorskip("tqdm")
    p = np.array([1.0, 1.0, 9.81])
    for h in (None, 1e-2):
        galpha.integrate(*py_model(p), (0.0, 0.5), Q0, V0, h=h, m=1, progress=True)
        err = capsys.readouterr().err
        assert "galpha:" in err and "/0.5 s" in err and "%" in err


# ---- the other callback slots, compiled: the numbers of their Python twins, bit for bit ----
@cfunc(types.int32(types.float64, dp, dp, dp, dp, dp, vp))
def c_stiffness(t, q, v, qdd, lam, K, user):
    out, mu = carray(K, 4), carray(lam, 1)
    out[0], out[1], out[2], out[3] = mu[0], 0.0, 0.0, mu[0]
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, vp))
def c_accel(t, q, v, out, user):
    x = carray(v, 2)
    carray(out, 1)[0] = x[0] * x[0] + x[1] * x[1]
    return 0


@cfunc(types.int32(types.float64, dp, dp, vp))
def c_phi_t(t, q, out, user):
    carray(out, 1)[0] = 0.0
    return 0


@cfunc(types.int32(types.float64, dp, dp, types.int32, dp, vp))
def c_force_p(t, q, v, j, f_p, user):
    p, out = carray(user, 3, np.float64), carray(f_p, 2)
    out[0] = 0.0
    out[1] = -p[2] if j == 0 else (-p[0] if j == 2 else 0.0)
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, dp, dp, dp, dp, dp, dp, dp, vp))
def c_cost(t, q, v, qdd, lam, value, d_q, d_v, d_qdd, d_lam, d_p, user):
    x = carray(q, 2)
    carray(value, 1)[0] = x[0] * x[1]
    g = carray(d_q, 2)
    g[0], g[1] = x[1], x[0]
    return 0


def test_every_other_slot_compiled():
    def stiffness(t, q, v, qdd, lam, K):
        K[0, 0] = K[1, 1] = lam[0]

    def accel(t, q, v, out):
        out[0] = v[0] * v[0] + v[1] * v[1]

    def phi_t(t, q, out):
        out[0] = 0.0

    def force_p(t, q, v, j, f_p):
        f_p[1] = -p[2] if j == 0 else (-p[0] if j == 2 else 0.0)

    def cost(t, q, v, qdd, lam, d_q, d_v, d_qdd, d_lam, d_p):
        d_q[0], d_q[1] = q[1], q[0]
        return q[0] * q[1]

    results = []
    for compiled in (False, True):
        p = np.array([1.3, 0.8, 9.81])
        cbs = ((c_mass, c_force, c_constraint, c_jacobian) if compiled else py_model(p))
        extra = dict(stiffness=c_stiffness, constraint_accel=c_accel, constraint_dt=c_phi_t,
                     force_p=c_force_p) if compiled else dict(
            stiffness=stiffness, constraint_accel=accel, constraint_dt=phi_t, force_p=force_p)
        with galpha.Solver(2, 1, *cbs, user=p if compiled else None, parameters=p,
                           sensitivity_method=("forward", "adjoint"), max_steps=400,
                           formulation=galpha.GA_INDEX2_STABILIZED, **extra) as s:
            s.init(0.0, Q0, V0)
            for _ in range(300):
                s.step(1e-3)
            sens = s.sensitivity()
            J, dJ = s.adjoint_gradient(terminal=c_cost if compiled else cost)
            results.append((s.q.copy(), s.lam.copy(), sens.dq, sens.dlam, J, dJ, s.stats))
    (q1, l1, dq1, dl1, J1, g1, st1), (q2, l2, dq2, dl2, J2, g2, st2) = results
    for a, b in ((q1, q2), (l1, l2), (dq1, dq2), (dl1, dl2), (g1, g2)):
        np.testing.assert_array_equal(a, b)
    assert J1 == J2
    # the compiled slots were used: the tangent and the constraint terms by callback
    for st in (st1, st2):
        assert st["stiffness_evals"] > 0 and st["accel_evals"] > 0
        assert st["constraint_dt_evals"] > 0
    # the adjoint gradient is the forward one (d(x y)/dp from dq)
    x, y = q1
    np.testing.assert_allclose(g1, y * dq1[0] + x * dq1[1], rtol=1e-9)


def test_numba_example():
    # examples/python/numba_pendulum.py: the peak rod force its compiled hook records, against
    # the exact m g (3 - 2 cos theta0) at the bottom
    script = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python",
                          "numba_pendulum.py")
    # (the example imports the source tree's package: it is told which library this process
    # loaded, wherever the build tree lies)
    out = subprocess.run([sys.executable, script], check=True, capture_output=True, text=True,
                         env=dict(os.environ, GALPHA_LIBRARY=galpha._ffi.path)).stdout
    import re
    peak, exact = map(float, re.search(r"peak rod force = ([0-9.]+) N \(exact ([0-9.]+)\)",
                                       out).groups())
    assert abs(peak - exact) < 1e-7 * exact


# first-order states: x'' = -k x + y, y' = -2 y (k = user[0]), with the coupling blocks
@cfunc(types.int32(types.float64, dp, dp, vp))
def c_unit_mass(t, q, M, user):
    carray(M, 1)[0] = 1.0
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, dp, vp))
def c_force_y(t, q, v, y, f, user):
    carray(f, 1)[0] = -carray(user, 1, np.float64)[0] * carray(q, 1)[0] + carray(y, 1)[0]
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, dp, vp))
def c_rate(t, q, v, y, ydot, user):
    carray(ydot, 1)[0] = -2.0 * carray(y, 1)[0]
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, dp, dp, dp, dp, vp))
def c_coupling(t, q, v, y, g_q, g_v, g_y, f_y, user):
    carray(g_q, 1)[0] = 0.0
    carray(g_v, 1)[0] = 0.0
    carray(g_y, 1)[0] = -2.0
    carray(f_y, 1)[0] = 1.0
    return 0


@cfunc(types.int32(types.float64, dp, dp, dp, vp))
def c_damping(t, q, v, C, user):
    carray(C, 1)[0] = 0.0
    return 0


def test_first_order_slots_compiled():
    k = np.array([4.0])

    def force_y(t, q, v, y, f):
        f[0] = -k[0] * q[0] + y[0]

    def rate(t, q, v, y, ydot):
        ydot[0] = -2.0 * y[0]

    def coupling(t, q, v, y, g_q, g_v, g_y, f_y):
        g_y[0, 0], f_y[0, 0] = -2.0, 1.0

    def unit_mass(t, q, M):
        M[0, 0] = 1.0

    def damping(t, q, v, C):
        C[0, 0] = 0.0

    runs = []
    for cbs in ((unit_mass, force_y, rate, coupling, damping, None),
                (c_unit_mass, c_force_y, c_rate, c_coupling, c_damping, k)):
        with galpha.Solver(1, 0, cbs[0], r=1, force_y=cbs[1], rate=cbs[2], coupling=cbs[3],
                           damping=cbs[4], user=cbs[5]) as s:
            s.init(0.0, [0.0], [0.0], [1.0])
            for _ in range(500):
                s.step(1e-3)
            runs.append((s.q.copy(), s.v.copy(), s.y.copy(), s.stats["coupling_evals"],
                         s.stats["damping_evals"]))
    for a, b in zip(*runs):
        np.testing.assert_array_equal(a, b)
    assert runs[1][3] > 0 and runs[1][4] > 0


def test_a_cfunc_with_another_signature_is_refused():
    """numba's cfunc carries its signature: a mass callback declared without `user` (three
    arguments) was accepted and ended in a misleading SingularMatrixError."""
    from numba import cfunc, types
    dp = types.CPointer(types.float64)

    @cfunc(types.int32(types.float64, dp, dp))
    def short_mass(t, q, M):
        return 0

    with pytest.raises(TypeError, match=r"short_mass has the signature int\(double, pointer, "
                       r"pointer\).*calls it as int\(double, pointer, pointer, pointer\)"):
        galpha.Solver(2, 1, short_mass, None, lambda t, q, phi: None, lambda t, q, J: None)

    @cfunc(types.int64(types.float64, dp, dp, types.voidptr))
    def wide_mass(t, q, M, u):
        return 0

    with pytest.raises(TypeError, match="wide_mass has the signature"):
        galpha.Solver(2, 1, wide_mass, None, lambda t, q, phi: None, lambda t, q, J: None)
