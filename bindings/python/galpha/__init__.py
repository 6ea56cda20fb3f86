"""galpha: the generalized-alpha method for constrained mechanical systems (ctypes bindings)."""
from . import _ffi  # noqa: F401  (loads the library and checks its version)

__version__ = _ffi.lib.ga_version().decode()
