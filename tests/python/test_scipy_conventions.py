"""galpha.integrate with scipy.integrate.solve_ivp's habits: its keywords (rtol, atol scalar or
per coordinate, max_step, first_step, args, method), callbacks that return their value,
sol.y and the counters, sol.sol(t) over arrays with qdd and lambda; Solver.interpolate over
arrays, repr, docstrings and type hints on every public name.

Expected values: the same run through galpha's own keywords (bit for bit), and an independent
RK4 solution of the pendulum's angle equation (numpy, not galpha) for the interpolants' order."""
import inspect
import math
import os
import sys
import types
import typing

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

Q0, V0 = [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0]


# ---- the pendulum as a solve_ivp user writes it: values returned, parameters in args ------
def mass_r(t, q, g, length):
    return np.eye(2)


def force_r(t, q, v, g, length):
    return np.array([0.0, -g])


def constraint_r(t, q, g, length):
    return 0.5 * (q @ q - length * length)


def jacobian_r(t, q, g, length):
    return q


def passes_vertical(t, q, v, lam, g, length):
    return q[0]


passes_vertical.terminal = True
passes_vertical.direction = -1


# ---- the same in galpha's own convention: outputs filled, parameters closed over ----------
G, LENGTH = 9.81, 1.0


def mass_f(t, q, M):
    M[:] = np.eye(2)


def force_f(t, q, v, f):
    f[:] = (0.0, -G)


def constraint_f(t, q, phi):
    phi[0] = 0.5 * (q @ q - LENGTH * LENGTH)


def jacobian_f(t, q, J):
    J[0, :] = q


def vertical_f(t, q, v, lam):
    return q[0]


vertical_f.terminal = True
vertical_f.direction = -1


def test_a_solve_ivp_script_runs_unchanged_and_gives_galphas_numbers():
    # what a scipy user writes first
    sol = galpha.integrate(mass_r, force_r, constraint_r, jacobian_r, (0.0, 2.0), Q0, V0, m=1,
                           rtol=1e-6, atol=1e-8, max_step=0.05, first_step=1e-3,
                           args=(9.81, 1.0), method="index2", dense_output=True,
                           events=[passes_vertical])
    assert sol.success and sol.status == 1 and "terminal event" in sol.message
    t = np.linspace(0.0, sol.t[-1], 7)
    y = sol.sol(t)
    assert sol.y.shape == (4, sol.t.size) and y.shape == (4, 7)
    # galpha's own keywords
    own = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 2.0), Q0, V0, m=1,
                           tolerances=(1e-6, 1e-8), step_limits=(0.0, 0.05),
                           initial_step=1e-3, formulation=galpha.GA_INDEX2_STABILIZED,
                           dense_output=True, events=[vertical_f])
    np.testing.assert_array_equal(sol.t, own.t)
    np.testing.assert_array_equal(sol.y, np.vstack([own.q.T, own.v.T]))
    np.testing.assert_array_equal(sol.lam, own.lam)
    np.testing.assert_array_equal(y, own.sol(t))
    np.testing.assert_array_equal(sol.t_events[0], own.t_events[0])
    np.testing.assert_array_equal(sol.y_events[0], own.y_events[0])
    assert (sol.nfev, sol.njev, sol.nlu) == (own.nfev, own.njev, own.nlu)
    # the event: the quarter period of the pendulum released at 1 rad
    assert abs(sol.t_events[0][0] - _quarter_period()) < 1e-5


def _quarter_period():
    """Quarter period of the pendulum released at 1 rad (g = 9.81, L = 1): K(sin 0.5) /
    sqrt(g), the complete elliptic integral by the arithmetic-geometric mean."""
    a, b = 1.0, math.cos(0.5)
    for _ in range(30):
        a, b = (a + b) / 2, math.sqrt(a * b)
    return math.pi / (2 * a) / math.sqrt(9.81)


