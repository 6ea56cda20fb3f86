#!/usr/bin/env bash
# The README's test command: installs what is missing (as root), then builds galpha twice --
# release with warnings as errors, and AddressSanitizer + UndefinedBehaviorSanitizer -- and
# runs the whole ctest suite (C, Python, Fortran, install/consumers, ABI) in both.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}"

common=(-DGALPHA_WERROR=ON -DPython3_EXECUTABLE=/usr/bin/python3 -DGALPHA_REQUIRE_PYTHON=ON
        -DGALPHA_REQUIRE_FORTRAN=ON)
run_suite() {
    local dir=$1; shift
    echo "=== $dir: $*"
    cmake -S . -B "$dir" "${common[@]}" "$@" >/dev/null
    cmake --build "$dir" -j "$JOBS" >/dev/null
    ctest --test-dir "$dir" --output-on-failure -j "$JOBS"
}
run_suite build -DCMAKE_BUILD_TYPE=Release
run_suite build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGALPHA_SANITIZE=ON
echo "all tests passed"
