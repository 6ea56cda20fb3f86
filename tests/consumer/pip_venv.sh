#!/bin/sh
# `pip install bindings/python` into a fresh virtual environment (system site packages for
# numpy), then import galpha and run the pendulum against the installed library.
set -eu
python=$1; pkg=$2; work=$3; prefix=$4
rm -rf "$work"
"$python" -m venv --system-site-packages "$work/venv"
"$work/venv/bin/pip" install --disable-pip-version-check --no-input -q "$pkg"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha.pc)")"
unset GALPHA_LIBRARY
cd "$work"
"$work/venv/bin/python" - <<'PY'
import math
import galpha
print("galpha", galpha.__version__, "from", galpha.__file__, "library", galpha.library_path)
assert "/venv/" in galpha.__file__
def mass(t, q, M): M[:] = ((1.0, 0.0), (0.0, 1.0))
def force(t, q, v, f): f[:] = (0.0, -9.81)
def constraint(t, q, phi): phi[0] = 0.5 * (q @ q - 1.0)
def jacobian(t, q, J): J[0, :] = q
sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 1.0),
                       [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0], 1e-3, m=1)
print("pendulum: success", sol.success, "q(1) =", sol.q[-1], "steps", sol.stats["steps"])
assert sol.success and abs(sol.q[-1] @ sol.q[-1] - 1.0) < 1e-12
PY
