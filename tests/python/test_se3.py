"""galpha.se3, the vectorized pose maps, against scipy's matrix exponential of the twist's 4 x 4
matrix [w~ u; 0 0]: the exponential, the logarithm as its inverse, the composition as the
matrices' product, the tangent operator as the derivative of exp; and a free body on an "se3"
block of Solver(space=...), whose screw motion the method follows exactly."""
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402
from galpha import se3, so3  # noqa: E402

scipy_linalg = pytest.importorskip("scipy.linalg")

RNG = np.random.default_rng(11)
XI = RNG.normal(size=(3, 4, 6))  # a (3, 4) batch of twists
XI[..., 3:] /= np.maximum(1.0, np.linalg.norm(XI[..., 3:], axis=-1, keepdims=True) / 2.5)


def hat(xi):
    u, w = xi[:3], xi[3:]
    return np.array([[0.0, -w[2], w[1], u[0]], [w[2], 0.0, -w[0], u[1]],
                     [-w[1], w[0], 0.0, u[2]], [0.0, 0.0, 0.0, 0.0]])


def homogeneous(p):
    H = np.eye(4)
    H[:3, :3], H[:3, 3] = so3.matrix(p[3:]), p[:3]
    return H


def test_exp_is_the_matrix_exponential_and_log_inverts_it():
    p = se3.exp(XI)
    assert p.shape == (3, 4, 7)
    for xi, pose in zip(XI.reshape(-1, 6), p.reshape(-1, 7)):
        assert np.max(np.abs(homogeneous(pose) - scipy_linalg.expm(hat(xi)))) < 1e-13
    assert np.max(np.abs(se3.log(p) - XI)) < 1e-12


def test_compose_is_the_matrices_product_and_broadcasts():
    a, b = se3.exp(XI[0]), se3.exp(XI[1])
    ab = se3.compose(a, b)
    for x, y, z in zip(a, b, ab):
        assert np.max(np.abs(homogeneous(z) - homogeneous(x) @ homogeneous(y))) < 1e-14
    one = se3.compose(a, b[0])
    assert np.max(np.abs(one - se3.compose(a, np.broadcast_to(b[0], a.shape)))) == 0.0


def test_tangent_is_the_derivative_of_exp_and_its_inverse_inverts_it():
    e = 1e-5
    T = se3.tangent(XI)
    assert T.shape == (3, 4, 6, 6)
    for xi, Tk in zip(XI.reshape(-1, 6), T.reshape(-1, 6, 6)):
        Hinv = np.linalg.inv(scipy_linalg.expm(hat(xi)))
        for j in range(6):
            d = np.zeros(6)
            d[j] = e
            D = (scipy_linalg.expm(hat(xi + d)) - scipy_linalg.expm(hat(xi - d))) / (2 * e)
            assert np.max(np.abs(Hinv @ D - hat(Tk[:, j]))) < 1e-8
    assert np.max(np.abs(T @ se3.tangent_inverse(XI) - np.eye(6))) < 1e-13


def test_refusals_raise_argument_errors():
    with pytest.raises(galpha.ArgumentError, match="se3.exp"):
        se3.exp(np.array([0.0, 0.0, 0.0, 0.0, np.nan, 0.0]))
    with pytest.raises(galpha.ArgumentError, match="unit norm"):
        se3.log(np.array([0.0, 0.0, 0.0, 1.1, 0.0, 0.0, 0.0]))
    with pytest.raises(galpha.ArgumentError):
        se3.tangent_inverse(np.array([0.0, 0.0, 0.0, 0.0, 2 * np.pi, 0.0]))
    with pytest.raises(galpha.ArgumentError, match="6 entries"):
        se3.exp(np.zeros(3))


def test_a_free_body_on_se3_follows_its_screw_exactly():
    # m = 2, J = diag(1, 2, 3), twist (u, w) with u along w about a principal axis: the body
    # equations M xi' = ad_xi^T M xi give xi' = 0, so q(t) = q0 o exp(t xi) exactly (a = 0)
    m, J = 2.0, np.array([1.0, 2.0, 3.0])
    xi = np.array([0.0, 0.0, 0.7, 0.0, 0.0, 2.0])

    def mass(t, q, M):
        M[...] = np.diag(np.concatenate([m * np.ones(3), J]))

    def force(t, q, v, f):  # ad_xi^T M xi = (-w x m u, -u x m u - w x J w)
        u, w = v[:3], v[3:]
        f[:3] = -np.cross(w, m * u)
        f[3:] = -np.cross(w, J * w)

    q0 = np.array([1.0, -1.0, 0.5, *so3.exp(np.array([0.3, -0.2, 0.1]))])
    with galpha.Solver(6, 0, mass, force, space=[("se3", 1)]) as s:
        s.init(0.0, q0, xi)
        for _ in range(50):
            s.step(0.01)
        want = se3.compose(q0, se3.exp(s.t * xi))
        assert np.max(np.abs(s.q - want)) < 1e-13
        assert np.max(np.abs(s.v - xi)) < 1e-13
