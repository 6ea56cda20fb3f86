"""Low-level ctypes declarations of libgalpha: one Python name per C function, same arguments.

The library is looked for, in order, at
  1. the path in the environment variable GALPHA_LIBRARY,
  2. the library a wheel carries in this package (galpha/_libs, listed by galpha/_bundled.py),
  3. the library installed with this package by `cmake --install` (galpha/_install.py),
  4. the installed library (pkg-config's libdir for galpha, then ctypes.util.find_library),
  5. the build tree next to this source tree (build*/libgalpha.so*).
"""
import ctypes
import ctypes.util
import glob
import os
import subprocess

c_double_p = ctypes.POINTER(ctypes.c_double)

# Must match GA_VERSION_MAJOR of the header these declarations were written for.
ABI_MAJOR = 0


def _candidates():
    """(where, path) to try; path None: that place has nothing (said in the error)."""
    env = os.environ.get("GALPHA_LIBRARY")
    if env:
        yield "environment variable GALPHA_LIBRARY", env
        return
    yield "environment variable GALPHA_LIBRARY", None
    here = os.path.dirname(os.path.abspath(__file__))
    try:  # a wheel's: the library and what it needs, in load order
        from ._bundled import LIBRARIES
    except ImportError:
        yield "this package's own copy (a wheel that carries the library)", None
    else:
        try:
            yield "this package's own copy (a wheel)", _load_bundled(here, LIBRARIES)
        except OSError as e:
            yield "this package's own copy (a wheel): %s" % e, None
    try:  # written by `cmake --install` next to this file: where the library went
        from ._install import LIBDIR_FROM_PACKAGE
        yield "install tree", os.path.normpath(os.path.join(
            here, LIBDIR_FROM_PACKAGE, "libgalpha.so.%d" % ABI_MAJOR))
    except ImportError:
        yield "install tree (a package installed by cmake --install)", None
    try:
        libdir = subprocess.run(["pkg-config", "--variable=libdir", "galpha"], check=True,
                                capture_output=True, text=True).stdout.strip()
        if libdir:
            yield "pkg-config libdir", os.path.join(libdir, "libgalpha.so.%d" % ABI_MAJOR)
    except (OSError, subprocess.CalledProcessError):
        yield "pkg-config galpha (is PKG_CONFIG_PATH set for the install prefix?)", None
    found = ctypes.util.find_library("galpha")
    if found:
        yield "ctypes.util.find_library", found
    else:
        yield "ctypes.util.find_library('galpha') (the linker's paths; run ldconfig after " \
              "installing to /usr/local)", None
    root = os.path.normpath(os.path.join(here, "..", "..", ".."))
    builds = sorted(glob.glob(os.path.join(root, "build*", "libgalpha.so.%d" % ABI_MAJOR)),
                    key=lambda p: (os.path.basename(os.path.dirname(p)) != "build", p))
    asan_loaded = "libasan" in os.environ.get("LD_PRELOAD", "")
    if not builds:
        yield "build trees next to this source tree (%s/build*)" % root, None
    for path in builds:
        # a sanitizer build aborts a process that did not preload its runtime: skip it
        if not asan_loaded and _needs_asan(path):
            yield "build tree %s (a sanitizer build: skipped)" % path, None
            continue
        yield "build tree", path


def _load_bundled(here, libraries):
    """Loads the dependencies a wheel carries (each unless a library of that name is in the
    process already, as libgomp may be through numpy: one copy of a runtime), so that
    libgalpha's own load finds them by name; the path of libgalpha."""
    try:
        with open("/proc/self/maps") as f:
            loaded = {os.path.basename(line.split()[-1]) for line in f if "/" in line}
    except OSError:
        loaded = set()
    for name in libraries[:-1]:
        if not any(x.startswith(name) for x in loaded):
            ctypes.CDLL(os.path.join(here, "_libs", name))
    return os.path.join(here, "_libs", libraries[-1])


def _needs_asan(path):
    try:
        with open(path, "rb") as f:
            return b"libasan.so" in f.read()
    except OSError:
        return False


def load():
    tried = []
    for where, path in _candidates():
        if path is None:
            tried.append("%s: nothing" % where)
            continue
        try:
            return ctypes.CDLL(path), path
        except OSError as e:
            tried.append("%s: %s (%s)" % (where, path, e))
    raise OSError("libgalpha not found; looked at:\n  " + "\n  ".join(tried) +
                  "\nSet GALPHA_LIBRARY to the full path of libgalpha.so.%d." % ABI_MAJOR)


lib, path = load()

# Callback types (void *user last; ctypes passes it through untouched).
MASS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, ctypes.c_void_p)
FORCE_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                            ctypes.c_void_p)
CONSTRAINT_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p,
                                 ctypes.c_void_p)
