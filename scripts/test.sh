#!/usr/bin/env bash
# The README's test command: installs what is missing (as root), then builds galpha twice --
# release with warnings as errors, and AddressSanitizer + UndefinedBehaviorSanitizer -- and
# runs the whole ctest suite (C, Python, Fortran, install/consumers, exports) in both, checks
# the ABI against its baseline (scripts/abi.sh), then runs the C suites once more under
# valgrind's memcheck, the threads suite under helgrind, and a seeded libFuzzer run.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}" "${DOCS_PACKAGES[@]}"

# each stage says when it starts, in minutes since the start: CI must stay under 40
stage() { echo "=== [$((SECONDS / 60)) min] $*"; }
common=(-DGALPHA_WERROR=ON -DPython3_EXECUTABLE=/usr/bin/python3 -DGALPHA_REQUIRE_PYTHON=ON
        -DGALPHA_REQUIRE_FORTRAN=ON)
run_suite() {
    local dir=$1; shift
    stage "$dir: $*"
    cmake -S . -B "$dir" "${common[@]}" "$@" >/dev/null
    cmake --build "$dir" -j "$JOBS" >/dev/null
    ctest --test-dir "$dir" --output-on-failure -j "$JOBS"
}
run_suite build -DCMAKE_BUILD_TYPE=Release
# (the benchmarks are compiled, with -Werror, in the release build; the sanitizer build,
# which runs none of them, skips them: a minute of CI)
run_suite build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGALPHA_SANITIZE=ON \
    -DGALPHA_BUILD_BENCH=OFF
# The ABI against its baseline (abi/libgalpha.abi): an incompatible change fails; the
# sanitizer build carries the debug information libabigail reads.
stage "ABI and the version policy"
bash scripts/abi.sh check build-sanitize/libgalpha.so
bash tests/check_version_policy.sh build-sanitize/libgalpha.so
# Valgrind's memcheck on the release build's C suites: reads of uninitialized memory, which the
# sanitizers do not see. (test_alloc and test_alloc_failures replace malloc themselves, so
# memcheck cannot watch them; the accuracy sweeps, test_newton_sweep, test_tolerance and
# test_output_sweep, and test_setup_scaling's 100 000 pendulums run the same code as the other
# suites for minutes, which memcheck would stretch to most of an hour.)
stage "memcheck: C suites of the release build under valgrind"
find build/tests/c -maxdepth 1 -type f -name 'test_*' -perm -u+x ! -name 'test_alloc*' \
    ! -name test_newton_sweep ! -name test_tolerance ! -name test_setup_scaling \
    ! -name test_output_sweep -print0 |
    xargs -0 -P "$JOBS" -I{} sh -c \
        'valgrind --error-exitcode=9 --quiet "$1" >"$1.memcheck.log" 2>&1 ||
         { echo "memcheck FAILED: $1"; tail -n 40 "$1.memcheck.log"; exit 255; }' _ {}
# Helgrind on the suite that runs solvers in parallel threads: data races.
stage "helgrind: build/tests/c/test_threads"
valgrind --tool=helgrind --error-exitcode=9 --quiet build/tests/c/test_threads >/dev/null
# The documentation site: Doxygen and Sphinx with warnings as errors, then the start page and
# the API page in headless Chromium, their screenshots read back.
stage "documentation site"
bash scripts/docs.sh
# The source tarball, the .deb and the wheel, each installed and used (scripts/package.sh).
stage "packages"
DOCS_HTML=$PWD/build-docs/html bash scripts/package.sh
# A deterministic libFuzzer run over the C API (clang, ASan + UBSan; scripts/fuzz.sh): a fixed
# seed and number of inputs from the committed corpus, so that CI's verdict never depends on
# luck; the longer explorations run before a stop (scripts/fuzz.sh explore).
bash scripts/fuzz.sh
echo "all tests passed in $((SECONDS / 60)) min $((SECONDS % 60)) s"
