"""The Pythonic layer: a Solver object over one ga_solver, callbacks as Python functions on
numpy arrays.

Callbacks fill their output array in place and return None (or 0) on success, a positive int
for a recoverable failure (the step is rejected) or a negative int for a fatal one. Their
array arguments are their own: inputs are read-only copies, the output starts zeroed and is
copied into the library's buffer when the callback returns successfully. Whatever a callback
keeps of them stays valid and unchanged, also after close() (Solver(zero_copy=True) trades
this for speed: views of the library's buffers, valid during the call only). Matrices are seen in their natural shape (M: n x n, Phi_q: m x n), column-major
(Fortran order) as in the C API.

A Python exception raised inside a callback makes the step fail cleanly (the solver stays at
its last accepted state) and is re-raised, with its traceback, from the call that stepped.
"""
from __future__ import annotations

import collections
import ctypes
import functools
import signal
import threading
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np

try:  # numpy >= 1.20
    from numpy.typing import ArrayLike
except ImportError:  # pragma: no cover
    ArrayLike = Any  # type: ignore

from . import _ffi
from ._callbacks import adapt
from .errors import CallbackRetry, StateError, error_for

_vp = ctypes.c_void_p
_i = ctypes.c_int
_d = ctypes.c_double
# Trampoline types: pointers arrive as plain addresses (cheaper than POINTER objects).
_MASS = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp)
_FORCE = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp)
_CONSTRAINT = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp)
_STIFFNESS = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp, _vp, _vp)
_EVENT = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp, _vp)
_COUPLING = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp)
_EVENT_Y = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp, _vp, _vp)
_FORCE_P = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _i, _vp, _vp)
_MASS_P = ctypes.CFUNCTYPE(_i, _d, _vp, _i, _vp, _vp, _vp)
_CONSTRAINT_P = ctypes.CFUNCTYPE(_i, _d, _vp, _i, _vp, _vp, _vp, _vp)
_COST = ctypes.CFUNCTYPE(_i, _d, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp, _vp)
_HOOK = ctypes.CFUNCTYPE(_i, _vp, _d, _vp, _vp, _vp, _vp)

# The derivatives of the accepted step in the sensitivity parameters (Solver.sensitivity).
Sensitivity = collections.namedtuple("Sensitivity", "dq dv dqdd dlam dy dydot")
# An equilibrium (ga_static_equilibrium): q, the multipliers lam
Equilibrium = collections.namedtuple("Equilibrium", "q lam")
# The small motions at rest in minimal coordinates q = q0 + N z (ga_linearize):
# M z'' + C z' + K z = 0
Linearization = collections.namedtuple("Linearization", "N M C K")
# Undamped modes (ga_modes): omega2 ascending, shapes (n x count) in q with unit modal mass;
# omega = sqrt(omega2) where omega2 >= 0 (NaN for an unstable direction)
Modes = collections.namedtuple("Modes", "omega2 omega shapes")
# Damped modes (ga_modes_damped): the eigenvalues s (complex, by |s|; Re s > 0 unstable) and
# the displacement shapes (complex, n x count, largest entry 1)
DampedModes = collections.namedtuple("DampedModes", "s shapes")
# A static path (ga_static_path): the load factors (k), q (k x n) and lam (k x m) of its points
# after the start, and the status that ended it ("done", "stopped")
StaticPath = collections.namedtuple("StaticPath", "load q lam ended")
# With first-order states (ga_static_equilibrium_y): q, the states y and lam at rest
EquilibriumY = collections.namedtuple("EquilibriumY", "q y lam")
# The first-order form x' = A x of the small motions at rest, x = (z, z', y) (ga_state_space)
StateSpace = collections.namedtuple("StateSpace", "N A")


Sensitivity.__doc__ = """Solver.sensitivity(): derivatives of the accepted step's q, v, qdd,
lam, y and ydot with respect to the parameters, one column per parameter."""
Equilibrium.__doc__ = """Solver.static_equilibrium(): the rest q and its multipliers lam."""
EquilibriumY.__doc__ = """Solver.static_equilibrium_y(): the rest q, first-order states y and
multipliers lam."""
Linearization.__doc__ = """Solver.linearize(): the small motions at rest in minimal coordinates
q = q0 + N z, M z'' + C z' + K z = 0."""
Modes.__doc__ = """Solver.modes() and modes_near(): omega2 ascending, omega (NaN where
omega2 < 0: an unstable direction), shapes (n x count) with unit modal mass."""
DampedModes.__doc__ = """Solver.damped_modes(): eigenvalues s (complex; Re s > 0 unstable)
and complex displacement shapes (n x count, largest entry 1)."""
StaticPath.__doc__ = """Solver.static_path(): load factors, q and lam of the points after the
start, and how the path ended ("done" or "stopped")."""
StateSpace.__doc__ = """Solver.state_space() and state_space_motion(): x' = A x in
x = (z, z', y), with q = q0 + N z."""


def _cast(fn, ctype):
    return ctypes.cast(fn, ctype) if fn is not None else ctype()


def native_address(fn: Any) -> Optional[int]:
    """The C address of a compiled callback -- a numba cfunc, a ctypes function pointer or an
    int address -- or None for a Python callable (or None)."""
    if fn is None or isinstance(fn, bool):
        return None
    if isinstance(fn, int):
        if fn <= 0:
            raise ValueError("a callback address must be a positive int, got %d" % fn)
        return fn
    if isinstance(fn, ctypes._CFuncPtr):
        address = ctypes.cast(fn, ctypes.c_void_p).value
        if not address:
            raise ValueError("a NULL ctypes function pointer is not a callback")
        return address
    address = getattr(fn, "address", None)  # numba.cfunc (CFunc: address, ctypes, native_name)
    if isinstance(address, int) and hasattr(fn, "native_name"):
        return address
    return None


def _kind(ctype):
    """'i', 'd' or 'p' (any pointer) of a ctypes type, else its name."""
    if ctype is _i:
        return "i"
    if ctype is _d:
        return "d"
    if ctype is _vp or (isinstance(ctype, type) and issubclass(ctype, ctypes._Pointer)):
        return "p"
    return getattr(ctype, "__name__", repr(ctype))


def _c_signature(kinds):
    names = {"i": "int", "d": "double", "p": "pointer"}
    return "%s(%s)" % (names.get(kinds[0], kinds[0]),
                       ", ".join(names.get(k, k) for k in kinds[1:]))


def check_compiled_signature(fn: Any, ctype: Any, what: str = "callback") -> None:
    """A numba cfunc carries its signature: one that is not the C callback's is refused by
    name (it was accepted and failed far from here, e.g. as a singular matrix)."""
    proto = getattr(fn, "ctypes", None)
    if not hasattr(fn, "native_name") or proto is None:
        return  # an address or a ctypes pointer: nothing to compare with
    got = [_kind(getattr(proto, "restype", None))] + [_kind(a) for a in
                                                      (getattr(proto, "argtypes", None) or ())]
    want = [_kind(ctype._restype_)] + [_kind(a) for a in ctype._argtypes_]
    if got != want:
        raise TypeError("the compiled %s has the signature %s (numba: %s); galpha calls it as "
                        "%s (see the header's ga_*_fn)" % (what, _c_signature(got),
                                                           getattr(fn, "_sig", "?"),
                                                           _c_signature(want)))


def user_pointer(user: Any) -> Tuple[Optional[int], Any]:
    """(address, what keeps it alive) of the `user` argument passed to compiled callbacks: None
    (NULL), an int address, a numpy array (its data), or a ctypes object (its address)."""
    if user is None:
        return None, None
    if isinstance(user, bool):
        raise TypeError("user must be None, an int address, a numpy array or a ctypes object")
    if isinstance(user, int):
        return user, None
    if isinstance(user, np.ndarray):
        if not user.flags.c_contiguous:
            raise ValueError("user: a numpy array passed to C must be contiguous")
        return user.ctypes.data, user
    if isinstance(user, ctypes._SimpleCData) or isinstance(user, (ctypes.Structure,
                                                                   ctypes.Array)):
        return ctypes.addressof(user), user
    raise TypeError("user must be None, an int address, a numpy array or a ctypes object, "
                    "not %s" % type(user).__name__)


_PATTERN_MATRICES = {"mass": _ffi.GA_MATRIX_MASS, "jacobian": _ffi.GA_MATRIX_JACOBIAN,
                     "stiffness": _ffi.GA_MATRIX_STIFFNESS, "damping": _ffi.GA_MATRIX_DAMPING}



_MAIN_THREAD = threading.main_thread().ident
_sigint_handler_tried = False
_running = None  # the solver whose call into C runs in the main thread now


def _on_sigint(signum, frame):
    """galpha's SIGINT handler: during a call into C it only flags the solver (see
    _InterruptsDeferred); otherwise it is Python's own (KeyboardInterrupt)."""
    if _running is not None:
        _running._interrupted = True
    else:
        signal.default_int_handler(signum, frame)


class _InterruptsDeferred:
    """Ctrl-C during a call into C: a KeyboardInterrupt raised inside a ctypes callback, before
    its try, was swallowed, and the library read an undefined return value (29-39 % of
    interrupts were lost). In the main thread, while such a call runs, SIGINT only sets a flag:
    the next callback returns a fatal failure (the step fails and leaves the state as it was),
    and KeyboardInterrupt is raised when the call returns. The handler is installed once, at
    the first call, if SIGINT still has Python's default handler then (swapping it at every
    call cost more than a pendulum step with Python callbacks); a handler of the program's
    own is left alone."""

    def __init__(self, solver):
        self.solver = solver
        self.main = False
        self.outer = None

    def __enter__(self):
        global _running, _sigint_handler_tried
        self.main = threading.get_ident() == _MAIN_THREAD
        if self.main:
            if not _sigint_handler_tried:
                _sigint_handler_tried = True
                if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                    signal.signal(signal.SIGINT, _on_sigint)
            self.outer = _running
            _running = self.solver
        return self

    def __exit__(self, *exc):
        global _running
        if self.main:
            _running = self.outer
            if self.solver._interrupted:
                self.solver._interrupted = False
                raise KeyboardInterrupt
        return False


