"""galpha.so3, the vectorized rotation maps, against formulas written out here with numpy:
the exponential's closed form, Rodrigues' matrix, the logarithm as the exponential's inverse,
the product as the matrices' product, the tangent operator's closed form and the inverse."""
import os
import sys

import numpy as np
import pytest

if "GALPHA_PYTHON_INSTALLED" not in os.environ:
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bindings", "python"))
import galpha  # noqa: E402
from galpha import so3  # noqa: E402

RNG = np.random.default_rng(7)
PSI = RNG.normal(size=(5, 4, 3))  # a (5, 4) batch of rotation vectors, |psi| up to about 4
PSI /= np.maximum(1.0, np.linalg.norm(PSI, axis=-1, keepdims=True) / 3.0)  # |psi| <= 3


def skew(v):
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    o = np.zeros_like(x)
    return np.stack([np.stack([o, -z, y], -1), np.stack([z, o, -x], -1),
                     np.stack([-y, x, o], -1)], -2)


def test_exp_is_the_closed_form_over_a_batch():
    q = so3.exp(PSI)
    assert q.shape == (5, 4, 4)
    t = np.linalg.norm(PSI, axis=-1, keepdims=True)
    want = np.concatenate([np.cos(t / 2), np.sin(t / 2) / t * PSI], axis=-1)
    assert np.max(np.abs(q - want)) < 1e-15


def test_matrix_is_rodrigues_and_log_inverts_exp():
    q = so3.exp(PSI)
    t = np.linalg.norm(PSI, axis=-1)[..., None, None]
    K = skew(PSI) / t
    want = np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * (K @ K)
    assert np.max(np.abs(so3.matrix(q) - want)) < 1e-14
    assert np.max(np.abs(so3.log(q) - PSI)) < 1e-14


def test_compose_is_the_product_of_rotations_and_broadcasts():
    a, b = so3.exp(PSI[0]), so3.exp(PSI[1])
    ab = so3.compose(a, b)
    assert np.max(np.abs(so3.matrix(ab) - so3.matrix(a) @ so3.matrix(b))) < 1e-14
    one = so3.compose(a, b[0])  # b[0] against every a
    assert np.max(np.abs(so3.matrix(one) - so3.matrix(a) @ so3.matrix(b[0]))) < 1e-14


def test_tangent_closed_form_and_inverse():
    T = so3.tangent(PSI)
    t = np.linalg.norm(PSI, axis=-1)[..., None, None]
    S = skew(PSI)
    want = np.eye(3) + (np.cos(t) - 1) / t**2 * S + (t - np.sin(t)) / t**3 * (S @ S)
    assert np.max(np.abs(T - want)) < 1e-14
    assert np.max(np.abs(T @ so3.tangent_inverse(PSI) - np.eye(3))) < 1e-13


def test_refusals_raise_argument_errors():
    with pytest.raises(galpha.ArgumentError):
        so3.exp(np.array([0.0, np.nan, 0.0]))
    with pytest.raises(galpha.ArgumentError):
        so3.log(np.array([1.1, 0.0, 0.0, 0.0]))
    with pytest.raises(galpha.ArgumentError):
        so3.tangent_inverse(np.array([0.0, 2 * np.pi, 0.0]))
    with pytest.raises(galpha.ArgumentError):
        so3.exp(np.zeros(4))  # not a rotation vector
