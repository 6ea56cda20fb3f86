"""The heavy top on R^3 x SO(3) from Python (issue 36): Solver(space=...), the rotation built
with galpha.so3, against an independent reference -- Euler's equations about the pivot with a
rotation matrix by scipy's DOP853 at rtol 1e-12, checked by the Lagrange top's invariants.
Order 2 in the centre of mass in both formulations, quaternion and matrix storage agreeing to
round-off, the sparse path, and the space's argument checks."""
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402
from galpha import so3  # noqa: E402

scipy_integrate = pytest.importorskip("scipy.integrate")

MASS = 15.0
JC = np.array([0.234375, 0.46875, 0.234375])
X = np.array([0.0, 1.0, 0.0])
G = np.array([0.0, 0.0, -9.81])
OMEGA0 = np.array([0.0, 150.0, -4.61538])
JP = np.diag(JC) + MASS * (X @ X * np.eye(3) - np.outer(X, X))


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


class Top:
    """x in space, the rotation as a quaternion or a matrix (column-major in q), body omega."""

    def __init__(self, matrix):
        self.matrix = matrix
        self.nq = 12 if matrix else 7

    def rotation(self, q):
        r = q[3:]
        return r.reshape(3, 3, order="F") if self.matrix else so3.matrix(r)

    def mass(self, t, q, M):
        M[...] = np.diag(np.concatenate([MASS * np.ones(3), JC]))

    def force(self, t, q, v, f):
        w = v[3:]
        f[:3] = MASS * G
        f[3:] = -np.cross(w, JC * w)

    def constraint(self, t, q, phi):
        phi[...] = q[:3] - self.rotation(q) @ X

    def jacobian(self, t, q, J):
        J[:, :3] = np.eye(3)
        J[:, 3:] = self.rotation(q) @ hat(X)  # d/de of -R exp(e w) X

    def initial(self):
        rot = np.eye(3).ravel(order="F") if self.matrix else np.array([1.0, 0.0, 0.0, 0.0])
        return np.concatenate([X, rot]), np.concatenate([np.cross(OMEGA0, X), OMEGA0])

    def solver(self, formulation, **options):
        return galpha.Solver(6, 3, self.mass, self.force, self.constraint, self.jacobian,
                             space=[("vector", 3), ("so3_matrix" if self.matrix else "so3", 1)],
                             formulation=formulation, **options)


def reference(t_end):
    def rhs(t, y):
        R, w = y[:9].reshape(3, 3), y[9:]
        dw = np.linalg.solve(JP, -np.cross(w, JP @ w) + np.cross(X, R.T @ (MASS * G)))
        return np.concatenate([(R @ hat(w)).ravel(), dw])

    sol = scipy_integrate.solve_ivp(rhs, (0.0, t_end), np.concatenate([np.eye(3).ravel(), OMEGA0]),
                                    method="DOP853", rtol=1e-12, atol=1e-12)
    R, w = sol.y[:9, -1].reshape(3, 3), sol.y[9:, -1]

    def invariants(R, w):
        return np.array([0.5 * w @ JP @ w - MASS * G @ (R @ X), (R @ JP @ w)[2], w[1]])

    drift = np.abs(invariants(R, w) - invariants(np.eye(3), OMEGA0))
    assert np.all(drift <= 1e-9 * np.abs(invariants(np.eye(3), OMEGA0)))
    return R @ X, w


def run(top, formulation, h, t_end):
    with top.solver(formulation) as s:
        q0, v0 = top.initial()
        s.init(0.0, q0, v0)
        for _ in range(int(round(t_end / h))):
            s.step(h)
        return s.q, s.v


@pytest.mark.parametrize("formulation", [galpha.GA_INDEX3, galpha.GA_INDEX2_STABILIZED])
def test_order_two_in_the_centre_of_mass(formulation):
    com_ref, w_ref = reference(0.5)
    hs = np.array([1e-3, 5e-4, 2.5e-4])
    errors = []
    for h in hs:
        q, v = run(Top(False), formulation, h, 0.5)
        errors.append(np.abs(q[:3] - com_ref).max())
    order = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert 1.9 < order < 2.1, (errors, order)


def test_quaternion_and_matrix_storage_agree():
    qa, va = run(Top(False), galpha.GA_INDEX3, 1e-3, 0.5)
    qb, vb = run(Top(True), galpha.GA_INDEX3, 1e-3, 0.5)
    assert np.abs(qa[:3] - qb[:3]).max() < 1e-12
    assert np.abs(va - vb).max() < 1e-12 * 150
    assert np.abs(so3.matrix(qa[3:]) - qb[3:].reshape(3, 3, order="F")).max() < 1e-12


def test_shapes_and_dense_output_on_the_group():
    top = Top(False)
    with top.solver(galpha.GA_INDEX2_STABILIZED) as s:
        assert s.nq == 7 and s.n == 6
        q0, v0 = top.initial()
        s.init(0.0, q0, v0)
        s.step(1e-3)
        q, v, lam = s.interpolate(5e-4)
        assert q.shape == (7,) and v.shape == (6,) and lam.shape == (3,)
        assert abs(np.linalg.norm(q[3:]) - 1.0) < 1e-14
        with pytest.raises(galpha.ArgumentError, match="shapes"):
            s.init(0.0, v0, v0)


def test_space_arguments_are_checked():
    top = Top(False)
    with pytest.raises(ValueError, match="unknown kind"):
        galpha.Solver(6, 3, top.mass, space=[("vector", 3), ("so2", 1)])
    with pytest.raises(ValueError, match="count >= 1"):
        galpha.Solver(6, 3, top.mass, space=[("vector", 3), ("so3", 0)])
    with pytest.raises(galpha.ArgumentError, match="6 velocity coordinates"):
        galpha.Solver(7, 3, top.mass, top.force, top.constraint, top.jacobian,
                      space=[("vector", 3), ("so3", 1)])


class SparseTop(Top):
    """The same top with declared patterns (1-D value arrays): M's diagonal, Phi_q whole,
    K_t and C_t on the rotation's 3 x 3 block (by differences)."""
    ROT = (np.repeat(np.arange(3, 6), 3), np.tile(np.arange(3, 6), 3))
    PATTERNS = {"mass": (np.arange(6), np.arange(6)),
                "jacobian": (np.repeat(np.arange(3), 6), np.tile(np.arange(6), 3)),
                "stiffness": ROT, "damping": ROT}

    def mass(self, t, q, M):
        M[...] = np.concatenate([MASS * np.ones(3), JC])

    def jacobian(self, t, q, J):
        D = np.zeros((3, 6))
        Top.jacobian(self, t, q, D)
        J[...] = D.ravel()

    def solver(self, formulation, **options):
        return Top.solver(self, formulation, patterns=self.PATTERNS,
                          linear_solver=galpha.GA_LINEAR_SPARSE, **options)


@pytest.mark.parametrize("formulation", [galpha.GA_INDEX3, galpha.GA_INDEX2_STABILIZED])
def test_the_sparse_path_is_the_dense_one(formulation):
    qa, va = run(SparseTop(False), formulation, 1e-3, 0.2)
    qb, vb = run(Top(False), formulation, 1e-3, 0.2)
    assert np.abs(qa - qb).max() < 1e-12
    assert np.abs(va - vb).max() < 1e-12 * 150