def test_counters_are_solve_ivps():
    sol = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 0.5), Q0, V0, m=1,
                           rtol=1e-5)
    assert sol.nfev == sol.stats["residuals"] > 0
    assert sol.njev == sol.stats["stiffness_evals"]
    assert sol.nlu == sol.stats["factorizations"] > 0
    assert sol.message == "reached t_span[1]"


def test_atol_per_coordinate():
    # rtol so small that atol sets the weights
    common = dict(m=1, rtol=1e-9, method="index2")
    one = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0,
                           atol=1e-5, **common)
    each = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0,
                            atol=[1e-5] * 4, **common)
    np.testing.assert_array_equal(one.y, each.y)  # equal entries: the scalar, bit for bit
    tight = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0,
                             atol=[1e-5, 1e-5, 1e-8, 1e-5], **common)
    assert tight.t.size > 2 * one.t.size  # a velocity held 1000 times tighter
    with pytest.raises(galpha.ArgumentError, match="2 n"):
        galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0,
                         atol=[1e-7] * 3, **common)
    with pytest.raises(galpha.ArgumentError, match=r"atol\[1\]"):
        galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0,
                         atol=[1e-7, 0.0, 1e-7, 1e-7], **common)


def test_keywords_said_twice_or_out_of_place_are_refused():
    run = lambda **kw: galpha.integrate(mass_f, force_f, constraint_f, jacobian_f,  # noqa
                                        (0.0, 0.1), Q0, V0, m=1, **kw)
    with pytest.raises(TypeError, match="tolerances"):
        run(rtol=1e-6, tolerances=(1e-6, 1e-6))
    with pytest.raises(TypeError, match="formulation"):
        run(method="index2", formulation=galpha.GA_INDEX3)
    with pytest.raises(ValueError, match="solve_ivp's ODE methods"):
        run(method="RK45")
    with pytest.raises(ValueError, match="fixes the steps"):
        run(h=1e-3, rtol=1e-6)
    with pytest.raises(ValueError, match="max_step"):
        run(max_step=0.0)
    assert run(max_step=np.inf).success  # solve_ivp's default: no bound


def test_callbacks_may_return_their_value_or_fill_it():
    filled = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 0.3), Q0, V0,
                              1e-3, m=1)
    returned = galpha.integrate(lambda t, q: np.eye(2), lambda t, q, v: (0.0, -G),
                                lambda t, q: 0.5 * (q @ q - 1.0), lambda t, q: q,
                                (0.0, 0.3), Q0, V0, 1e-3, m=1)
    np.testing.assert_array_equal(filled.y, returned.y)
    np.testing.assert_array_equal(filled.lam, returned.lam)
    with_args = galpha.integrate(lambda t, q, M, g: mass_f(t, q, M),
                                 lambda t, q, v, f, g: f.__setitem__(slice(None), (0.0, -g)),
                                 lambda t, q, phi, g: constraint_f(t, q, phi),
                                 lambda t, q, J, g: jacobian_f(t, q, J), (0.0, 0.3), Q0, V0,
                                 1e-3, m=1, args=(G,))
    np.testing.assert_array_equal(filled.y, with_args.y)


def test_a_returning_callback_is_checked():
    with pytest.raises(TypeError, match="returned None"):
        galpha.integrate(mass_f, lambda t, q, v: None, constraint_f, jacobian_f, (0.0, 0.1),
                         Q0, V0, 1e-3, m=1)
    with pytest.raises(ValueError, match="shape"):
        galpha.integrate(mass_f, lambda t, q, v: np.zeros(3), constraint_f, jacobian_f,
                         (0.0, 0.1), Q0, V0, 1e-3, m=1)
    # neither convention: refused when the solver is built, naming both
    with pytest.raises(TypeError, match=r"force\(t, q, v, f\).*force\(t, q, v\)"):
        galpha.Solver(2, 1, mass_f, lambda t: None, constraint_f, jacobian_f)


