"""SO(3) as unit quaternions: the maps of galpha's C API (ga_so3_*), vectorized.

Conventions (those of the solver): a quaternion is (w, x, y, z), w the scalar part;
R(q) x = q x q^-1 maps body to space; increments are right (body-frame), q o exp(psi); the
tangent operator T(psi) is the right-trivialized derivative of exp::

    exp(psi + d) = exp(psi) o exp(T(psi) d + O(|d|^2))

Every function takes arrays whose last axis is the item (3 for a rotation vector, 4 for a
quaternion) and maps all items in one call: psi of shape (..., 3) gives q of shape (..., 4);
matrices come as (..., 3, 3). Invalid input raises galpha.ArgumentError (a value not finite, a
quaternion whose norm is not 1 within 1e-6, ``|psi| >= 2 pi`` for tangent_inverse).

    import numpy as np, galpha.so3 as so3
    q = so3.exp(np.array([[0.0, 0.0, np.pi / 2]]))   # a quarter turn about z
    so3.matrix(q) @ [1.0, 0.0, 0.0]                  # -> [[0, 1, 0]]
"""
from __future__ import annotations

import numpy as np

from . import _ffi
from .solver import ArrayLike
from .errors import error_for


def _items(x, width, name):
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.ndim == 0 or a.shape[-1] != width:
        raise error_for(_ffi.GA_ERR_ARG, "%s: the last axis must have %d entries, got shape %s"
                        % (name, width, a.shape))
    return a


_REFUSED = "a value not finite, a quaternion not of unit norm within 1e-6, or |psi| >= 2 pi " \
    "for tangent_inverse"


def _call(fn, name, inputs, out_shape, refused=_REFUSED):
    count = inputs[0].size // inputs[0].shape[-1]
    out = np.empty(inputs[0].shape[:-1] + out_shape)
    ptrs = [a.ctypes.data_as(_ffi.c_double_p) for a in inputs]
    status = fn(count, *ptrs, out.ctypes.data_as(_ffi.c_double_p))
    if status != _ffi.GA_OK:
        raise error_for(status, "%s: %s (%s)" % (name, _ffi.ga_strerror(status).decode(), refused))
    return out


def exp(psi: ArrayLike) -> np.ndarray:
    """q = exp(psi) = (cos(t/2), sin(t/2) psi / t), ``t = |psi|``: (..., 3) -> (..., 4)."""
    return _call(_ffi.ga_so3_exp, "so3.exp", [_items(psi, 3, "psi")], (4,))


def log(q: ArrayLike) -> np.ndarray:
    """The rotation vector psi with exp(psi) = +-q, ``|psi| <= pi``: (..., 4) -> (..., 3)."""
    return _call(_ffi.ga_so3_log, "so3.log", [_items(q, 4, "q")], (3,))


def compose(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """a o b, the quaternion product (first b, then a): (..., 4) x (..., 4) -> (..., 4)."""
    a, b = _items(a, 4, "a"), _items(b, 4, "b")
    a, b = (np.ascontiguousarray(x) for x in np.broadcast_arrays(a, b))
    return _call(_ffi.ga_so3_compose, "so3.compose", [a, b], (4,))


def _matrices(fn, name, x, width, size=3, refused=_REFUSED):
    # the C API writes each matrix column-major; numpy's (..., k, k) is row-major: transpose
    out = _call(fn, name, [_items(x, width, name)], (size * size,), refused)
    return np.swapaxes(out.reshape(out.shape[:-1] + (size, size)), -1, -2)


def matrix(q: ArrayLike) -> np.ndarray:
    """R(q), the rotation matrix: (..., 4) -> (..., 3, 3)."""
    return _matrices(_ffi.ga_so3_matrix, "so3.matrix", q, 4)


def tangent(psi: ArrayLike) -> np.ndarray:
    """T(psi): (..., 3) -> (..., 3, 3)."""
    return _matrices(_ffi.ga_so3_tangent, "so3.tangent", psi, 3)


def tangent_inverse(psi: ArrayLike) -> np.ndarray:
    """T(psi)^-1 (``|psi| < 2 pi``): (..., 3) -> (..., 3, 3)."""
    return _matrices(_ffi.ga_so3_tangent_inverse, "so3.tangent_inverse", psi, 3)