def _runs_callbacks(method):
    """Runs a method that may call the model's callbacks with Ctrl-C deferred (see above)."""
    @functools.wraps(method)
    def deferred(self, *args, **kwargs):
        with _InterruptsDeferred(self):
            return method(self, *args, **kwargs)
    return deferred


def _serialized(method):
    """Runs a method with the solver's lock held: calls from several threads are serialized
    (close() no longer frees the C solver under a step running in another thread)."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        with self._lock:
            return method(self, *args, **kwargs)
    return locked


_SPACE_KINDS = {"vector": _ffi.GA_SPACE_VECTOR, "so3": _ffi.GA_SPACE_SO3_QUATERNION,
                "so3_matrix": _ffi.GA_SPACE_SO3_MATRIX, "se3": _ffi.GA_SPACE_SE3}
_SPACE_SIZES = {"vector": (1, 1), "so3": (4, 3), "so3_matrix": (9, 3),
                "se3": (7, 6)}  # (nq, nv) per count


def _space_blocks(space):
    """(kinds, counts, nq, nv) of Solver's space=[(kind, count), ...]."""
    kinds, counts, nq, nv = [], [], 0, 0
    for block in space:
        try:
            kind, count = block
        except (TypeError, ValueError):
            raise ValueError(f"space: each block is a (kind, count) pair, not {block!r}")
        if kind not in _SPACE_KINDS:
            raise ValueError(f"space: unknown kind {kind!r} (one of {', '.join(_SPACE_KINDS)})")
        count = int(count)
        if count < 1:
            raise ValueError(f"space: block {block!r} needs a count >= 1")
        kinds.append(_SPACE_KINDS[kind])
        counts.append(count)
        nq += count * _SPACE_SIZES[kind][0]
        nv += count * _SPACE_SIZES[kind][1]
    if not kinds:
        raise ValueError("space: at least one block")
    return kinds, counts, nq, nv


