#!/bin/sh
# `pip install bindings/python` and `pip install -e bindings/python` into fresh virtual
# environments (system site packages for numpy), then import galpha and run the pendulum
# against the installed library: from the venv's copy, and from the source tree.
set -eu
python=$1; pkg=$2; work=$3; prefix=$4
rm -rf "$work"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha.pc)")"
unset GALPHA_LIBRARY
# the pure-Python package over the installed library (the wheel that carries the library is
# scripts/package.sh's)
export GALPHA_WHEEL_LIBRARY=none
for mode in copy editable; do
"$python" -m venv --system-site-packages "$work/$mode"
if [ $mode = copy ]; then
    "$work/$mode/bin/pip" install --disable-pip-version-check --no-input -q "$pkg"
    expect="$work/$mode/"
else
    "$work/$mode/bin/pip" install --disable-pip-version-check --no-input -q -e "$pkg"
    expect="$(cd "$pkg" && pwd)/galpha/"
fi
cd "$work"
EXPECT="$expect" "$work/$mode/bin/python" - <<'PY'
import math, os
import galpha
print("galpha", galpha.__version__, "from", galpha.__file__, "library", galpha.library_path)
assert galpha.__file__.startswith(os.environ["EXPECT"]), galpha.__file__
def mass(t, q, M): M[:] = ((1.0, 0.0), (0.0, 1.0))
def force(t, q, v, f): f[:] = (0.0, -9.81)
def constraint(t, q, phi): phi[0] = 0.5 * (q @ q - 1.0)
def jacobian(t, q, J): J[0, :] = q
sol = galpha.integrate(mass, force, constraint, jacobian, (0.0, 1.0),
                       [math.sin(1.0), -math.cos(1.0)], [0.0, 0.0], 1e-3, m=1)
print("pendulum: success", sol.success, "q(1) =", sol.q[-1], "steps", sol.stats["steps"])
assert sol.success and abs(sol.q[-1] @ sol.q[-1] - 1.0) < 1e-12
PY
done
