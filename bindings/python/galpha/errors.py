"""Exceptions: one class per ga_status, carrying the library's message."""
from . import _ffi


class GalphaError(Exception):
    """A galpha call failed. `status` is the ga_status code, `message` ga_last_error()."""

    status = None

    def __init__(self, message, status=None):
        super().__init__(message)
        if status is not None:
            self.status = status
        self.message = message


class ArgumentError(GalphaError, ValueError):
    status = _ffi.GA_ERR_ARG


class StateError(GalphaError, RuntimeError):
    status = _ffi.GA_ERR_STATE


class OutOfMemoryError(GalphaError, MemoryError):
    status = _ffi.GA_ERR_NOMEM


class CallbackError(GalphaError, RuntimeError):
    """A callback returned a negative value (fatal)."""
    status = _ffi.GA_ERR_CALLBACK


class RecoverableError(GalphaError, RuntimeError):
    """Base of the failures after which the step may be retried, e.g. with a smaller h. The
    solver is still at its last accepted state."""


class CallbackRetry(RecoverableError):
    """A callback returned a positive value: the step was rejected."""
    status = _ffi.GA_ERR_CALLBACK_RETRY


class NonFiniteError(RecoverableError, FloatingPointError):
    status = _ffi.GA_ERR_NONFINITE


class SingularMatrixError(RecoverableError, ArithmeticError):
    status = _ffi.GA_ERR_SINGULAR


class ConvergenceError(RecoverableError):
    """Newton's method did not converge in max_iter iterations."""
    status = _ffi.GA_ERR_NEWTON


class InconsistentError(GalphaError, ValueError):
    status = _ffi.GA_ERR_INCONSISTENT


class InternalError(GalphaError, RuntimeError):
    status = _ffi.GA_ERR_INTERNAL


class StepSizeError(GalphaError, RuntimeError):
    """Adaptive mode: the step size fell below its minimum."""
    status = _ffi.GA_ERR_STEP_SIZE


class UnresolvedError(RecoverableError):
    """Index 3: the step's velocities violate the velocity constraint far beyond O(h^2) -- h is
    too large for the motion (ga_set_resolution_check); retry smaller, or take the stabilized
    index-2 formulation."""
    status = _ffi.GA_ERR_UNRESOLVED


class DerivativeError(GalphaError, ValueError):
    """Solver.check_derivatives: a derivative callback disagrees with central differences (or
    a constraint has a zero gradient); the message names the worst entries."""
    status = _ffi.GA_ERR_DERIVATIVE


_BY_STATUS = {cls.status: cls for cls in (
    ArgumentError, StateError, OutOfMemoryError, CallbackError, CallbackRetry, NonFiniteError,
    SingularMatrixError, ConvergenceError, InconsistentError, InternalError, StepSizeError,
    UnresolvedError, DerivativeError)}


def error_for(status, message):
    """The exception for a ga_status (GalphaError for a status this module does not know)."""
    cls = _BY_STATUS.get(status, GalphaError)
    if not message:
        message = _ffi.ga_strerror(status).decode()
    return cls(message, status)
