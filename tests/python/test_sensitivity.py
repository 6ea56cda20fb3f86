"""Forward sensitivities from Python: Solver(parameters=...) and Solver.sensitivity()."""
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:  # else: the package comes from PYTHONPATH
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402

L = 1.0
Q0 = np.array([np.sin(1.0), -np.cos(1.0)])
V0 = np.zeros(2)


def pendulum(p, **options):
    """The pendulum with mass p[0] and gravity p[1], read from p at every call."""
    def mass(t, q, M):
        M[:] = p[0] * np.eye(2)

    def force(t, q, v, f):
        f[:] = (0.0, -p[0] * p[1])

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q @ q - L * L)

    def jacobian(t, q, J):
        J[0, :] = q

    return galpha.Solver(2, 1, mass, force, constraint, jacobian, **options)


def final_state(p, steps=100, h=1e-2, **options):
    with pendulum(p, **options) as s:
        s.init(0.0, Q0, V0)
        for _ in range(steps):
            s.step(h)
        return s.q.copy(), s.v.copy(), s.lam.copy(), (s.sensitivity() if "parameters" in
                                                       options else None)


def test_sensitivities_are_derivatives_of_the_discrete_solution():
    """Against central differences of whole runs (full Newton), index 3 and 2."""
    for formulation in (galpha.GA_INDEX3, galpha.GA_INDEX2_STABILIZED):
        p = np.array([1.0, 9.81])
        q, v, lam, sens = final_state(p, parameters=p, depends=("force", "mass"),
                                      formulation=formulation)
        assert sens.dq.shape == (2, 2) and sens.dlam.shape == (1, 2)
        assert np.array_equal(p, [1.0, 9.81])  # restored after every perturbation
        for j in range(2):
            e = 1e-4 * p[j]
            runs = []
            for sign in (1, -1):
                pp = p.copy()
                pp[j] += sign * e
                runs.append(final_state(pp, reuse=galpha.GA_REUSE_NEVER, newton=(1e-13, 30),
                                        formulation=formulation))
            for k, d in enumerate((sens.dq, sens.dv)):
                fd = (runs[0][k] - runs[1][k]) / (2 * e)
                assert np.allclose(d[:, j], fd, rtol=0, atol=1e-7 * max(1.0, np.abs(fd).max()))


def length_pendulum(p, **options):
    """The pendulum of unit mass, length p[0] (in the constraint only) and gravity p[1]."""
    def mass(t, q, M):
        M[:] = np.eye(2)

    def force(t, q, v, f):
        f[:] = (0.0, -p[1])

    def constraint(t, q, phi):
        phi[0] = 0.5 * (q @ q - p[0] * p[0])

    def jacobian(t, q, J):
        J[0, :] = q

    return galpha.Solver(2, 1, mass, force, constraint, jacobian, **options)


def length_run(p, **options):
    with length_pendulum(p, **options) as s:
        s.init(0.0, Q0, V0)  # consistent at L = 1 only: the start projects it
        for _ in range(100):
            s.step(1e-2)
        return s.q.copy(), s.v.copy(), (s.sensitivity() if "parameters" in options else None)


def test_parameters_in_the_constraints():
    """depends=("constraint",): against whole-run central differences (index 2), and the
    constraint_p callback against galpha's differences."""
    p = np.array([1.0, 9.81])
    asked = []

    def constraint_p(t, q, j, phi_p, Phi_q_p, Phi_t_p):
        asked.append(Phi_t_p is not None)
        phi_p[0] = -p[0] if j == 0 else 0.0
        Phi_q_p[:] = 0.0
        if Phi_t_p is not None:
            Phi_t_p[0] = 0.0

    f = galpha.GA_INDEX2_STABILIZED
    deps = ("force", "constraint")
    q, v, sens = length_run(p, parameters=p, depends=deps, formulation=f)
    e = 1e-4
    runs = []
    for sign in (1, -1):
        pp = p.copy()
        pp[0] += sign * e
        runs.append(length_run(pp, reuse=galpha.GA_REUSE_NEVER, newton=(1e-13, 30),
                               formulation=f))
    for k, d in enumerate((sens.dq, sens.dv)):
        fd = (runs[0][k] - runs[1][k]) / (2 * e)
        assert np.allclose(d[:, 0], fd, rtol=0, atol=1e-6 * np.abs(fd).max())
    exact = length_run(p, parameters=p, depends=deps, formulation=f, constraint_p=constraint_p)
    assert True in asked and False in asked  # dPhi_t/dp where index 2 needs it, only there
    for a, b in zip(sens, exact[2]):
        assert np.allclose(a, b, rtol=1e-8, atol=1e-10)