def test_a_returned_value_is_never_broadcast():
    """A value of another shape than its output is refused, as scipy refuses fun's: a scalar
    force for n = 2 filled both entries, a vector for the 2 x 2 mass both rows."""
    with pytest.raises(ValueError, match=r"force returned float of shape \(\); f has shape \(2,\)"):
        galpha.integrate(mass_f, lambda t, q, v: -G, constraint_f, jacobian_f, (0.0, 0.1),
                         Q0, V0, 1e-3, m=1)
    with pytest.raises(ValueError, match=r"mass returned .* of shape \(2,\); M has shape \(2, 2\)"):
        galpha.integrate(lambda t, q: np.ones(2), force_f, constraint_f, jacobian_f, (0.0, 0.1),
                         Q0, V0, 1e-3, m=1)
    # two constraints returned as one number (the pendulum's twice): refused, not copied
    with pytest.raises(ValueError, match=r"constraint returned float64 of shape \(\); phi has shape \(2,\)"):
        galpha.integrate(mass_f, force_f, lambda t, q: 0.5 * (q @ q - 1.0),
                         lambda t, q: np.vstack([q, q]), (0.0, 0.1), Q0, V0, 1e-3, m=2)
    # one constraint: a number is its one entry
    r = galpha.integrate(mass_f, force_f, lambda t, q: 0.5 * (q @ q - 1.0), lambda t, q: q,
                         (0.0, 0.1), Q0, V0, 1e-3, m=1)
    assert r.success


def test_args_and_an_ambiguous_callback_are_named():
    # args must be a tuple (scipy: "supply args as a tuple")
    with pytest.raises(TypeError, match=r"args must be a tuple .* args=\(9.81,\)"):
        galpha.integrate(mass_r, force_r, constraint_r, jacobian_r, (0.0, 0.1), Q0, V0, 1e-3,
                         m=1, args=9.81)
    # constraint(t, q, phi) with args=(g,): three arguments, taken as constraint(t, q, g) -> phi;
    # its failure says which convention was taken and how to write the other
    with pytest.raises(TypeError) as e:
        galpha.integrate(lambda t, q, M, g: mass_f(t, q, M),
                         lambda t, q, v, f, g: force_f(t, q, v, f), constraint_f,
                         lambda t, q, J, g: jacobian_f(t, q, J), (0.0, 0.1), Q0, V0, 1e-3,
                         m=1, args=(G,))
    notes = "\n".join(getattr(e.value, "__notes__", []))
    assert "constraint was taken as returning its output, constraint(t, q, *args) -> phi" in notes
    assert "constraint(t, q, phi, *args)" in notes


@pytest.mark.parametrize("fail_at", range(3, 40))
def test_a_failure_while_an_accepted_step_is_recorded(fail_at):
    """An adaptive run without events records each accepted step from the step hook, and the
    consistent qdd and lam it reads evaluate the force: a CallbackRetry there ended integrate
    with an internal "cannot reshape" (ts, q, v were appended, qdd not). Now every run
    returns a result: success, or the failure's status and message, the rows all as long."""
    calls = [0]

    def force(t, q, v, f):
        calls[0] += 1
        if calls[0] == fail_at:
            raise galpha.CallbackRetry("not now")
        f[:] = (0.0, -G)
    r = galpha.integrate(mass_f, force, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0, m=1,
                         rtol=1e-6)
    assert r.success or (r.status == galpha.CallbackRetry.status and "force" in r.message)
    assert r.q.shape == (len(r.t), 2) and r.lam.shape == (len(r.t), 1)
    assert r.qdd.shape == (len(r.t), 2) and r.y.shape == (4, len(r.t))


def test_callback_retry_raised_in_a_callback_is_recoverable():
    failed = []

    def force(t, q, v):
        if t > 0.2 and not failed:
            failed.append(t)
            raise galpha.CallbackRetry("not this one")
        return (0.0, -G)
    sol = galpha.integrate(mass_f, force, constraint_f, jacobian_f, (0.0, 0.5), Q0, V0, m=1,
                           rtol=1e-5)
    assert sol.success and failed and sol.stats["failed_steps"] >= 1
    with galpha.Solver(2, 1, mass_f, force, constraint_f, jacobian_f) as s:
        failed.clear()
        s.init(0.0, Q0, V0)
        s.step(0.1)
        s.step(0.1)
        with pytest.raises(galpha.CallbackRetry):
            s.step(0.1)  # fixed steps: the failure is reported, the state kept
        assert s.t == pytest.approx(0.2)


