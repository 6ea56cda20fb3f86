"""galpha: the generalized-alpha method of Arnold & Bruls for constrained mechanical systems
M(q) q'' = f(q, q', t) - Phi_q^T lambda, Phi(q, t) = 0 -- Python bindings over ctypes.

    import galpha
    with galpha.Solver(n, m, mass, force, constraint, jacobian, rho_inf=0.9) as s:
        s.init(0.0, q0, v0)
        s.step(1e-3)
        print(s.t, s.q, s.lam, s.stats)

or, for time histories, galpha.integrate(...). The low-level mirror of the C API is
galpha._ffi (one function per C function)."""
from . import _ffi
from ._ffi import (GA_DEPENDS_CONSTRAINT, GA_DEPENDS_FORCE, GA_DEPENDS_MASS,  # noqa: F401
                   GA_SENSITIVITY_ADJOINT,  # noqa: F401
                   GA_SENSITIVITY_FORWARD, GA_EVENT_BOTH, GA_EVENT_FALLING, GA_EVENT_RISING,  # noqa: F401
                   GA_INDEX2_STABILIZED, GA_INDEX3, GA_INFO_ERROR_ESTIMATE,  # noqa: F401
                   GA_INFO_H_NEXT, GA_INFO_NEWTON_ITERS, GA_INFO_NEWTON_RATIO, GA_INFO_RCOND,
                   GA_INFO_VELOCITY_RESIDUAL,
                   GA_INIT_PROJECT, GA_INIT_REFUSE, GA_LINEAR_AUTO, GA_LINEAR_DENSE,
                   GA_LINEAR_DENSE_EIGEN, GA_LINEAR_DENSE_LAPACK, GA_LINEAR_DENSE_UNBLOCKED,
                   GA_LINEAR_SPARSE,
                   GA_MATRIX_DAMPING, GA_MATRIX_JACOBIAN, GA_MATRIX_MASS, GA_MATRIX_STIFFNESS,
                   GA_OUTPUT_CONSISTENT, GA_OUTPUT_STEP,
                   GA_PREDICTOR_CONSTANT_A, GA_PREDICTOR_EXTRAPOLATE, GA_PREDICTOR_ZERO,
                   GA_REDUNDANT_DROP, GA_REDUNDANT_REFUSE,
                   GA_REUSE_AUTO, GA_REUSE_NEVER, GA_SPACE_SE3, GA_SPACE_SO3_MATRIX,
                   GA_SPACE_SO3_QUATERNION,
                   GA_SPACE_VECTOR, GA_TANGENT_AUTO, GA_TANGENT_FD,
                   GA_TANGENT_NEGLECT)
from .errors import (ArgumentError, CallbackError, CallbackRetry, ConvergenceError,  # noqa: F401
                     DerivativeError,
                     GalphaError, InconsistentError, InternalError, NonFiniteError,
                     OutOfMemoryError, RecoverableError, SingularMatrixError, StateError,
                     StepSizeError, UnresolvedError)
from .integrate import IntegrateResult, OdeSolution, integrate  # noqa: F401
from .solver import (DampedModes, Equilibrium, EquilibriumY, Linearization,  # noqa: F401
                     Modes, Sensitivity, Solver, StateSpace, StaticPath)
from . import se3, so3  # noqa: F401,E402


def __getattr__(name):
    # galpha.ensemble on first use: `python3 -m galpha.ensemble` must find it not yet imported
    if name == "ensemble":
        import importlib
        return importlib.import_module(".ensemble", __name__)
    raise AttributeError("module 'galpha' has no attribute %r" % name)

__version__ = _ffi.lib.ga_version().decode()
library_path = _ffi.path