def test_derivative_callbacks():
    """df/dp and (dM/dp) a by callbacks give what central differences give."""
    p = np.array([1.0, 9.81])

    def force_p(t, q, v, j, out):
        out[:] = (0.0, -p[1]) if j == 0 else (0.0, -p[0])

    def mass_p(t, q, j, a, out):
        out[:] = a if j == 0 else 0.0

    by_differences = final_state(p, parameters=p, depends=("force", "mass"))[3]
    by_callbacks = final_state(p, parameters=p, depends=("force", "mass"), force_p=force_p,
                               mass_p=mass_p)[3]
    for a, b in zip(by_differences, by_callbacks):
        assert np.allclose(a, b, rtol=1e-8, atol=1e-10)


def test_refusals():
    with pytest.raises(ValueError, match="float64"):
        pendulum([1.0, 9.81], parameters=[1.0, 9.81])
    with pytest.raises(ValueError, match="float64"):
        pendulum(None, parameters=np.array([1, 2]))
    with pytest.raises(ValueError, match="dependence"):
        pendulum(None, parameters=np.array([1.0]), depends=("constraints",))
    with pytest.raises(ValueError, match="shape"):
        pendulum(None, parameters=np.array([1.0]), parameter_scale=[1.0, 2.0])
    with pytest.raises(galpha.ArgumentError, match="p_scale"):
        pendulum(None, parameters=np.array([1.0]), parameter_scale=[-1.0])
    p = np.array([1.0, 9.81])
    with pendulum(p) as s:
        s.init(0.0, Q0, V0)
        with pytest.raises(galpha.StateError, match="no sensitivities"):
            s.sensitivity()
    with pendulum(p, parameters=p) as s:
        with pytest.raises(galpha.StateError):
            s.sensitivity()  # before init


def test_callback_errors_reach_the_caller():
    p = np.array([1.0, 9.81])

    def broken(t, q, v, j, out):
        raise RuntimeError("no derivative today")

    with pendulum(p, parameters=p, force_p=broken) as s:
        s.init(0.0, Q0, V0)
        with pytest.raises(RuntimeError, match="no derivative today"):
            s.step(1e-2)
        assert s.t == 0.0


def test_adjoint_gradient_equals_forward():
    """dJ/dp of J = integral of |v|^2 / 2 + lambda^2 plus the final height, by the adjoint
    sweep and by the forward sensitivities summed with the same trapezoidal weights."""
    p = np.array([1.0, 9.81])

    def running(t, q, v, qdd, lam, d_q, d_v, d_qdd, d_lam, d_p):
        d_v[:] = v
        d_lam[0] = 2.0 * lam[0]
        return 0.5 * v @ v + lam[0] ** 2

    def terminal(t, q, v, qdd, lam, d_q, d_v, d_qdd, d_lam, d_p):
        d_q[1] = 1.0
        return q[1]

    h, steps = 1e-2, 100
    with pendulum(p, parameters=p, depends=("force", "mass"),
                  sensitivity_method=("forward", "adjoint"), max_steps=steps,
                  output=galpha.GA_OUTPUT_STEP) as s:
        s.init(0.0, Q0, V0)
        J_fwd, dJ_fwd, prev = 0.0, np.zeros(2), None
        for k in range(steps + 1):
            if k:
                s.step(h)
            v, lam, sens = s.v, s.lam, s.sensitivity()
            L = 0.5 * v @ v + lam[0] ** 2
            dL = v @ sens.dv + 2.0 * lam[0] * sens.dlam[0]
            if prev is not None:
                J_fwd += 0.5 * h * (prev[0] + L)
                dJ_fwd += 0.5 * h * (prev[1] + dL)
            prev = (L, dL)
        J_fwd += s.q[1]
        dJ_fwd += s.sensitivity().dq[1]
        J, dJ = s.adjoint_gradient(running, terminal)
    assert J == pytest.approx(J_fwd, rel=1e-12)
    assert np.allclose(dJ, dJ_fwd, rtol=1e-9, atol=1e-12)
    # checkpointing: segments of 8 steps recomputed from checkpoints, the same numbers
    with pendulum(p, parameters=p, depends=("force", "mass"),
                  sensitivity_method=("forward", "adjoint"),
                  max_steps=steps, adjoint_checkpoints=(8, 13),
                  output=galpha.GA_OUTPUT_STEP) as s:
        s.init(0.0, Q0, V0)
        for _ in range(steps):
            s.step(h)
        J2, dJ2 = s.adjoint_gradient(running, terminal)
    assert J2 == J and np.array_equal(dJ2, dJ)


