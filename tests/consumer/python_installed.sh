#!/bin/sh
# The installed Python package: its modules are byte for byte those of the source tree (plus
# _install.py, the note of where the library is), so what an install can get wrong is how
# the package finds its library and how the processes it starts find the package. The suites
# that load the library (test_solver, test_pendulum), compile callbacks against it
# (test_compiled), and start processes, MPI ranks and a dask cluster (test_ensemble's) run
# on it; the rest of the Python suite runs once, in python.build_tree.
set -eu
python=$1; source=$2; installed=$3; tests=$4
for f in "$source"/*.py "$source"/py.typed; do
    cmp "$f" "$installed/$(basename "$f")"
done
listing=$(mktemp)
ls "$installed" | sort >"$listing"
extra=$( (ls "$source"; echo _install.py; echo __pycache__) | sort -u | comm -13 - "$listing")
rm -f "$listing"
if [ -n "$extra" ]; then
    echo "installed but not in the source package: $extra"
    exit 1
fi
cd "$(dirname "$installed")"
exec "$python" -m pytest -q -p no:cacheprovider "$tests/test_solver.py" "$tests/test_pendulum.py" \
    "$tests/test_compiled.py" "$tests/test_ensemble.py" \
    -k "not test_ensemble or processes or mpi or dask or example"