class Solver:
    """A galpha solver for n coordinates and m constraints.

    Parameters
    ----------
    n, m : int
        Sizes, fixed for the life of the solver.
    mass(t, q, M), force(t, q, v, f), constraint(t, q, phi), jacobian(t, q, J) : callables
        The model. `force` may be None (no applied forces); `constraint` and `jacobian` are
        required when m > 0.
    stiffness(t, q, v, qdd, lam, K), damping(t, q, v, C), constraint_accel(t, q, v, out),
    constraint_dt(t, q, out)
        Optional exact tangents, constraint acceleration term and Phi_t (finite differences
        otherwise).
    patterns : dict, optional
        Sparsity patterns for the sparse path (ga_set_pattern): {"mass" | "jacobian" |
        "stiffness" | "damping": (rows, cols)}, 0-based index arrays of equal length nnz. The
        callback of a matrix with a pattern receives a 1-D array of its nnz values in that
        order instead of the dense matrix; an empty pattern declares the matrix zero. A
        pattern may also be given in compressed-column form (ga_set_pattern_csc): any object
        with `indptr` and `indices` (a scipy.sparse csc_matrix, say; n + 1 column pointers),
        whose values then come column by column, as the `data` of such a matrix.
    rho_inf, params, newton, tangent_mode, scaling, predictor, init_mode, formulation, redundant,
    tolerances, reuse, constant_mass, linear_solver, rescale, corrected_start, step_limits,
    initial_step, output, resolution_check
        Options, as the C setters (ga_set_rho_inf, ga_set_params((alpha_m, alpha_f, beta,
        gamma)), ga_set_newton((tol, max_iter)), ga_set_tolerances((rtol, atol)),
        ga_set_step_limits((h_min, h_max)), ga_set_formulation(galpha.GA_INDEX2_STABILIZED),
        ...).
    r, rate(t, q, v, y, ydot), force_y(t, q, v, y, f), coupling(t, q, v, y, g_q, g_v, g_y, f_y),
    coupling_exact, coupling_patterns
        First-order states y' = g(t, q, v, y) (ga_set_first_order): r of them, `rate` fills
        ydot (length r); `force_y`, if given, replaces `force` so that the applied forces see
        y. `coupling` optionally fills the blocks dg/dq, dg/dv (r x n), dg/dy (r x r), df/dy
        (n x r) (finite differences otherwise); coupling_exact=False leaves g_q, g_v, f_y out
        of the iteration matrix (a measurement aid); coupling_patterns={"g_q" | "g_v": (rows,
        cols)} declares where those blocks may be nonzero (0-based; empty: zero), so that their
        finite differences take one rate call per group of columns (ga_set_coupling_pattern).
        Start with init(t0, q0, v0, y0); read `y`, `ydot` and interpolate_y(t).
    parameters, depends, parameter_scale, force_p(t, q, v, j, f_p), mass_p(t, q, j, a, out),
    constraint_p(t, q, j, phi_p, Phi_q_p, Phi_t_p)
        Forward sensitivities (ga_set_sensitivity): `parameters` is the 1-D float64 array the
        callbacks read the model's parameters from at every call -- galpha perturbs its entries
        in place for differences (restoring them before any call returns), so the callbacks
        must read it, not a copy. `depends` is a subset of ("force", "mass", "rate",
        "constraint") (default ("force",)): what the parameters enter (rate: the first-order
        states' g; constraint: Phi, and so Phi_q and Phi_t). `force_p` and `mass_p`
        optionally give df/dp_j and (dM/dp_j) a exactly, `constraint_p` dPhi/dp_j, dPhi_q/dp_j
        (shaped as the jacobian's J) and, unless Phi_t_p is None, dPhi_t/dp_j (central
        differences otherwise). Read the derivatives of the accepted step with sensitivity().
    sensitivity_method, max_steps
        A subset of ("forward", "adjoint") (ga_set_sensitivity_method; default ("forward",)):
        with "adjoint" the run from init() on is recorded, up to max_steps steps, for
        adjoint_gradient().
    adjoint_checkpoints : (interval, count)
        Checkpointing for records that do not fit (ga_set_adjoint_checkpoints): one segment
        of `interval` steps kept, a checkpoint after every interval-th step, runs of up to
        interval times count steps; adjoint_gradient() computes earlier segments again.
    space : sequence of (kind, count), optional
        A configuration space that is a product of blocks (ga_create_space): kind "vector"
        (count coordinates), "so3" (count rotations stored as unit quaternions (w, x, y, z)),
        "so3_matrix" (count rotation matrices, 9 numbers column-major each) or "se3" (count
        poses, each the position then the unit quaternion, 7 numbers). Rotations and poses
        move on the group with body-frame velocities: q has nq numbers (4, 9 or 7 per
        block item), v and everything shaped like it n (3 per rotation, 6 per pose: the
        twist (u, w)), and n must be that number. Phi_q and K_t are derivatives along right
        increments (galpha.so3 and galpha.se3 build them). Index 3 and 2, fixed and
        adaptive steps, dense output, events, checkpoints, first-order states, forward and
        adjoint sensitivities; on the sparse path (pattern=) index 3 and 2 without
        sensitivities.
    user : None, int, numpy array or ctypes object
        The `user` pointer compiled callbacks receive (``void *user``: an address, a numpy
        array's data, a ctypes object's address); NULL by default. Python callbacks ignore it.
    zero_copy : bool
        False (default): callbacks get copies of their inputs and an array of their own to
        fill, so what they keep stays valid and unchanged after the call. True: views of the
        library's buffers instead, faster (see docs/performance.md), valid only during the
        call (inputs read-only; nothing may be kept, written or read after the call returns).

    Every callback may instead be compiled: a numba cfunc (`numba.cfunc(sig)(fn)`), a ctypes
    function pointer or an int address, with the C signature of the header's ``ga_*_fn``; it is
    called directly from C, without Python (examples/python/numba_pendulum.py). Arrays arrive
    as raw pointers: column-major, dense or pattern values as with Python callbacks.

    Use as a context manager, or call close(); the handle is also freed by the garbage
    collector.
    """

    def __init__(self, n: int, m: int, mass: Any, force: Any = None, constraint: Any = None,
                 jacobian: Any = None, *,
                 stiffness=None, damping=None, constraint_accel=None, constraint_dt=None,
                 rho_inf=None,
                 params=None, newton=None, tangent_mode=None, scaling=None, predictor=None,
                 init_mode=None, formulation=None, redundant=None, tolerances=None, reuse=None,
                 constant_mass=None, linear_solver=None, rescale=None, corrected_start=None,
                 step_limits=None, initial_step=None, output=None, resolution_check=None,
                 patterns=None,
                 r=0, rate=None, force_y=None, coupling=None, coupling_exact=None,
                 coupling_patterns=None, parameters=None, depends=("force",),
                 parameter_scale=None, force_p=None, mass_p=None, constraint_p=None,
                 sensitivity_method=("forward",), max_steps=None, adjoint_checkpoints=None,
                 zero_copy=False, user=None, space=None, args: Sequence[Any] = ()) -> None:
        self._ptr = None
        self._lock = threading.RLock()  # see _serialized
        self._pending = None          # exception raised inside a callback
        self._interrupted = False     # SIGINT during a call into C (_InterruptsDeferred)
        self._in_callback = 0         # callbacks of this solver running now
        self._views = {}              # (address, shape, writeable) -> ndarray
        self._compiled = []           # compiled callbacks (and the user data) kept alive
        self._user_address, keep = user_pointer(user)
        self._compiled.append(keep)
        self._hook = None
        self.n, self.m = int(n), int(m)
        if self.n < 1 or self.m < 0 or self.m > self.n:  # (ga_create has no solver to say why)
            raise error_for(_ffi.GA_ERR_ARG,
                            f"Solver(n={self.n}, m={self.m}): needs n >= 1 coordinates and "
                            "0 <= m <= n constraints")
        handle = ctypes.c_void_p()
        self._euclidean = space is None
        if space is None:
            self.nq = self.n
            self._check(_ffi.ga_create(self.n, self.m, ctypes.byref(handle)))
        else:
            kinds, counts, self.nq, nv = _space_blocks(space)
            self._euclidean = all(kind == _SPACE_KINDS["vector"] for kind in kinds)
            if nv != self.n:
                raise error_for(_ffi.GA_ERR_ARG,
                                f"Solver(n={self.n}, space={space!r}): the blocks have "
                                f"{nv} velocity coordinates, n must be that")
            _i = ctypes.c_int * len(kinds)
            self._check(_ffi.ga_create_space(len(kinds), _i(*kinds), _i(*counts), self.m,
                                             ctypes.byref(handle)))
        self._ptr = handle
        self._lib = _ffi.lib          # keeps the library alive for __del__ at shutdown
        self._free = _ffi.ga_free
        n, m, nq = self.n, self.m, self.nq
        v = self._view
        # declared patterns first: they decide the shape the callbacks see
        nnz = {}
        for name, pattern in (patterns or {}).items():
            if name not in _PATTERN_MATRICES:
                raise ValueError(f"unknown matrix {name!r} in patterns (one of "
                                 f"{', '.join(_PATTERN_MATRICES)})")
            if hasattr(pattern, "indptr") and hasattr(pattern, "indices"):
                if getattr(pattern, "format", "csc") != "csc":
                    raise ValueError(f"pattern of {name}: format {pattern.format!r}, not csc")
                indptr = np.ascontiguousarray(pattern.indptr, dtype=np.intc).ravel()
                indices = np.ascontiguousarray(pattern.indices, dtype=np.intc).ravel()
                if indptr.size != n + 1:
                    raise ValueError(f"pattern of {name}: {indptr.size} column pointers, "
                                     f"not n + 1 = {n + 1}")
                if indices.size < (indptr[-1] if indptr[-1] > 0 else 0):
                    raise ValueError(f"pattern of {name}: {indices.size} row indices, but "
                                     f"the column pointers end at {indptr[-1]}")
                ip = ctypes.POINTER(ctypes.c_int)
                self._check(_ffi.ga_set_pattern_csc(self._ptr, _PATTERN_MATRICES[name],
                                                    indptr.ctypes.data_as(ip),
                                                    indices.ctypes.data_as(ip)))
                nnz[name] = int(indptr[-1])
                continue
            rows, cols = pattern
            rows = np.ascontiguousarray(rows, dtype=np.intc).ravel()
            cols = np.ascontiguousarray(cols, dtype=np.intc).ravel()
            if rows.size != cols.size:
                raise ValueError(f"pattern of {name}: {rows.size} rows but {cols.size} cols")
            ip = ctypes.POINTER(ctypes.c_int)
            self._check(_ffi.ga_set_pattern(self._ptr, _PATTERN_MATRICES[name], rows.size,
                                            rows.ctypes.data_as(ip), cols.ctypes.data_as(ip)))
            nnz[name] = rows.size

        def shape(name, dense):
            return (nnz[name],) if name in nnz else dense
        # Python callbacks that return their output, or take `args`, become ones that fill it
        # (decided here, once; _callbacks.py)
        if not isinstance(args, (tuple, list)):
            raise TypeError("args must be a tuple of the callbacks' extra arguments, e.g. "
                            "args=(%r,) for one; got %s" % (args, type(args).__name__))
        self._args = args = tuple(args)

        def adapted(fn, name, inputs, outputs):
            if fn is None or native_address(fn) is not None:
                return fn
            return adapt(fn, name, inputs, outputs, args)
        mass = adapted(mass, "mass", ["t", "q"], ["M"])
        force = adapted(force, "force", ["t", "q", "v"], ["f"])
        constraint = adapted(constraint, "constraint", ["t", "q"], ["phi"])
        jacobian = adapted(jacobian, "jacobian", ["t", "q"], ["J"])
        stiffness = adapted(stiffness, "stiffness", ["t", "q", "v", "qdd", "lam"], ["K"])
        damping = adapted(damping, "damping", ["t", "q", "v"], ["C"])
        constraint_accel = adapted(constraint_accel, "constraint_accel", ["t", "q", "v"],
                                   ["out"])
        constraint_dt = adapted(constraint_dt, "constraint_dt", ["t", "q"], ["out"])
        rate = adapted(rate, "rate", ["t", "q", "v", "y"], ["ydot"])
        force_y = adapted(force_y, "force_y", ["t", "q", "v", "y"], ["f"])
        coupling = adapted(coupling, "coupling", ["t", "q", "v", "y"],
                           ["g_q", "g_v", "g_y", "f_y"])
        force_p = adapted(force_p, "force_p", ["t", "q", "v", "j"], ["f_p"])
        mass_p = adapted(mass_p, "mass_p", ["t", "q", "j", "a"], ["out"])
        constraint_p = adapted(constraint_p, "constraint_p", ["t", "q", "j"],
                               ["phi_p", "Phi_q_p", "Phi_t_p"])
        self._user = {"mass": mass, "force": force, "constraint": constraint,
                      "jacobian": jacobian, "stiffness": stiffness, "damping": damping,
                      "constraint_accel": constraint_accel, "constraint_dt": constraint_dt}

        # Trampolines. By default a callback gets its inputs as read-only copies and fills a
        # zeroed array of its own, copied into the library's buffer when it returns: whatever
        # it keeps of them stays valid and unchanged after the call (and after close()), and
        # nothing it does reaches the library's memory outside the call. zero_copy=True hands
        # it views of the library's buffers instead, valid during the call only. Every
        # exception is caught and stored. The return value counts by its sign, as in C: int()
        # would pass 2**32 through the C int as 0 (success) and truncate -0.5 to 0; a value
        # without a sign (NaN, a string) is an error of the callback.
        def status(fn, rc):
            if rc is None or rc == 0:
                return 0
            if rc > 0:
                return 1
            if rc < 0:
                return -1
            raise TypeError("callback %s returned %r: expected None or an int"
                            % (getattr(fn, "__name__", "?"), rc))

        def copied(address, size):
            a = v(address, (size,)).copy()
            a.flags.writeable = False
            return a

        def call(fn, out_address, out_shape, t, *inputs):
            if self._pending is not None or self._interrupted:
                return -1
            self._in_callback += 1
            try:
                # several outputs (the coupling blocks): tuples of addresses and shapes
                many = isinstance(out_address, tuple)
                places = tuple(zip(out_address, out_shape)) if many else ((out_address,
                                                                           out_shape),)
                if zero_copy:
                    outs = [v(a, sh, True) for a, sh in places]
                    return status(fn, fn(t, *[v(a, (k,)) for a, k in inputs],
                                         outs if many else outs[0]))
                outs = [np.zeros(sh, order="F") for _, sh in places]
                rc = status(fn, fn(t, *[copied(a, k) for a, k in inputs],
                                   outs if many else outs[0]))
                if rc == 0:
                    for (a, sh), out in zip(places, outs):
                        v(a, sh, True)[...] = out
                return rc
            except CallbackRetry:  # raised by a callback: recoverable, as a positive return
                return 1
            except BaseException as e:  # re-raised by the call that stepped
                self._pending = e
                return -1
            finally:
                self._in_callback -= 1

        self._call = call
        self._copied = copied
        self._zero_copy = zero_copy
        self._event_cb = None
        self._event_fns = ()
        sM, sJ = shape("mass", (n, n)), shape("jacobian", (m, n))
        self._jacobian_shape = sJ
        sK, sC = shape("stiffness", (n, n)), shape("damping", (n, n))
        slot = self._slot
        self._cbs = [
            slot(mass, _MASS, lambda t, q, M, u: call(mass, M, sM, t, (q, nq))),
            slot(force, _FORCE, lambda t, q, qd, f, u: call(force, f, (n,), t, (q, nq), (qd, n))),
            slot(constraint if m else None, _CONSTRAINT,
                 lambda t, q, p, u: call(constraint, p, (m,), t, (q, nq))),
            slot(jacobian if m else None, _CONSTRAINT,
                 lambda t, q, J, u: call(jacobian, J, sJ, t, (q, nq))),
            slot(stiffness, _STIFFNESS, lambda t, q, qd, a, lam, K, u: call(
                stiffness, K, sK, t, (q, nq), (qd, n), (a, n), (lam, m))),
            slot(damping, _FORCE,
                 lambda t, q, qd, C, u: call(damping, C, sC, t, (q, nq), (qd, n))),
            slot(constraint_accel, _FORCE, lambda t, q, qd, o, u: call(
                constraint_accel, o, (m,), t, (q, nq), (qd, n))),
            slot(constraint_dt if m else None, _CONSTRAINT,
                 lambda t, q, o, u: call(constraint_dt, o, (m,), t, (q, nq))),
        ]
        mc, fc, cc, jc, kc, dc, ac, tc = self._cbs
        self._check(_ffi.ga_set_callbacks(self._ptr, _cast(mc, _ffi.MASS_FN),
                                          _cast(fc, _ffi.FORCE_FN),
                                          _cast(cc, _ffi.CONSTRAINT_FN),
                                          _cast(jc, _ffi.JACOBIAN_FN), self._user_address))
        if kc or dc:
            self._check(_ffi.ga_set_tangents(self._ptr, _cast(kc, _ffi.STIFFNESS_FN),
                                             _cast(dc, _ffi.DAMPING_FN)))
        if ac:
            self._check(_ffi.ga_set_constraint_accel(self._ptr,
                                                     _cast(ac, _ffi.CONSTRAINT_ACCEL_FN)))
        if tc:
            self._check(_ffi.ga_set_constraint_dt(self._ptr, _cast(tc, _ffi.CONSTRAINT_FN)))
        self.r = int(r)
        if self.r or rate is not None:
            r = self.r
            self._user.update(rate=rate, force_y=force_y, coupling=coupling)
            fo = [
                slot(force_y, _EVENT, lambda t, q, qd, y, f, u: call(
                    force_y, f, (n,), t, (q, nq), (qd, n), (y, r))),
                slot(rate, _EVENT, lambda t, q, qd, y, yd, u: call(
                    rate, yd, (r,), t, (q, nq), (qd, n), (y, r))),
                slot(coupling, _COUPLING, lambda t, q, qd, y, gq, gv, gy, fy, u: call(
                    lambda t, q, qd, y, out: coupling(t, q, qd, y, out[0], out[1], out[2],
                                                      out[3]),
                    (gq, gv, gy, fy), ((r, n), (r, n), (r, r), (n, r)), t, (q, nq), (qd, n),
                    (y, r))),
            ]
            self._cbs += fo
            self._check(_ffi.ga_set_first_order(self._ptr, r, _cast(fo[0], _ffi.FORCE_Y_FN),
                                                _cast(fo[1], _ffi.RATE_FN)))
            if coupling:
                self._check(_ffi.ga_set_coupling(self._ptr, _cast(fo[2], _ffi.COUPLING_FN)))
        for name, pattern in (coupling_patterns or {}).items():
            blocks = {"g_q": _ffi.GA_COUPLING_G_Q, "g_v": _ffi.GA_COUPLING_G_V}
            if name not in blocks:
                raise ValueError(f"unknown coupling block {name!r} (g_q or g_v)")
            rows, cols = (np.ascontiguousarray(x, dtype=np.intc).ravel() for x in pattern)
            if rows.size != cols.size:
                raise ValueError(f"pattern of {name}: {rows.size} rows but {cols.size} cols")
            ip = ctypes.POINTER(ctypes.c_int)
            self._check(_ffi.ga_set_coupling_pattern(self._ptr, blocks[name], rows.size,
                                                     rows.ctypes.data_as(ip),
                                                     cols.ctypes.data_as(ip)))
        if coupling_exact is not None:
            self._check(_ffi.ga_set_coupling_exact(self._ptr, int(bool(coupling_exact))))
        self._parameters = None
        if parameters is not None:
            self._set_sensitivity(parameters, depends, parameter_scale, force_p, mass_p,
                                  constraint_p)
            methods = 0
            for name in sensitivity_method:
                if name not in ("forward", "adjoint"):
                    raise ValueError(f"unknown sensitivity method {name!r} (forward or adjoint)")
                methods |= (_ffi.GA_SENSITIVITY_FORWARD if name == "forward"
                            else _ffi.GA_SENSITIVITY_ADJOINT)
            if methods != _ffi.GA_SENSITIVITY_FORWARD or max_steps is not None:
                if "adjoint" in sensitivity_method and max_steps is None:
                    raise ValueError("the adjoint record needs max_steps")
                self._check(_ffi.ga_set_sensitivity_method(self._ptr, methods,
                                                           int(max_steps or 0)))
            if adjoint_checkpoints is not None:
                interval, count = adjoint_checkpoints
                self._check(_ffi.ga_set_adjoint_checkpoints(self._ptr, int(interval),
                                                            int(count)))
        if rho_inf is not None:
            self.set_rho_inf(rho_inf)
        if params is not None:
            self.set_params(*params)
        if newton is not None:
            self.set_newton(*newton)
        if tangent_mode is not None:
            self._check(_ffi.ga_set_tangent_mode(self._ptr, int(tangent_mode)))
        if scaling is not None:
            self._check(_ffi.ga_set_scaling(self._ptr, int(bool(scaling))))
        if predictor is not None:
            self._check(_ffi.ga_set_predictor(self._ptr, int(predictor)))
        if init_mode is not None:
            self._check(_ffi.ga_set_init_mode(self._ptr, int(init_mode[0]), float(init_mode[1])))
        for value, setter in ((formulation, _ffi.ga_set_formulation), (reuse, _ffi.ga_set_jacobian_reuse),
                              (linear_solver, _ffi.ga_set_linear_solver),
                              (output, _ffi.ga_set_output),
                              (redundant, _ffi.ga_set_redundant_constraints)):
            if value is not None:
                self._check(setter(self._ptr, int(value)))
        for value, setter in ((constant_mass, _ffi.ga_set_constant_mass), (rescale, _ffi.ga_set_rescale),
                              (corrected_start, _ffi.ga_set_corrected_start)):
            if value is not None:
                self._check(setter(self._ptr, int(bool(value))))
        if tolerances is not None:
            self.set_tolerances(*tolerances)
        if step_limits is not None:
            self._check(_ffi.ga_set_step_limits(self._ptr, float(step_limits[0]), float(step_limits[1])))
        if initial_step is not None:
            self._check(_ffi.ga_set_initial_step(self._ptr, float(initial_step)))
        if resolution_check is not None:
            self._check(_ffi.ga_set_resolution_check(self._ptr, float(resolution_check)))

    def _set_sensitivity(self, parameters, depends, scale, force_p, mass_p, constraint_p):
        p = parameters
        if (not isinstance(p, np.ndarray) or p.dtype != np.float64 or p.ndim != 1 or
                not p.flags.c_contiguous or not p.flags.writeable):
            raise ValueError("parameters must be the writeable, contiguous 1-D float64 array "
                             "the callbacks read (galpha perturbs it in place)")
        flags = 0
        known = {"force": _ffi.GA_DEPENDS_FORCE, "mass": _ffi.GA_DEPENDS_MASS,
                 "rate": _ffi.GA_DEPENDS_RATE, "constraint": _ffi.GA_DEPENDS_CONSTRAINT}
        for name in depends:
            if name not in known:
                raise ValueError(f"unknown dependence {name!r} (force, mass, rate or "
                                 "constraint)")
            flags |= known[name]
        sc = None
        if scale is not None:
            sc = np.ascontiguousarray(scale, dtype=float).ravel()
            if sc.shape != p.shape:
                raise ValueError("parameter_scale must have the shape of parameters")
        self._check(_ffi.ga_set_sensitivity(self._ptr, p.size, self._dp(p),
                                            None if sc is None else self._dp(sc), flags))
        self._parameters = (p, sc)  # alive as long as the solver: the library holds p
        n, nq, call = self.n, self.nq, self._call
        slot = self._slot
        cbs = [
            slot(force_p, _FORCE_P, lambda t, q, qd, j, out, u: call(
                lambda t, q, qd, o: force_p(t, q, qd, j, o), out, (n,), t, (q, nq), (qd, n))),
            slot(mass_p, _MASS_P, lambda t, q, j, a, out, u: call(
                lambda t, q, a, o: mass_p(t, q, j, a, o), out, (n,), t, (q, nq), (a, n))),
        ]
        if force_p or mass_p:
            self._cbs += cbs
            self._check(_ffi.ga_set_parameter_derivatives(self._ptr,
                                                          _cast(cbs[0], _ffi.FORCE_P_FN),
                                                          _cast(cbs[1], _ffi.MASS_P_FN)))
        if constraint_p:
            m, sJ = self.m, self._jacobian_shape

            def trampoline(t, q, j, phi_p, J_p, phi_tp, u):
                places = (phi_p, J_p) + ((phi_tp,) if phi_tp else ())
                shapes = ((m,), sJ) + (((m,),) if phi_tp else ())
                return call(lambda t, q, outs: constraint_p(
                    t, q, j, outs[0], outs[1], outs[2] if len(outs) > 2 else None),
                    places, shapes, t, (q, nq))
            cb = slot(constraint_p, _CONSTRAINT_P, trampoline)
            self._cbs.append(cb)
            self._check(_ffi.ga_set_constraint_parameter_derivative(
                self._ptr, _cast(cb, _ffi.CONSTRAINT_P_FN)))

    @_serialized
    def set_sensitivity_start(self, j: int, dq0: Optional[ArrayLike] = None,
                              dv0: Optional[ArrayLike] = None) -> None:
        """dq0/dp_j and dv0/dp_j (None: zero), for every later init() (see
        ga_set_sensitivity_start): initial values as parameters."""
        arrays = []
        for x in (dq0, dv0):
            if x is None:
                arrays.append(None)
                continue
            a = np.ascontiguousarray(x, dtype=float).ravel()
            if a.shape != (self.n,):
                raise error_for(_ffi.GA_ERR_ARG, "dq0 and dv0 must have shape (%d,)" % self.n)
            arrays.append(a)
        self._check(_ffi.ga_set_sensitivity_start(
            self._handle(), int(j), *[None if a is None else self._dp(a) for a in arrays]))

    @_serialized
    def sensitivity(self) -> Sensitivity:
        """Derivatives of the accepted step's q, v, qdd and lambda with respect to the
        parameters (ga_get_sensitivity, ga_get_sensitivity_y): a Sensitivity of arrays dq
        (n, np), dv (n, np), dqdd (n, np), dlam (m, np), dy and dydot (r, np); column j is
        d/dp_j."""
        if self._parameters is None:
            raise error_for(_ffi.GA_ERR_STATE, "no sensitivities: Solver(parameters=...)")
        n, m, nq, npar = self.n, self.m, self.nq, self._parameters[0].size
        out = [np.empty((npar, max(k, 1))) for k in (n, n, n, m)]
        for j in range(npar):
            self._check(_ffi.ga_get_sensitivity(self._handle(), j,
                                                *[self._dp(x[j]) for x in out]))
        dq, dv, dqdd, dlam = (x[:, :k].T.copy() for x, k in zip(out, (n, n, n, m)))
        r = self.r
        ys = [np.empty((npar, max(r, 1))) for _ in range(2)]
        for j in range(npar):
            self._check(_ffi.ga_get_sensitivity_y(self._handle(), j,
                                                  *[self._dp(x[j]) for x in ys]))
        dy, dydot = (x[:, :r].T.copy() for x in ys)
        return Sensitivity(dq, dv, dqdd, dlam, dy, dydot)

    @_serialized
    @_runs_callbacks
    def adjoint_gradient(self, running: Optional[Callable[..., float]] = None,
                         terminal: Optional[Callable[..., float]] = None
                         ) -> Tuple[float, np.ndarray]:
        """(J, dJ/dp) of J = terminal(x_N) + the trapezoidal sum of running(x_n) over the
        steps recorded since init() (ga_adjoint_gradient), by the discrete adjoint. Each cost is
        fn(t, q, v, qdd, lam, d_q, d_v, d_qdd, d_lam, d_p) -> value, filling the partial
        derivatives (zeroed arrays of lengths n, n, n, m, np) where they are not zero."""
        if self._parameters is None:
            raise error_for(_ffi.GA_ERR_STATE, "no sensitivities: Solver(parameters=...)")
        n, m, nq, npar = self.n, self.m, self.nq, self._parameters[0].size
        v = self._view

        def trampoline(fn):
            if fn is None:
                return None
            if native_address(fn) is not None:
                return self._slot(fn, _COST, None)

            def c(t, q, qd, qdd, lam, value, dq, dv, dqdd, dlam, dp, u):
                if self._pending is not None or self._interrupted:
                    return -1
                try:
                    outs = [np.zeros(k) for k in (n, n, n, m, npar)]
                    val = fn(t, self._copied(q, nq), self._copied(qd, n), self._copied(qdd, n),
                             self._copied(lam, m) if m else np.zeros(0), *outs)
                    v(value, (1,), True)[0] = float(val)
                    for address, out in zip((dq, dv, dqdd, dlam, dp), outs):
                        if out.size:
                            v(address, out.shape, True)[...] = out
                    return 0
                except BaseException as e:  # re-raised below
                    self._pending = e
                    return -1
            return _COST(c)

        cbs = (trampoline(running), trampoline(terminal))
        J = np.zeros(1)
        dJ = np.zeros(max(npar, 1))
        self._check(_ffi.ga_adjoint_gradient(self._handle(), _cast(cbs[0], _ffi.COST_FN),
                                             _cast(cbs[1], _ffi.COST_FN), self._dp(J),
                                             self._dp(dJ)))
        return float(J[0]), dJ[:npar].copy()

    # ---- plumbing ---------------------------------------------------------------------------
    def _slot(self, fn, ctype, trampoline):
        """The C function pointer of one callback: fn's own if it is compiled (numba cfunc,
        ctypes function pointer, int address; it gets the solver's `user`), else the Python
        trampoline. None if fn is None."""
        if fn is None:
            return None
        address = native_address(fn)
        if address is not None:
            check_compiled_signature(fn, ctype, getattr(fn, "__name__", "callback"))
            self._compiled.append(fn)
            return ctype(address)
        if not callable(fn):
            raise TypeError("a callback must be callable, a numba cfunc, a ctypes function "
                            "pointer or an int address, not %s" % type(fn).__name__)
        return ctype(trampoline)

    def _view(self, address, shape, writeable=False):
        key = (address, shape, writeable)
        arr = self._views.get(key)
        if arr is None:
            size = int(np.prod(shape))
            buf = (ctypes.c_double * max(size, 1)).from_address(address)
            # an input over a read-only memoryview: its writeable flag cannot be set
            flat = (np.ctypeslib.as_array(buf) if writeable else
                    np.frombuffer(memoryview(buf).toreadonly(), dtype=np.float64))[:size]
            # column-major storage seen with its natural (rows, cols) shape
            arr = flat.reshape(shape[::-1]).T if len(shape) == 2 else flat
            arr.flags.writeable = writeable
            self._views[key] = arr
        return arr

    def _check(self, status):
        pending, self._pending = self._pending, None
        if pending is not None:
            raise pending.with_traceback(pending.__traceback__)
        if status < _ffi.GA_OK:
            message = _ffi.ga_last_error(self._ptr).decode() if self._ptr else ""
            raise error_for(status, message)
        return status in (_ffi.GA_EVENT, _ffi.GA_STOPPED)

    def _handle(self):
        if self._ptr is None:
            raise error_for(_ffi.GA_ERR_STATE, "solver is closed")
        return self._ptr

    @staticmethod
    def _dp(a):
        return a.ctypes.data_as(_ffi.c_double_p)

    @_serialized
    @_runs_callbacks
    def _get(self, fn, size):
        out = np.empty(max(size, 1))
        self._check(fn(self._handle(), self._dp(out)))
        return out[:size]

    # ---- life cycle -------------------------------------------------------------------------
    @_serialized
    def close(self) -> None:
        """Free the C solver (idempotent). Not from one of its own callbacks: ga_free ignores
        that call (the solver is in use), so it raises StateError instead of leaking it."""
        if self._in_callback:
            raise error_for(_ffi.GA_ERR_STATE, "close() from a callback of the same solver")
        if self._ptr is not None:
            self._free(self._ptr)
            self._ptr = None
        self._views.clear()

    def __enter__(self) -> "Solver":
        return self

    # One object owns one C solver: a copy would free it twice.
    def __copy__(self):
        raise TypeError("a galpha.Solver cannot be copied (it owns its C solver); create "
                        "another, or take a checkpoint (get_state) and restore it")

    def __deepcopy__(self, memo):
        self.__copy__()

    def __reduce__(self):
        raise TypeError("a galpha.Solver cannot be pickled (it owns its C solver and Python "
                        "callbacks); pickle how to build it instead")

    def __exit__(self, *exc: Any) -> bool:
        self.close()
        return False

    def __repr__(self) -> str:
        sizes = "n=%d, m=%d" % (self.n, self.m)
        if self.nq != self.n:
            sizes += ", nq=%d" % self.nq
        if self.r:
            sizes += ", r=%d" % self.r
        if self._ptr is None:
            return "<galpha.Solver %s, closed>" % sizes
        # never wait for a run in another thread, nor call into C from one of its callbacks
        if self._in_callback or not self._lock.acquire(blocking=False):
            return "<galpha.Solver %s, running>" % sizes
        try:
            t = ctypes.c_double()
            if _ffi.ga_get_t(self._ptr, ctypes.byref(t)) != _ffi.GA_OK:
                return "<galpha.Solver %s, not initialized>" % sizes
            steps = ctypes.c_longlong()
            _ffi.ga_get_counter(self._ptr, 0, ctypes.byref(steps))
            return "<galpha.Solver %s, t=%.6g, steps=%d, %s>" % (
                sizes, t.value, steps.value, _ffi.ga_linear_solver_name(self._ptr).decode())
        finally:
            self._lock.release()

    def __del__(self):
        try:
            self.close()
        except Exception:  # interpreter shutdown: modules may already be gone
            pass

    # ---- options ----------------------------------------------------------------------------
    @_serialized
    def set_rho_inf(self, rho_inf: float) -> None:
        """Chung-Hulbert parameters from the spectral radius at infinity, rho_inf in [0, 1]
        (ga_set_rho_inf; default 0.9): 1 keeps every frequency, 0 damps the highest at once."""
        self._check(_ffi.ga_set_rho_inf(self._handle(), float(rho_inf)))

    @_serialized
    def set_params(self, alpha_m: float, alpha_f: float, beta: float, gamma: float) -> None:
        """The method's four parameters directly (ga_set_params); refused unless second order
        and stable (the message names the broken condition)."""
        self._check(_ffi.ga_set_params(self._handle(), alpha_m, alpha_f, beta, gamma))

    @_serialized
    def set_tolerances(self, rtol: float, atol: Union[float, ArrayLike]) -> None:
        """Tolerances of adaptive steps (ga_set_tolerances): rtol a number; atol a number, or
        one per coordinate (ga_set_tolerances_vector): 2 n + r numbers, the positions (on a
        space with rotations, the n tangent coordinates), the velocities, then the
        first-order states -- the rows of integrate's `y` on a vector space."""
        a = np.asarray(atol, dtype=float)
        if a.ndim == 0:
            self._check(_ffi.ga_set_tolerances(self._handle(), float(rtol), float(a)))
            return
        a = np.ascontiguousarray(a.ravel())
        if a.size != 2 * self.n + self.r:
            raise error_for(_ffi.GA_ERR_ARG, "atol has %d entries; per coordinate it needs 2 n "
                            "+ r = %d (positions, velocities, first-order states)"
                            % (a.size, 2 * self.n + self.r))
        self._check(_ffi.ga_set_tolerances_vector(self._handle(), float(rtol), self._dp(a)))

    @_serialized
    def set_newton(self, tol: float, max_iter: int = 20) -> None:
        """Newton tolerance (on the increments, each quantity relative to itself) and iteration
        limit (ga_set_newton)."""
        self._check(_ffi.ga_set_newton(self._handle(), float(tol), int(max_iter)))

    @property
    @_serialized
    def params(self) -> Tuple[float, float, float, float]:
        """(alpha_m, alpha_f, beta, gamma)"""
        vals = [ctypes.c_double() for _ in range(4)]
        self._check(_ffi.ga_get_params(self._handle(), *[ctypes.byref(x) for x in vals]))
        return tuple(x.value for x in vals)

    # ---- stepping ---------------------------------------------------------------------------
    @_serialized
    @_runs_callbacks
    def init(self, t0: float, q0: ArrayLike, v0: ArrayLike, y0: Optional[ArrayLike] = None
             ) -> None:
        """Consistent initial values at t0 (see ga_init); with first-order states, y0 their
        initial values (ga_init_y; None on a running solver keeps the states it holds)."""
        q0 = np.ascontiguousarray(q0, dtype=float)
        v0 = np.ascontiguousarray(v0, dtype=float)
        if q0.shape != (self.nq,) or v0.shape != (self.n,):
            raise error_for(_ffi.GA_ERR_ARG, "q0 and v0 must have shape (%d,)" % self.n
                            if self.nq == self.n else "q0 and v0 must have shapes (%d,) and "
                            "(%d,)" % (self.nq, self.n))
        if y0 is None:
            self._check(_ffi.ga_init(self._handle(), float(t0), self._dp(q0), self._dp(v0)))
            return
        y0 = np.ascontiguousarray(y0, dtype=float).reshape(-1)
        if y0.shape != (self.r,):
            raise error_for(_ffi.GA_ERR_ARG, "y0 must have shape (%d,)" % self.r)
        self._check(_ffi.ga_init_y(self._handle(), float(t0), self._dp(q0), self._dp(v0),
                                   self._dp(np.append(y0, 0.0))))

    @_serialized
    def set_coupling_exact(self, exact: bool) -> None:
        """Whether g_q, g_v, f_y are in the iteration matrix (see ga_set_coupling_exact)."""
        self._check(_ffi.ga_set_coupling_exact(self._handle(), int(bool(exact))))

    def _y_pair(self, fn, *args):
        y, yd = np.empty(max(self.r, 1)), np.empty(max(self.r, 1))
        self._check(fn(self._handle(), *args, self._dp(y), self._dp(yd)))
        return y[:self.r], yd[:self.r]

    @property
    @_serialized
    def y(self) -> np.ndarray:
        """First-order states at the accepted step (copy)."""
        return self._y_pair(_ffi.ga_get_y)[0]

    @property
    @_serialized
    def ydot(self) -> np.ndarray:
        """Their rates y' = g at the accepted step (copy)."""
        return self._y_pair(_ffi.ga_get_y)[1]

    @_serialized
    @_runs_callbacks
    def interpolate_y(self, t: Union[float, ArrayLike]) -> Tuple[np.ndarray, np.ndarray]:
        """(y, ydot) at t inside the last step (see ga_interpolate_y): shapes (r,) for a
        number t, (k, r) for k times."""
        times = np.asarray(t, dtype=float)
        pairs = [self._y_pair(_ffi.ga_interpolate_y, float(tk)) for tk in times.ravel()]
        if times.ndim == 0:
            return pairs[0]
        return (np.array([p[0] for p in pairs]).reshape(times.size, self.r),
                np.array([p[1] for p in pairs]).reshape(times.size, self.r))

    def _stepping(self, fn, x):
        """fn(handle, x) under the lock, with Ctrl-C deferred in the main thread (the work of
        _serialized and _runs_callbacks, inlined: a step loop pays it at every step)."""
        global _running, _sigint_handler_tried
        with self._lock:
            ptr = self._ptr
            if ptr is None:
                raise error_for(_ffi.GA_ERR_STATE, "solver is closed")
            if threading.get_ident() != _MAIN_THREAD:
                return self._check(fn(ptr, x))
            if not _sigint_handler_tried:
                _sigint_handler_tried = True
                if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                    signal.signal(signal.SIGINT, _on_sigint)
            outer, _running = _running, self
            try:
                status = fn(ptr, x)
            finally:
                _running = outer
            if self._interrupted:
                self._interrupted = False
                self._pending = None
                raise KeyboardInterrupt
            if status == 0 and self._pending is None:
                return False
            return self._check(status)

    def step(self, h: float) -> bool:
        """One step of size h. On failure raises; the state stays at the last accepted step.
        True if it stopped at a terminal event (see set_events) or the step hook asked to stop
        (set_step_hook), else False."""
        return self._stepping(_ffi.ga_step, h)

    def step_adaptive(self, t_stop: float) -> bool:
        """One error-controlled step, not beyond t_stop (see ga_step_adaptive). True if it
        stopped at a terminal event or by the step hook."""
        return self._stepping(_ffi.ga_step_adaptive, t_stop)

    def advance(self, t_out: float) -> bool:
        """Error-controlled steps until t_out exactly (see ga_advance), or until a terminal
        event or the step hook asks to stop: True then (the solver at the end of that step),
        else False."""
        return self._stepping(_ffi.ga_advance, t_out)

    @_serialized
    def set_events(self, functions: Any, multipliers: bool = False, states: bool = False,
                   direction: Optional[Sequence[int]] = None,
                   terminal: Optional[Sequence[bool]] = None) -> None:
        """Watch event functions g(t, q, v, lam) -> float (see ga_set_events), each with the
        optional attributes of scipy's solve_ivp: `direction` (> 0 rising, < 0 falling, 0
        either; default 0) and `terminal` (true: step, step_adaptive and advance stop there
        and return True; default False). lam is None unless `multipliers` (then the
        multipliers at the located state, consistent with q and v). With `states`, the
        functions are g(t, q, v, lam, y) with the first-order states y (ga_set_events_y). An
        empty list removes them. The events found by the last stepping call: `events`.

        `functions` may also be one compiled function (numba cfunc, ctypes function pointer
        or address) with the C signature of ga_event_fn (ga_event_y_fn with `states`) that
        fills all of g; then `direction` and `terminal` are sequences giving their number."""
        if native_address(functions) is not None:
            if direction is None:
                raise ValueError("a compiled event function needs `direction` (one entry per "
                                 "function)")
            count = len(direction)
            terminal = [True] * count if terminal is None else list(terminal)
            if len(terminal) != count:
                raise ValueError("direction and terminal differ in length")
            dirs = (_i * max(count, 1))(*[int(np.sign(d)) for d in direction])
            terms = (_i * max(count, 1))(*[int(bool(x)) for x in terminal])
            if states:
                cb = self._slot(functions, _EVENT_Y, None)
                self._check(_ffi.ga_set_events_y(self._handle(), count,
                                                 _cast(cb, _ffi.EVENT_Y_FN), dirs, terms,
                                                 int(bool(multipliers))))
            else:
                cb = self._slot(functions, _EVENT, None)
                self._check(_ffi.ga_set_events(self._handle(), count, _cast(cb, _ffi.EVENT_FN),
                                               dirs, terms, int(bool(multipliers))))
            self._event_cb, self._event_fns = cb, (functions,)
            return
        functions = tuple(functions)
        for g in functions:
            if not callable(g):
                raise TypeError("event functions must be callable, got %r" % (g,))
        count, n, m, r, nq = len(functions), self.n, self.m, self.r, self.nq
        call = self._call

        args = self._args

        def evaluate(t, q, v, lam, g, y=None):
            for k, fn in enumerate(functions):
                value = fn(t, q, v, lam, y, *args) if states else fn(t, q, v, lam, *args)
                # a number, or a 0-d or one-element array: None, strings and arrays of several
                # values are said to be what they are (numpy took "0.5" as 0.5)
                if isinstance(value, (str, bytes)) or value is None or np.size(value) != 1:
                    raise TypeError("event function %d (%s) returned %r: expected one number"
                                    % (k, getattr(fn, "__name__", "?"), value))
                g[k] = float(np.reshape(value, ()))

        def trampoline(t, q, v, lam, g, u):
            if lam:
                return call(evaluate, g, (count,), t, (q, nq), (v, n), (lam, m))
            return call(lambda t, q, v, g: evaluate(t, q, v, None, g), g, (count,), t,
                        (q, nq), (v, n))

        def trampoline_y(t, q, v, y, lam, g, u):
            if lam:
                return call(lambda t, q, v, y, lam, g: evaluate(t, q, v, lam, g, y), g,
                            (count,), t, (q, nq), (v, n), (y, r), (lam, m))
            return call(lambda t, q, v, y, g: evaluate(t, q, v, None, g, y), g, (count,), t,
                        (q, nq), (v, n), (y, r))

        direction = (_i * max(count, 1))(*[int(np.sign(getattr(g, "direction", 0)))
                                            for g in functions])
        terminal = (_i * max(count, 1))(*[int(bool(getattr(g, "terminal", False)))
                                           for g in functions])
        if states:
            cb = _EVENT_Y(trampoline_y) if count else None
            self._check(_ffi.ga_set_events_y(self._handle(), count, _cast(cb, _ffi.EVENT_Y_FN),
                                             direction, terminal, int(bool(multipliers))))
        else:
            cb = _EVENT(trampoline) if count else None
            self._check(_ffi.ga_set_events(self._handle(), count, _cast(cb, _ffi.EVENT_FN),
                                           direction, terminal, int(bool(multipliers))))
        self._event_cb, self._event_fns = cb, functions

    @_serialized
    def set_step_hook(self, fn: Any, multipliers: bool = False, user: Any = None) -> None:
        """Call fn after every accepted step of step, step_adaptive and advance (see
        ga_set_step_hook); None removes it. A Python fn is called as fn(t, q, v, lam) (lam None
        unless `multipliers`; arrays as the other callbacks get them) and returns a true value
        to stop the stepping call after this step, which then returns True. An exception it
        raises stops the call too and is re-raised from it (the step stays accepted). fn may
        also be compiled (numba cfunc, ctypes function pointer, address) with the C signature
        ``int(const ga_solver *s, double t, const double *q, const double *v, const double
        *lambda, void *user)``; `user` as the Solver's (default: the Solver's)."""
        if fn is None:
            self._check(_ffi.ga_set_step_hook(self._handle(), _ffi.STEP_HOOK_FN(), None, 0))
            self._hook = None
            return
        n, m, nq = self.n, self.m, self.nq
        address = native_address(fn)
        if address is not None:
            check_compiled_signature(fn, _HOOK, "step hook")
            uaddr, keep = user_pointer(user) if user is not None else (self._user_address, None)
            cb = _HOOK(address)
            hold = (fn, keep)
        else:
            if user is not None:
                raise ValueError("user is for compiled hooks; a Python hook sees what it closes "
                                 "over")
            if not callable(fn):
                raise TypeError("the step hook must be callable or compiled, not %s"
                                % type(fn).__name__)
            zero_copy, copied, view = self._zero_copy, self._copied, self._view

            def trampoline(handle, t, q, v, lam, u):
                if self._pending is not None or self._interrupted:
                    return 1
                self._in_callback += 1
                try:
                    if zero_copy:
                        args = (view(q, (nq,)), view(v, (n,)), view(lam, (m,)) if lam else None)
                    else:
                        args = (copied(q, nq), copied(v, n), copied(lam, m) if lam else None)
                    return 1 if fn(t, *args) else 0
                except BaseException as e:  # re-raised by the call that stepped
                    self._pending = e
                    return 1
                finally:
                    self._in_callback -= 1
            cb, uaddr, hold = _HOOK(trampoline), None, fn
        self._check(_ffi.ga_set_step_hook(self._handle(), ctypes.cast(cb, _ffi.STEP_HOOK_FN),
                                          uaddr, int(bool(multipliers))))
        self._hook = (cb, hold)

    @property
    @_serialized
    def events(self) -> list:
        """The events found by the last step, step_adaptive or advance, in time order -- a list
        of (t, index, direction) (see ga_get_event)."""
        count = ctypes.c_int()
        self._check(_ffi.ga_get_event_count(self._handle(), ctypes.byref(count)))
        out = []
        for i in range(count.value):
            t, k, d = ctypes.c_double(), ctypes.c_int(), ctypes.c_int()
            self._check(_ffi.ga_get_event(self._handle(), i, ctypes.byref(t), ctypes.byref(k),
                                          ctypes.byref(d)))
            out.append((t.value, k.value, d.value))
        return out

    @_serialized
    @_runs_callbacks
    def interpolate(self, t: Union[float, ArrayLike]
                    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, v, lam) at t inside the last step (dense output, see ga_interpolate): arrays of
        shapes (nq,), (n,), (m,) for a number t; for an array of k times, (k, nq), (k, n),
        (k, m), a row per time (as integrate's histories)."""
        times = np.asarray(t, dtype=float)
        q, v = np.empty((times.size, self.nq)), np.empty((times.size, self.n))
        lam = np.empty((times.size, max(self.m, 1)))
        for k, tk in enumerate(times.ravel()):
            self._check(_ffi.ga_interpolate(self._handle(), float(tk), self._dp(q[k]),
                                            self._dp(v[k]), self._dp(lam[k])))
        lam = lam[:, :self.m]
        if times.ndim == 0:
            return q[0], v[0], lam[0]
        return q, v, lam

    @_serialized
    @_runs_callbacks
    def interpolate_qdd(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """qdd at t inside the last step (see ga_interpolate_qdd): shape (n,) for a number t,
        (k, n) for k times."""
        times = np.asarray(t, dtype=float)
        qdd = np.empty((times.size, self.n))
        for k, tk in enumerate(times.ravel()):
            self._check(_ffi.ga_interpolate_qdd(self._handle(), float(tk), self._dp(qdd[k])))
        return qdd[0] if times.ndim == 0 else qdd

    @property
    @_serialized
    def linear_solver_name(self) -> str:
        """The linear solver in use (ga_linear_solver_name), e.g. "dense unblocked LU"."""
        return _ffi.ga_linear_solver_name(self._handle()).decode()

    @property
    @_serialized
    def active_constraints(self) -> np.ndarray:
        """Flags of the constraints in use (True) or dropped as redundant (False)."""
        flags = (ctypes.c_int * max(self.m, 1))()
        self._check(_ffi.ga_get_active_constraints(self._handle(), flags))
        return np.array([bool(x) for x in flags[:self.m]], dtype=bool)

    # ---- state ------------------------------------------------------------------------------
    @property
    @_serialized
    def t(self) -> float:
        """Time of the last accepted step (or of init)."""
        x = ctypes.c_double()
        self._check(_ffi.ga_get_t(self._handle(), ctypes.byref(x)))
        return x.value

    @property
    @_serialized
    def h_last(self) -> float:
        """Size of the last accepted step (0 before the first)."""
        x = ctypes.c_double()
        self._check(_ffi.ga_get_h_last(self._handle(), ctypes.byref(x)))
        return x.value

    @property
    def q(self) -> np.ndarray:
        """Positions of the last accepted step (a copy; nq numbers)."""
        return self._get(_ffi.ga_get_q, self.nq)

    @property
    def v(self) -> np.ndarray:
        """Velocities (a copy)."""
        return self._get(_ffi.ga_get_v, self.n)

    @property
    def qdd(self) -> np.ndarray:
        """Accelerations (a copy; consistent with q and v unless output=GA_OUTPUT_STEP)."""
        return self._get(_ffi.ga_get_qdd, self.n)

    @property
    def lam(self) -> np.ndarray:
        """Multipliers (a copy; consistent with q and v unless output=GA_OUTPUT_STEP)."""
        return self._get(_ffi.ga_get_lambda, self.m)

    @property
    def a(self) -> np.ndarray:
        """The auxiliary vector a of the method (a copy)."""
        return self._get(_ffi.ga_get_a, self.n)

    @property
    @_serialized
    def stats(self) -> dict:
        """Work counters as a dict (steps, failed_steps, newton_iters, factorizations, ...)."""
        out = {}
        for key, name in enumerate(_ffi.COUNTERS):
            x = ctypes.c_longlong()
            self._check(_ffi.ga_get_counter(self._handle(), key, ctypes.byref(x)))
            out[name] = x.value
        return out

    @_serialized
    def reset_counters(self) -> None:
        """Set every work counter of `stats` to zero."""
        self._check(_ffi.ga_reset_counters(self._handle()))

    @_serialized
    def check_derivatives(self, t: float, q: ArrayLike, v: ArrayLike,
                          qdd: Optional[ArrayLike] = None, lam: Optional[ArrayLike] = None,
                          y: Optional[ArrayLike] = None, tol: float = 1e-6) -> None:
        """Every derivative callback given (jacobian, stiffness, damping, constraint_accel,
        constraint_dt, coupling, force_p, mass_p, constraint_p) at (t, q, v, qdd, lam, y)
        against central differences of what it derives (ga_check_derivatives). Returns the
        largest relative difference; raises DerivativeError naming each derivative beyond tol
        with its worst entry (or a constraint with a zero gradient). qdd defaults to zero, lam
        to ones, y to zero."""
        arrays = []
        for x, size in ((q, self.nq), (v, self.n), (qdd, self.n), (lam, self.m), (y, None)):
            if x is None:
                arrays.append(None)
                continue
            a = np.ascontiguousarray(x, dtype=float).ravel()
            if size is not None and a.size != size:
                raise ValueError(f"an array of {size} values expected, got {a.size}")
            arrays.append(a)
        if arrays[0] is None or arrays[1] is None:
            raise ValueError("q and v are required")
        worst = ctypes.c_double()
        self._check(_ffi.ga_check_derivatives(
            self._handle(), float(t), *[None if a is None else self._dp(a) for a in arrays],
            float(tol), ctypes.byref(worst)))
        return worst.value

    def _rest_arrays(self, q, lam):
        # the space before the sizes: on a space with rotations the C call refuses whatever q is
        if not self._euclidean:
            raise StateError("operating points (statics, paths, linearization, modes): on "
                             "coordinates in R^n only (not yet on a space with rotations)")
        q = np.array(q, dtype=float).ravel()
        if q.size != self.n:
            raise ValueError(f"q: {self.n} values expected, got {q.size}")
        if lam is not None:
            lam = np.ascontiguousarray(lam, dtype=float).ravel()
            if lam.size != self.m:
                raise ValueError(f"lam: {self.m} values expected, got {lam.size}")
        return q, lam

    @_serialized
    @_runs_callbacks
    def static_equilibrium(self, q0: ArrayLike, t: float = 0.0, tol: float = 1e-10,
                           max_iter: int = 50) -> Equilibrium:
        """The static equilibrium f(q, 0, t) = Phi_q^T lam, Phi(q, t) = 0 by Newton from q0
        (ga_static_equilibrium): an Equilibrium(q, lam). Raises ConvergenceError (no
        equilibrium in reach), SingularMatrixError (a limit point, or an unrestrained motion),
        the callbacks' errors."""
        q, _ = self._rest_arrays(q0, None)
        lam = np.zeros(max(self.m, 1))
        self._check(_ffi.ga_static_equilibrium(self._handle(), float(t), self._dp(q),
                                               self._dp(lam), float(tol), int(max_iter)))
        return Equilibrium(q, lam[:self.m].copy())

    @_serialized
    @_runs_callbacks
    def static_equilibrium_y(self, q0: ArrayLike, y0: ArrayLike, t: float = 0.0,
                             tol: float = 1e-10, max_iter: int = 50) -> EquilibriumY:
        """The static equilibrium with the first-order states as unknowns too (f(q, 0, y) =
        Phi_q^T lam, g(q, 0, y) = 0, Phi = 0; ga_static_equilibrium_y) from (q0, y0): an
        EquilibriumY(q, y, lam)."""
        q, _ = self._rest_arrays(q0, None)
        r = self.r
        y = np.ascontiguousarray(np.array(y0, dtype=float).ravel())
        if y.size != r:
            raise ValueError(f"y0 has {y.size} entries, the model has {r} first-order states")
        ybuf = np.zeros(max(r, 1))
        ybuf[:r] = y
        lam = np.zeros(max(self.m, 1))
        self._check(_ffi.ga_static_equilibrium_y(self._handle(), float(t), self._dp(q),
                                                 self._dp(ybuf), self._dp(lam), float(tol),
                                                 int(max_iter)))
        return EquilibriumY(q, ybuf[:r].copy(), lam[:self.m].copy())

    @_serialized
    @_runs_callbacks
    def state_space(self, q: ArrayLike, y: Optional[ArrayLike] = None,
                    lam: Optional[ArrayLike] = None, t: float = 0.0) -> StateSpace:
        """The first-order form x' = A x of the small motions about (q, y, lam) at rest, x =
        (z, z', y) in the minimal coordinates q = q0 + N z (ga_state_space): a StateSpace(N,
        A), A (2 dof + r square). y: the first-order states (None without them); lam None:
        the balancing multipliers."""
        q, lam = self._rest_arrays(q, lam)
        r = self.r
        ybuf = np.zeros(max(r, 1))
        if r:
            if y is None:
                raise ValueError(f"the model has {r} first-order states: y is needed")
            ybuf[:r] = np.array(y, dtype=float).ravel()
        dim = ctypes.c_int()
        h = self._handle()
        lp = None if lam is None else self._dp(lam)
        max_dim = 2 * self.n + r
        N = np.zeros(self.n * self.n)
        A = np.zeros(max(max_dim * max_dim, 1))
        self._check(_ffi.ga_state_space(h, float(t), self._dp(q), self._dp(ybuf), lp, max_dim,
                                        ctypes.byref(dim), self._dp(N), self._dp(A)))
        d = dim.value
        dof = (d - r) // 2
        return StateSpace(N[:self.n * dof].reshape((self.n, dof), order="F").copy(),
                          A[:d * d].reshape((d, d), order="F").copy())

    @_serialized
    @_runs_callbacks
    def state_space_motion(self, q: ArrayLike, v: ArrayLike, y: Optional[ArrayLike] = None,
                           t: float = 0.0) -> StateSpace:
        """The first-order form x' = A x of the small motions about a moving state
        (t, q, v, y) on the constraints, x = (z, w, y) in the chart q + N z of the constraint
        manifold (ga_state_space_motion): a StateSpace(N, A), with the centripetal and
        Coriolis terms. y: the first-order states (None without them)."""
        q, _ = self._rest_arrays(q, None)
        v, _ = self._rest_arrays(v, None)
        r = self.r
        ybuf = np.zeros(max(r, 1))
        if r:
            if y is None:
                raise ValueError(f"the model has {r} first-order states: y is needed")
            ybuf[:r] = np.array(y, dtype=float).ravel()
        dim = ctypes.c_int()
        max_dim = 2 * self.n + r
        N = np.zeros(self.n * self.n)
        A = np.zeros(max(max_dim * max_dim, 1))
        self._check(_ffi.ga_state_space_motion(self._handle(), float(t), self._dp(q),
                                               self._dp(v), self._dp(ybuf), max_dim,
                                               ctypes.byref(dim), self._dp(N), self._dp(A)))
        d = dim.value
        dof = (d - r) // 2
        return StateSpace(N[:self.n * dof].reshape((self.n, dof), order="F").copy(),
                          A[:d * d].reshape((d, d), order="F").copy())

    @_serialized
    @_runs_callbacks
    def linearize(self, q: ArrayLike, lam: Optional[ArrayLike] = None, t: float = 0.0
                  ) -> Linearization:
        """The small motions about (q, lam) at rest in minimal coordinates q = q0 + N z
        (ga_linearize): a Linearization(N, M, C, K) with N (n x dof) orthonormal, Phi_q N = 0,
        and M z'' + C z' + K z = 0. lam None: the multipliers that balance f at q."""
        q, lam = self._rest_arrays(q, lam)
        n = self.n
        dof = ctypes.c_int()
        mats = [np.zeros(n * n) for _ in range(4)]  # N (ld n), M, C, K (ld dof)
        self._check(_ffi.ga_linearize(self._handle(), float(t), self._dp(q),
                                      None if lam is None else self._dp(lam), n,
                                      ctypes.byref(dof), *[self._dp(a) for a in mats]))
        d = dof.value
        N = mats[0][:n * d].reshape((n, d), order="F").copy()
        return Linearization(N, *[a[:d * d].reshape((d, d), order="F").copy() for a in mats[1:]])

    @_serialized
    @_runs_callbacks
    def static_path(self, q0: ArrayLike, load: np.ndarray, ds: float, max_points: int = 1000,
                    tol: float = 1e-10, t: float = 0.0,
                    stop: Optional[Callable[..., bool]] = None) -> StaticPath:
        """The equilibrium path in a load factor through limit points (ga_static_path):
        `load` is a float array of one entry that the callbacks read (the call writes the
        load there as it goes; afterwards it holds the last point's); from the equilibrium at
        load[0] near q0, points at arc length ``|ds|`` apart (ds > 0: the load rising first), up
        to max_points or until stop(load, q, lam) returns True. A StaticPath of the points
        after the start. Raises as static_equilibrium; the points before a failure are lost
        with it (the exception's solver state is the last point)."""
        q, _ = self._rest_arrays(q0, None)
        if not (isinstance(load, np.ndarray) and load.dtype == np.float64 and load.size == 1
                and load.flags.c_contiguous):
            raise TypeError("load must be a float64 numpy array of one entry, which the "
                            "callbacks read")
        lam = np.zeros(max(self.m, 1))
        n, m = self.n, self.m
        loads, qs, lams = [], [], []

        def point(mu, qp, lp, u):
            if self._pending is not None or self._interrupted:
                return 1
            try:
                qq = np.ctypeslib.as_array(qp, shape=(n,)).copy()
                ll = np.ctypeslib.as_array(lp, shape=(m,)).copy() if m else np.zeros(0)
                loads.append(mu)
                qs.append(qq)
                lams.append(ll)
                return 1 if stop is not None and stop(mu, qq, ll) else 0
            except BaseException as e:  # re-raised by _check
                self._pending = e
                return 1
        cb = _ffi.PATH_FN(point)
        stopped = self._check(_ffi.ga_static_path(
            self._handle(), float(t), load.ctypes.data_as(_ffi.c_double_p), self._dp(q),
            self._dp(lam), float(ds), int(max_points), float(tol), cb, None))
        return StaticPath(np.array(loads), np.array(qs).reshape(-1, n),
                          np.array(lams).reshape(-1, m), "stopped" if stopped else "done")

    @_serialized
    @_runs_callbacks
    def damped_modes(self, q: ArrayLike, lam: Optional[ArrayLike] = None,
                     count: Optional[int] = None, t: float = 0.0) -> DampedModes:
        """The `count` modes of the linearized damped (possibly non-conservative) system at an
        equilibrium (ga_modes_damped; count None: all 2 dof): DampedModes(s, shapes)."""
        q, lam = self._rest_arrays(q, lam)
        if count is None:
            count = 2 * self.linearize(q, lam, t).N.shape[1]
        count = int(count)
        re, im = np.zeros(max(count, 1)), np.zeros(max(count, 1))
        sr, si = np.zeros(self.n * max(count, 1)), np.zeros(self.n * max(count, 1))
        self._check(_ffi.ga_modes_damped(self._handle(), float(t), self._dp(q),
                                         None if lam is None else self._dp(lam), count,
                                         self._dp(re), self._dp(im), self._dp(sr), self._dp(si)))
        shapes = (sr + 1j * si)[:self.n * count].reshape((self.n, count), order="F")
        return DampedModes((re + 1j * im)[:count], shapes)

    @_serialized
    @_runs_callbacks
    def modes(self, q: ArrayLike, lam: Optional[ArrayLike] = None,
              count: Optional[int] = None, t: float = 0.0) -> Modes:
        """The `count` lowest undamped vibration modes at an equilibrium (q, lam) (ga_modes;
        count None: every degree of freedom): Modes(omega2, omega, shapes), shapes (n x count)
        with unit modal mass. Raises InconsistentError when q is no equilibrium."""
        q, lam = self._rest_arrays(q, lam)
        if count is None:
            count = self.linearize(q, lam, t).N.shape[1]
        count = int(count)
        omega2 = np.zeros(max(count, 1))
        shapes = np.zeros(self.n * max(count, 1))
        self._check(_ffi.ga_modes(self._handle(), float(t), self._dp(q),
                                  None if lam is None else self._dp(lam), count,
                                  self._dp(omega2), self._dp(shapes)))
        w2 = omega2[:count].copy()
        with np.errstate(invalid="ignore"):
            omega = np.where(w2 >= 0.0, np.sqrt(np.abs(w2)), np.nan)
        return Modes(w2, omega, shapes[:self.n * count].reshape((self.n, count), order="F").copy())

    @_serialized
    @_runs_callbacks
    def modes_near(self, q: ArrayLike, lam: Optional[ArrayLike] = None, sigma: float = 0.0,
                   count: int = 6, t: float = 0.0) -> Modes:
        """The `count` undamped modes at an equilibrium (q, lam) whose omega^2 lie nearest
        `sigma`, by shift-invert Lanczos on the solver's (sparse, when patterns are declared)
        factorization (ga_modes_near): Modes(omega2, omega, shapes), omega2 ascending, shapes
        (n x count) with unit modal mass. For large models, where `modes` would be dense."""
        q, lam = self._rest_arrays(q, lam)
        count = int(count)
        omega2 = np.zeros(max(count, 1))
        shapes = np.zeros(self.n * max(count, 1))
        self._check(_ffi.ga_modes_near(self._handle(), float(t), self._dp(q),
                                       None if lam is None else self._dp(lam), float(sigma),
                                       count, self._dp(omega2), self._dp(shapes)))
        w2 = omega2[:count].copy()
        with np.errstate(invalid="ignore"):
            omega = np.where(w2 >= 0.0, np.sqrt(np.abs(w2)), np.nan)
        return Modes(w2, omega, shapes[:self.n * count].reshape((self.n, count), order="F").copy())

    @_serialized
    def info(self, key: int) -> float:
        """A diagnostic of the last step by key (ga_get_info): galpha.GA_INFO_NEWTON_ITERS,
        GA_INFO_NEWTON_RATIO, GA_INFO_RCOND, GA_INFO_ERROR_ESTIMATE, GA_INFO_H_NEXT,
        GA_INFO_VELOCITY_RESIDUAL."""
        x = ctypes.c_double()
        self._check(_ffi.ga_get_info(self._handle(), int(key), ctypes.byref(x)))
        return x.value

    @_serialized
    def get_state(self) -> np.ndarray:
        """Checkpoint: the full state as a flat float array (see ga_get_state)."""
        size = ctypes.c_size_t()
        self._check(_ffi.ga_state_size(self._handle(), ctypes.byref(size)))
        out = np.empty(size.value)
        self._check(_ffi.ga_get_state(self._handle(), self._dp(out), size.value))
        return out

    @_serialized
    def set_state(self, state: ArrayLike) -> None:
        """Restore a checkpoint of get_state (ga_set_state): the run continues bit for bit as
        from where it was taken (also in another solver built the same way)."""
        state = np.ascontiguousarray(state, dtype=float)
        self._check(_ffi.ga_set_state(self._handle(), self._dp(state), state.size))