JACOBIAN_FN = CONSTRAINT_FN
STIFFNESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                                c_double_p, c_double_p, ctypes.c_void_p)
DAMPING_FN = FORCE_FN
CONSTRAINT_ACCEL_FN = FORCE_FN
EVENT_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                            c_double_p, ctypes.c_void_p)
FORCE_Y_FN = EVENT_FN  # (t, q, v, y, f, user)
RATE_FN = EVENT_FN     # (t, q, v, y, ydot, user)
EVENT_Y_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                              c_double_p, c_double_p, ctypes.c_void_p)
FORCE_P_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, ctypes.c_int,
                              c_double_p, ctypes.c_void_p)  # (t, q, v, j, f_p, user)
MASS_P_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, ctypes.c_int, c_double_p,
                             c_double_p, ctypes.c_void_p)   # (t, q, j, a, out, user)
CONSTRAINT_P_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, ctypes.c_int,
                                   c_double_p, c_double_p, c_double_p, ctypes.c_void_p)
COST_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                           c_double_p, c_double_p, c_double_p, c_double_p, c_double_p,
                           c_double_p, c_double_p, ctypes.c_void_p)
STEP_HOOK_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, c_double_p,
                                c_double_p, c_double_p, ctypes.c_void_p)  # (s, t, q, v, lam, user)
PATH_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p,
                           ctypes.c_void_p)  # (load, q, lam, user)
COUPLING_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, c_double_p, c_double_p, c_double_p,
                               c_double_p, c_double_p, c_double_p, c_double_p, ctypes.c_void_p)

# Status codes (pinned in galpha.h).
GA_OK = 0
GA_ERR_ARG = -1
GA_ERR_STATE = -2
GA_ERR_NOMEM = -3
GA_ERR_CALLBACK = -4
GA_ERR_CALLBACK_RETRY = -5
GA_ERR_NONFINITE = -6
GA_ERR_SINGULAR = -7
GA_ERR_NEWTON = -8
GA_ERR_INCONSISTENT = -9
GA_ERR_INTERNAL = -10
GA_ERR_STEP_SIZE = -11
GA_ERR_UNRESOLVED = -12
GA_ERR_DERIVATIVE = -13
GA_EVENT = 1  # not an error: a stepping call stopped at an event
GA_STOPPED = 2  # not an error: the step hook asked to stop

# Sensitivity dependence flags (ga_depends).
GA_DEPENDS_FORCE = 1
GA_DEPENDS_MASS = 2
GA_DEPENDS_RATE = 4
GA_DEPENDS_CONSTRAINT = 8
GA_SENSITIVITY_FORWARD = 1
GA_SENSITIVITY_ADJOINT = 2

# Enumerations.
GA_TANGENT_AUTO, GA_TANGENT_FD, GA_TANGENT_NEGLECT = 0, 1, 2
GA_PREDICTOR_CONSTANT_A, GA_PREDICTOR_ZERO, GA_PREDICTOR_EXTRAPOLATE = 0, 1, 2
GA_REUSE_AUTO, GA_REUSE_NEVER = 0, 1
GA_MATRIX_MASS, GA_MATRIX_JACOBIAN, GA_MATRIX_STIFFNESS, GA_MATRIX_DAMPING = 0, 1, 2, 3
(GA_LINEAR_AUTO, GA_LINEAR_DENSE, GA_LINEAR_SPARSE, GA_LINEAR_DENSE_LAPACK,
 GA_LINEAR_DENSE_EIGEN, GA_LINEAR_DENSE_UNBLOCKED) = 0, 1, 2, 3, 4, 5
GA_INDEX3, GA_INDEX2_STABILIZED = 0, 1
GA_SPACE_VECTOR, GA_SPACE_SO3_QUATERNION, GA_SPACE_SO3_MATRIX, GA_SPACE_SE3 = 0, 1, 2, 3
GA_REDUNDANT_REFUSE, GA_REDUNDANT_DROP = 0, 1
GA_INIT_PROJECT, GA_INIT_REFUSE = 0, 1
GA_OUTPUT_CONSISTENT, GA_OUTPUT_STEP = 0, 1
GA_EVENT_BOTH, GA_EVENT_RISING, GA_EVENT_FALLING = 0, 1, -1
GA_EVENT_LOG = 64
GA_COUPLING_G_Q, GA_COUPLING_G_V = 0, 1
(GA_INFO_RCOND, GA_INFO_NEWTON_ITERS, GA_INFO_NEWTON_RATIO, GA_INFO_ERROR_ESTIMATE,
 GA_INFO_H_NEXT, GA_INFO_VELOCITY_RESIDUAL) = 0, 1, 2, 3, 4, 5