@pytest.mark.parametrize("bare", [True, False])
def test_callback_retry_raised_without_a_message(bare):
    """`raise galpha.CallbackRetry`, the class as Python code raises it, is the same
    recoverable failure as with a message (it was a TypeError from __init__)."""
    failed = []

    def force(t, q, v):
        if t > 0.2 and not failed:
            failed.append(t)
            if bare:
                raise galpha.CallbackRetry
            raise galpha.CallbackRetry()
        return (0.0, -G)
    sol = galpha.integrate(mass_f, force, constraint_f, jacobian_f, (0.0, 0.5), Q0, V0, m=1,
                           rtol=1e-5)
    assert sol.success and failed and sol.stats["failed_steps"] >= 1
    assert str(galpha.CallbackRetry()) == ("A callback asked for a retry (it returned a positive "
                                           "value or raised CallbackRetry).")


def _reference(t_end, steps=20000):
    """Pendulum released at 1 rad: q, v, qdd, lam at t_end by RK4 on the angle (numpy)."""
    th, om, h = 1.0, 0.0, t_end / steps
    f = lambda th, om: (om, -G * math.sin(th))  # noqa: E731
    for _ in range(steps):
        k1 = f(th, om)
        k2 = f(th + h / 2 * k1[0], om + h / 2 * k1[1])
        k3 = f(th + h / 2 * k2[0], om + h / 2 * k2[1])
        k4 = f(th + h * k3[0], om + h * k3[1])
        th += h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        om += h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    q = np.array([math.sin(th), -math.cos(th)])
    v = om * np.array([math.cos(th), math.sin(th)])
    lam = v @ v - G * q[1]  # from (q . qdd + |v|^2 = 0) with qdd = f - q lam, |q| = 1
    return q, v, np.array([0.0, -G]) - q * lam, lam


def test_whole_run_interpolant_is_second_order_in_qdd_and_lambda():
    # between the steps: t at 0.37 of a step of the coarsest run
    t = 0.3 + 0.37 * 0.02
    q_ref, v_ref, a_ref, l_ref = _reference(t)
    errors = []
    for h in (0.02, 0.01, 0.005):
        sol = galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 0.5), Q0, V0,
                               h, m=1, dense_output=True)
        errors.append([np.abs(sol.sol.q(t) - q_ref).max(), np.abs(sol.sol.v(t) - v_ref).max(),
                       np.abs(sol.sol.qdd(t) - a_ref).max(), abs(sol.sol.lam(t)[0] - l_ref)])
        k = np.array([0.1, t, 0.45])
        assert sol.sol.qdd(k).shape == (2, 3) and sol.sol.lam(k).shape == (1, 3)
        np.testing.assert_array_equal(sol.sol(k)[:, 1], sol.sol(t))
    errors = np.array(errors)
    orders = np.log2(errors[:-1] / errors[1:])
    print("interpolant errors (q, v, qdd, lam) per h:", errors, "orders:", orders)
    assert np.all((orders > 1.6) & (orders < 2.6)), orders


def test_states_in_y_and_in_the_interpolant():
    # the pendulum's angle integrated as a first-order state: y' = -v_x / q_y... kept simple:
    # y' = -y, y(0) = 1, so y = exp(-t)
    def rate(t, q, v, y):
        return -y

    def force_y(t, q, v, y):
        return (0.0, -G)
    sol = galpha.integrate(mass_f, None, constraint_f, jacobian_f, (0.0, 1.0), Q0, V0, 1e-3,
                           m=1, r=1, rate=rate, force_y=force_y, y0=[1.0], dense_output=True)
    assert sol.y.shape == (5, sol.t.size)
    np.testing.assert_array_equal(sol.y[4], sol.states[:, 0])
    assert abs(sol.y[4, -1] - math.exp(-1.0)) < 1e-6
    t = np.array([0.2555, 0.7305])
    assert np.abs(sol.sol.states(t)[0] - np.exp(-t)).max() < 1e-6
    assert sol.sol(t).shape == (5, 2)
    with pytest.raises(ValueError, match="first-order"):
        galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 0.1), Q0, V0, 1e-3,
                         m=1, dense_output=True).sol.states(0.05)


