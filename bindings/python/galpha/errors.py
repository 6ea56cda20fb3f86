"""Exceptions: one class per ga_status, carrying the library's message."""
from . import _ffi


class GalphaError(Exception):
    """A galpha call failed. `status` is the ga_status code, `message` ga_last_error()."""

    status = None

    def __init__(self, message=None, status=None):
        # `raise galpha.CallbackRetry` as Python code raises it: the class says what happened
        if message is None:
            message = (type(self).__doc__ or type(self).__name__).strip().split("\n")[0]
        super().__init__(message)
        if status is not None:
            self.status = status
        self.message = message


class ArgumentError(GalphaError, ValueError):
    """An argument was refused (GA_ERR_ARG): out of range, NaN, a wrong size."""
    status = _ffi.GA_ERR_ARG


class StateError(GalphaError, RuntimeError):
    """A call out of order (GA_ERR_STATE), e.g. a step before init, or on a closed solver."""
    status = _ffi.GA_ERR_STATE


class OutOfMemoryError(GalphaError, MemoryError):
    """The library could not allocate (GA_ERR_NOMEM); nothing changed."""
    status = _ffi.GA_ERR_NOMEM


class CallbackError(GalphaError, RuntimeError):
    """A callback returned a negative value (fatal)."""
    status = _ffi.GA_ERR_CALLBACK


class RecoverableError(GalphaError, RuntimeError):
    """Base of the failures after which the step may be retried, e.g. with a smaller h. The
    solver is still at its last accepted state."""


class CallbackRetry(RecoverableError):
    """A callback asked for a retry (it returned a positive value or raised CallbackRetry)."""
    status = _ffi.GA_ERR_CALLBACK_RETRY


class NonFiniteError(RecoverableError, FloatingPointError):
    """NaN or Inf in a callback's output or the iterates (GA_ERR_NONFINITE)."""
    status = _ffi.GA_ERR_NONFINITE


class SingularMatrixError(RecoverableError, ArithmeticError):
    """The iteration matrix (or a saddle-point system) is singular (GA_ERR_SINGULAR)."""
    status = _ffi.GA_ERR_SINGULAR


class ConvergenceError(RecoverableError):
    """Newton's method did not converge in max_iter iterations."""
    status = _ffi.GA_ERR_NEWTON


class InconsistentError(GalphaError, ValueError):
    """Initial values violate the constraints and projecting was refused, or a point is
    no equilibrium (GA_ERR_INCONSISTENT)."""
    status = _ffi.GA_ERR_INCONSISTENT


class InternalError(GalphaError, RuntimeError):
    """A defect inside galpha (GA_ERR_INTERNAL): please report it with the message."""
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