COUNTERS = ("steps", "failed_steps", "newton_iters", "factorizations", "residuals",
            "mass_evals", "force_evals", "constraint_evals", "jacobian_evals",
            "stiffness_evals", "damping_evals", "accel_evals", "rejected_steps",
            "constraint_dt_evals", "event_evals", "rate_evals", "coupling_evals")

_S = ctypes.c_void_p  # ga_solver *
_I = ctypes.c_int
_D = ctypes.c_double
_P = ctypes.POINTER

_SIGNATURES = {
    "ga_version": (ctypes.c_char_p, []),
    "ga_version_number": (_I, []),
    "ga_strerror": (ctypes.c_char_p, [_I]),
    "ga_last_error": (ctypes.c_char_p, [_S]),
    "ga_create": (_I, [_I, _I, _P(_S)]),
    "ga_create_space": (_I, [_I, _P(_I), _P(_I), _I, _P(_S)]),
    "ga_get_space_size": (_I, [_S, _P(_I), _P(_I)]),
    "ga_free": (None, [_S]),
    "ga_get_size": (_I, [_S, _P(_I), _P(_I)]),
    "ga_set_callbacks": (_I, [_S, MASS_FN, FORCE_FN, CONSTRAINT_FN, JACOBIAN_FN, ctypes.c_void_p]),
    "ga_set_tangents": (_I, [_S, STIFFNESS_FN, DAMPING_FN]),
    "ga_set_tangent_mode": (_I, [_S, _I]),
    "ga_set_constraint_accel": (_I, [_S, CONSTRAINT_ACCEL_FN]),
    "ga_set_constraint_dt": (_I, [_S, CONSTRAINT_FN]),
    "ga_set_rho_inf": (_I, [_S, _D]),
    "ga_set_params": (_I, [_S, _D, _D, _D, _D]),
    "ga_get_params": (_I, [_S, _P(_D), _P(_D), _P(_D), _P(_D)]),
    "ga_set_newton": (_I, [_S, _D, _I]),
    "ga_set_scaling": (_I, [_S, _I]),
    "ga_set_predictor": (_I, [_S, _I]),
    "ga_set_init_mode": (_I, [_S, _I, _D]),
    "ga_init": (_I, [_S, _D, c_double_p, c_double_p]),
    "ga_step": (_I, [_S, _D]),
    "ga_get_t": (_I, [_S, _P(_D)]),
    "ga_get_h_last": (_I, [_S, _P(_D)]),
    "ga_get_q": (_I, [_S, c_double_p]),
    "ga_get_v": (_I, [_S, c_double_p]),
    "ga_get_qdd": (_I, [_S, c_double_p]),
    "ga_get_lambda": (_I, [_S, c_double_p]),
    "ga_get_a": (_I, [_S, c_double_p]),
    "ga_state_size": (_I, [_S, _P(ctypes.c_size_t)]),
    "ga_get_state": (_I, [_S, c_double_p, ctypes.c_size_t]),
    "ga_set_state": (_I, [_S, c_double_p, ctypes.c_size_t]),
    "ga_get_counter": (_I, [_S, _I, _P(ctypes.c_longlong)]),
    "ga_reset_counters": (_I, [_S]),
    "ga_get_info": (_I, [_S, _I, _P(_D)]),
    "ga_check_derivatives": (_I, [_S, _D, c_double_p, c_double_p, c_double_p, c_double_p,
                             c_double_p, _D, _P(_D)]),
    "ga_static_equilibrium": (_I, [_S, _D, c_double_p, c_double_p, _D, _I]),
    "ga_linearize": (_I, [_S, _D, c_double_p, c_double_p, _I, _P(_I), c_double_p, c_double_p,
                          c_double_p, c_double_p]),
    "ga_modes": (_I, [_S, _D, c_double_p, c_double_p, _I, c_double_p, c_double_p]),
    "ga_static_equilibrium_y": (_I, [_S, _D, c_double_p, c_double_p, c_double_p, _D, _I]),
    "ga_state_space": (_I, [_S, _D, c_double_p, c_double_p, c_double_p, _I, _P(_I), c_double_p,
                            c_double_p]),
    "ga_state_space_motion": (_I, [_S, _D, c_double_p, c_double_p, c_double_p, _I, _P(_I),
                                   c_double_p, c_double_p]),
    "ga_modes_near": (_I, [_S, _D, c_double_p, c_double_p, _D, _I, c_double_p, c_double_p]),
    "ga_modes_damped": (_I, [_S, _D, c_double_p, c_double_p, _I, c_double_p, c_double_p,
                             c_double_p, c_double_p]),
    "ga_static_path": (_I, [_S, _D, c_double_p, c_double_p, c_double_p, _D, _I, _D, PATH_FN,
                            ctypes.c_void_p]),
    "ga_set_jacobian_reuse": (_I, [_S, _I]),
    "ga_set_constant_mass": (_I, [_S, _I]),
    "ga_set_pattern": (_I, [_S, _I, _I, _P(_I), _P(_I)]),
    "ga_set_pattern_csc": (_I, [_S, _I, _P(_I), _P(_I)]),
    "ga_set_linear_solver": (_I, [_S, _I]),
    "ga_linear_solver_name": (ctypes.c_char_p, [_S]),
    "ga_set_formulation": (_I, [_S, _I]),
    "ga_set_resolution_check": (_I, [_S, _D]),
    "ga_set_redundant_constraints": (_I, [_S, _I]),
    "ga_get_active_constraints": (_I, [_S, _P(_I)]),
    "ga_set_rescale": (_I, [_S, _I]),
    "ga_set_corrected_start": (_I, [_S, _I]),
    "ga_set_tolerances": (_I, [_S, _D, _D]),
    "ga_set_tolerances_vector": (_I, [_S, _D, c_double_p]),
    "ga_set_step_limits": (_I, [_S, _D, _D]),
    "ga_set_initial_step": (_I, [_S, _D]),
    "ga_step_adaptive": (_I, [_S, _D]),
    "ga_advance": (_I, [_S, _D]),
    "ga_interpolate": (_I, [_S, _D, c_double_p, c_double_p, c_double_p]),
    "ga_interpolate_qdd": (_I, [_S, _D, c_double_p]),
    "ga_set_output": (_I, [_S, _I]),
    "ga_set_events": (_I, [_S, _I, EVENT_FN, _P(_I), _P(_I), _I]),
    "ga_set_step_hook": (_I, [_S, STEP_HOOK_FN, ctypes.c_void_p, _I]),
    "ga_get_event_count": (_I, [_S, _P(_I)]),
    "ga_get_event": (_I, [_S, _I, _P(_D), _P(_I), _P(_I)]),
    "ga_set_first_order": (_I, [_S, _I, FORCE_Y_FN, RATE_FN]),
    "ga_set_coupling": (_I, [_S, COUPLING_FN]),
    "ga_set_coupling_exact": (_I, [_S, _I]),
    "ga_init_y": (_I, [_S, _D, c_double_p, c_double_p, c_double_p]),
    "ga_get_y": (_I, [_S, c_double_p, c_double_p]),
    "ga_interpolate_y": (_I, [_S, _D, c_double_p, c_double_p]),
    "ga_set_events_y": (_I, [_S, _I, EVENT_Y_FN, _P(_I), _P(_I), _I]),
    "ga_set_coupling_pattern": (_I, [_S, _I, _I, _P(_I), _P(_I)]),
    "ga_set_sensitivity": (_I, [_S, _I, c_double_p, c_double_p, _I]),
    "ga_set_parameter_derivatives": (_I, [_S, FORCE_P_FN, MASS_P_FN]),
    "ga_set_constraint_parameter_derivative": (_I, [_S, CONSTRAINT_P_FN]),
    "ga_set_sensitivity_start": (_I, [_S, _I, c_double_p, c_double_p]),
    "ga_get_sensitivity": (_I, [_S, _I, c_double_p, c_double_p, c_double_p, c_double_p]),
    "ga_get_sensitivity_y": (_I, [_S, _I, c_double_p, c_double_p]),
    "ga_set_sensitivity_method": (_I, [_S, _I, ctypes.c_long]),
    "ga_set_adjoint_checkpoints": (_I, [_S, ctypes.c_long, ctypes.c_long]),
    "ga_adjoint_gradient": (_I, [_S, COST_FN, COST_FN, c_double_p, c_double_p]),
    "ga_so3_exp": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_so3_log": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_so3_compose": (_I, [ctypes.c_long, c_double_p, c_double_p, c_double_p]),
    "ga_so3_matrix": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_so3_tangent": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_so3_tangent_inverse": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_se3_exp": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_se3_log": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_se3_compose": (_I, [ctypes.c_long, c_double_p, c_double_p, c_double_p]),
    "ga_se3_tangent": (_I, [ctypes.c_long, c_double_p, c_double_p]),
    "ga_se3_tangent_inverse": (_I, [ctypes.c_long, c_double_p, c_double_p]),
}

for _name, (_restype, _argtypes) in _SIGNATURES.items():
    _f = getattr(lib, _name)
    _f.restype = _restype
    _f.argtypes = _argtypes
    globals()[_name] = _f

_major = lib.ga_version_number() // 10000
if _major != ABI_MAJOR:
    raise ImportError("%s is galpha %s; these bindings need ABI major %d"
                      % (path, lib.ga_version().decode(), ABI_MAJOR))