def test_adjoint_refusals_and_errors():
    p = np.array([1.0, 9.81])
    with pytest.raises(ValueError, match="max_steps"):
        pendulum(p, parameters=p, sensitivity_method=("adjoint",))
    with pytest.raises(ValueError, match="unknown sensitivity method"):
        pendulum(p, parameters=p, sensitivity_method=("backward",))

    def broken(t, q, v, qdd, lam, *grads):
        raise ZeroDivisionError("cost")

    with pendulum(p, parameters=p, sensitivity_method=("adjoint",), max_steps=10) as s:
        s.init(0.0, Q0, V0)
        s.step(1e-2)
        with pytest.raises(ZeroDivisionError):
            s.adjoint_gradient(terminal=broken)
        with pytest.raises(galpha.ArgumentError, match="no cost"):
            s.adjoint_gradient()
        with pytest.raises(galpha.StateError):
            s.sensitivity()  # adjoint only: no forward sensitivities


def test_identification_example_recovers_the_parameters():
    """examples/python/identify_crank.py: Gauss-Newton with the forward sensitivities finds k
    and c from noise-free angles of a run with the same steps, to the solver's precision."""
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "examples", "python"))
    import identify_crank as ic
    measured = ic.crank_angles(ic.TRUE, 4e-3, False, t_end=3.0)[0]
    p, iterations = ic.identify(measured, h=4e-3, t_end=3.0, verbose=False)
    assert np.allclose(p, ic.TRUE, rtol=1e-7)
    assert iterations <= 8


def test_initial_values_as_parameters():
    """d/d omega0 of the pendulum started at rate omega0: v0 = L omega0 (cos, sin)."""
    def run(omega0, sens):
        p = np.array([omega0])
        q0 = np.array([np.sin(1.0), -np.cos(1.0)])
        v0 = omega0 * np.array([np.cos(1.0), np.sin(1.0)])
        options = dict(parameters=p) if sens else dict(reuse=galpha.GA_REUSE_NEVER,
                                                       newton=(1e-13, 30))
        with pendulum(np.array([1.0, 9.81]), **options) as s:
            if sens:
                s.set_sensitivity_start(0, dv0=[np.cos(1.0), np.sin(1.0)])
                with pytest.raises(galpha.ArgumentError):
                    s.set_sensitivity_start(1)
            s.init(0.0, q0, v0)
            for _ in range(100):
                s.step(1e-2)
            return s.q.copy(), (s.sensitivity().dq[:, 0] if sens else None)
    _, dq = run(0.5, True)
    e = 1e-5
    fd = (run(0.5 + e, False)[0] - run(0.5 - e, False)[0]) / (2 * e)
    assert np.allclose(dq, fd, rtol=0, atol=1e-8 * np.abs(fd).max())


def test_first_order_states():
    """x'' = -x + y, y' = -c y (c the parameter, read by the rate): dy/dc and dx/dc against
    central differences of whole runs."""
    def run(c, sens):
        p = np.array([c])

        def mass(t, q, M):
            M[0, 0] = 1.0

        def force_y(t, q, v, y, f):
            f[0] = -q[0] + y[0]

        def rate(t, q, v, y, ydot):
            ydot[0] = -p[0] * y[0]

        options = (dict(parameters=p, depends=("rate",)) if sens
                   else dict(reuse=galpha.GA_REUSE_NEVER, newton=(1e-13, 30)))
        with galpha.Solver(1, 0, mass, r=1, rate=rate, force_y=force_y, **options) as s:
            s.init(0.0, [0.0], [0.0], [1.0])
            for _ in range(200):
                s.step(5e-3)
            return s.q.copy(), s.y.copy(), (s.sensitivity() if sens else None)
    q, y, S = run(2.0, True)
    assert S.dy.shape == (1, 1) and S.dydot.shape == (1, 1)
    e = 1e-5
    (qa, ya, _), (qb, yb, _) = run(2.0 + e, False), run(2.0 - e, False)
    assert S.dq[0, 0] == pytest.approx((qa[0] - qb[0]) / (2 * e), rel=1e-6)
    assert S.dy[0, 0] == pytest.approx((ya[0] - yb[0]) / (2 * e), rel=1e-6)
