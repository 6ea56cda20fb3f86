#!/usr/bin/env bash
# The version, said once for each place that states it: CMakeLists.txt (project), the header's
# GA_VERSION_* macros, the Python package (pyproject.toml, its build backend) and the newest
# release heading of CHANGELOG.md must agree. Prints it; exits 1, naming each, when they do not.
# (ctest runs it as release.versions_agree; scripts/abi.sh compares it with the ABI's.)
set -euo pipefail
cd "$(dirname "$0")/.."
cmake=$(sed -n 's/^project(galpha VERSION \([0-9.]*\).*/\1/p' CMakeLists.txt)
header=$(awk '/#define GA_VERSION_MAJOR/{a=$3} /#define GA_VERSION_MINOR/{b=$3}
              /#define GA_VERSION_PATCH/{c=$3} END{print a "." b "." c}' include/galpha.h)
pyproject=$(sed -n 's/^version = "\([0-9.]*\)"/\1/p' bindings/python/pyproject.toml)
backend=$(sed -n 's/^VERSION = "\([0-9.]*\)"/\1/p' bindings/python/_build/galpha_build.py)
changelog=$(sed -n 's/^## \[\([0-9][0-9.]*\)\].*/\1/p' CHANGELOG.md | head -n 1)
bad=0
for pair in "include/galpha.h:$header" "bindings/python/pyproject.toml:$pyproject" \
            "bindings/python/_build/galpha_build.py:$backend" "CHANGELOG.md:$changelog"; do
    if [ "${pair##*:}" != "$cmake" ]; then
        echo "version: ${pair%%:*} says '${pair##*:}', CMakeLists.txt says '$cmake'" >&2
        bad=1
    fi
done
[ $bad -eq 0 ] || exit 1
echo "$cmake"
