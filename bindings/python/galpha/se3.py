"""SE(3) as poses (x, q): the maps of galpha's C API (ga_se3_*), vectorized.

Conventions (those of the solver's "se3" blocks): a pose is 7 numbers, the position x of the
body's origin in space, then the unit quaternion q (w, x, y, z) of its rotation R; a twist
xi = (u, w) is 6 numbers, the body-frame translation u, then the rotation w. Increments are
right: (x, R) o exp(u, w) = (x + R V(w) u, R exp(w)), V(w) = so3.tangent(w)^T; compose is
(xa, Ra) o (xb, Rb) = (xa + Ra xb, Ra Rb); the tangent operator T(xi) is the right-trivialized
derivative of exp::

    exp(xi + d) = exp(xi) o exp(T(xi) d + O(|d|^2))

Arrays as in galpha.so3: the last axis is the item (6 for a twist, 7 for a pose), matrices
come as (..., 6, 6). Invalid input raises galpha.ArgumentError (a value not finite, a pose's
quaternion whose norm is not 1 within 1e-6, ``|w| >= 2 pi`` for tangent_inverse).

    import numpy as np, galpha.se3 as se3
    p = se3.exp([1.0, 0.0, 0.0, 0.0, 0.0, np.pi / 2])   # a screw: x (2/pi, 2/pi, 0), 90 deg
"""
from __future__ import annotations

import numpy as np

from . import _ffi
from .solver import ArrayLike
from .so3 import _call, _items, _matrices

_REFUSED = "a value not finite, a pose's quaternion not of unit norm within 1e-6, or " \
    "|w| >= 2 pi for tangent_inverse"


def exp(xi: ArrayLike) -> np.ndarray:
    """The pose exp(u, w) = (V(w) u, exp(w)): (..., 6) -> (..., 7)."""
    return _call(_ffi.ga_se3_exp, "se3.exp", [_items(xi, 6, "xi")], (7,), _REFUSED)


def log(p: ArrayLike) -> np.ndarray:
    """The twist xi with exp(xi) = p, ``|w| <= pi``: (..., 7) -> (..., 6)."""
    return _call(_ffi.ga_se3_log, "se3.log", [_items(p, 7, "p")], (6,), _REFUSED)


def compose(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """a o b = (xa + Ra xb, qa o qb): (..., 7) x (..., 7) -> (..., 7)."""
    a, b = _items(a, 7, "a"), _items(b, 7, "b")
    a, b = (np.ascontiguousarray(x) for x in np.broadcast_arrays(a, b))
    return _call(_ffi.ga_se3_compose, "se3.compose", [a, b], (7,), _REFUSED)


def tangent(xi: ArrayLike) -> np.ndarray:
    """T(xi) = [T(w), C(u, w); 0, T(w)]: (..., 6) -> (..., 6, 6)."""
    return _matrices(_ffi.ga_se3_tangent, "se3.tangent", xi, 6, 6, _REFUSED)


def tangent_inverse(xi: ArrayLike) -> np.ndarray:
    """T(xi)^-1 (``|w| < 2 pi``): (..., 6) -> (..., 6, 6)."""
    return _matrices(_ffi.ga_se3_tangent_inverse, "se3.tangent_inverse", xi, 6, 6, _REFUSED)