def test_solver_interpolate_takes_arrays():
    with galpha.Solver(2, 1, mass_f, force_f, constraint_f, jacobian_f) as s:
        s.init(0.0, Q0, V0)
        s.step(0.01)
        times = np.array([0.002, 0.005, 0.0093])
        q, v, lam = s.interpolate(times)
        qdd = s.interpolate_qdd(times)
        assert q.shape == (3, 2) and v.shape == (3, 2) and lam.shape == (3, 1)
        for k, tk in enumerate(times):
            one = s.interpolate(tk)
            np.testing.assert_array_equal(q[k], one[0])
            np.testing.assert_array_equal(v[k], one[1])
            np.testing.assert_array_equal(lam[k], one[2])
            np.testing.assert_array_equal(qdd[k], s.interpolate_qdd(tk))


def test_repr_says_what_the_solver_is():
    s = galpha.Solver(2, 1, mass_f, force_f, constraint_f, jacobian_f)
    assert repr(s) == "<galpha.Solver n=2, m=1, not initialized>"
    s.init(0.0, Q0, V0)
    for _ in range(3):
        s.step(0.01)
    assert repr(s).startswith("<galpha.Solver n=2, m=1, t=0.03, steps=3, dense")
    s.close()
    assert repr(s) == "<galpha.Solver n=2, m=1, closed>"


def _public(module):
    for name in sorted(dir(module)):
        obj = getattr(module, name)
        if name.startswith("_") or isinstance(obj, (int, float, str, types.ModuleType)):
            continue
        home = getattr(obj, "__module__", None) or module.__name__
        if not home.startswith("galpha") or (module is not galpha and home != module.__name__):
            continue  # another module's, imported
        yield "%s.%s" % (module.__name__, name), obj


def _members(cls):
    for name, member in vars(cls).items():
        if name.startswith("_") or not (callable(member) or isinstance(member, property)):
            continue
        yield name, member


def test_every_public_name_has_a_docstring_and_type_hints():
    import galpha.ensemble
    missing, unhinted = [], []
    for module in (galpha, galpha.so3, galpha.se3, galpha.ensemble):
        if not inspect.getdoc(module):
            missing.append(module.__name__)
        for name, obj in _public(module):
            if not (obj.__doc__ or "").strip():
                missing.append(name)
            if inspect.isfunction(obj):
                hints = typing.get_type_hints(obj)  # every annotation resolves
                if "return" not in hints:
                    unhinted.append(name)
            if inspect.isclass(obj) and obj.__module__.startswith("galpha"):
                for member_name, member in _members(obj):
                    fn = member.fget if isinstance(member, property) else member
                    if not (getattr(member, "__doc__", None) or "").strip():
                        missing.append("%s.%s" % (name, member_name))
                    if inspect.isfunction(fn) and obj in (galpha.Solver, galpha.OdeSolution):
                        if "return" not in typing.get_type_hints(fn):
                            unhinted.append("%s.%s" % (name, member_name))
    assert not missing, "no docstring: " + ", ".join(missing)
    assert not unhinted, "no return annotation: " + ", ".join(unhinted)
    package = os.path.dirname(galpha.__file__)
    assert os.path.isfile(os.path.join(package, "py.typed"))


def test_an_unknown_keyword_is_integrates():
    """A misspelt keyword is reported as integrate's, not as Solver.__init__()'s."""
    with pytest.raises(TypeError, match=r"integrate\(\) got an unexpected keyword argument 'rtoll'"):
        galpha.integrate(mass_f, force_f, constraint_f, jacobian_f, (0.0, 0.1), Q0, V0, m=1,
                         rtoll=1e-6)
