#!/usr/bin/env bash
# The README's test command, in two tiers.
#
#   bash scripts/test.sh          the quick tier: builds galpha twice -- release with warnings
#                                 as errors, and AddressSanitizer + UndefinedBehaviorSanitizer
#                                 -- and runs the whole ctest suite (C, Python, Fortran,
#                                 install/consumers, exports) in both, under whatever BLAS and
#                                 LAPACK the system selects.
#   bash scripts/test.sh --deep   CI (.ci/run): the quick tier with OpenBLAS selected, then the
#                                 ABI against its baseline, the release suite again under every
#                                 other BLAS/LAPACK Debian offers (reference, OpenBLAS serial,
#                                 BLIS), valgrind's memcheck and helgrind, the documentation
#                                 site, the packages, and a seeded libFuzzer run.
#
# Both install what is missing first (as root).
set -euo pipefail
cd "$(dirname "$0")/.."
deep=0
case "${1:-}" in
    "") ;;
    --deep) deep=1 ;;
    *) echo "usage: bash scripts/test.sh [--deep]" >&2; exit 2 ;;
esac
. scripts/deps.sh
if [ "$deep" = 1 ]; then
    ensure_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}" "${DOCS_PACKAGES[@]}" \
        "${BLAS_PACKAGES[@]}"
else
    ensure_packages "${BUILD_PACKAGES[@]}" "${TEST_PACKAGES[@]}"
fi

# each stage says when it starts, in minutes since the start: the quick tier must stay under
# 10 (the README says how long it takes), the deep one under CI's 60
stage() { echo "=== [$((SECONDS / 60)) min $((SECONDS % 60)) s] $*"; }
common=(-DGALPHA_WERROR=ON -DPython3_EXECUTABLE=/usr/bin/python3 -DGALPHA_REQUIRE_PYTHON=ON
        -DGALPHA_REQUIRE_FORTRAN=ON)
build_only() {
    local dir=$1; shift
    cmake -S . -B "$dir" "${common[@]}" "$@" >/dev/null
    cmake --build "$dir" -j "$JOBS" >/dev/null
}
# The deep tier selects each BLAS/LAPACK in turn with update-alternatives, and gives the
# system back its own selection however the run ends.
multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)
alternative() { echo "lib$1.so.3-$multiarch"; }
selected() { update-alternatives --query "$(alternative "$1")" | sed -n 's/^Value: //p'; }
mode_of() { update-alternatives --query "$(alternative "$1")" | sed -n 's/^Status: //p'; }
restore_blas() {
    for lib in blas lapack; do
        if [ "${saved_mode[$lib]}" = auto ]; then
            update-alternatives --quiet --auto "$(alternative "$lib")"
        else
            update-alternatives --quiet --set "$(alternative "$lib")" "${saved_value[$lib]}"
        fi
    done
}
# select DIR: the BLAS in DIR, with its own LAPACK if it has one (OpenBLAS), else the reference
select_blas() {
    local dir=$1 lapack
    update-alternatives --quiet --set "$(alternative blas)" "$dir/libblas.so.3"
    lapack=$dir/liblapack.so.3
    [ -e "$lapack" ] || lapack=/usr/lib/$multiarch/lapack/liblapack.so.3
    update-alternatives --quiet --set "$(alternative lapack)" "$lapack"
}
if [ "$deep" = 1 ]; then
    [ "$(id -u)" -eq 0 ] || { echo "the deep tier selects BLAS builds: run it as root" >&2; exit 1; }
    declare -A saved_mode saved_value
    for lib in blas lapack; do
        saved_mode[$lib]=$(mode_of "$lib")
        saved_value[$lib]=$(selected "$lib")
    done
    trap restore_blas EXIT
    select_blas "/usr/lib/$multiarch/openblas-pthread"
fi
echo "BLAS: $(readlink -f "/usr/lib/$multiarch/libblas.so.3"), LAPACK: $(readlink -f \
    "/usr/lib/$multiarch/liblapack.so.3"); python3 on PATH: $(command -v python3 || echo none)"

stage "build: release"
build_only build -DCMAKE_BUILD_TYPE=Release
# The release suite runs while the sanitizer build compiles: the suite's last minute is one
# long test on one core, the build fills the other. Its report follows once both are done.
stage "build: release suite, while build-sanitize compiles"
ctest --test-dir build --output-on-failure -j "$JOBS" >build/ctest.log 2>&1 &
release_suite=$!
# -O1 -g1: UBSan's checks make the optimizer the build's cost (at -O2 -g: 6 min of build and
# 4.6 min of tests here; at -O1 -g1: 3 and 5, docs/design-notes.md). The benchmarks, which
# this build runs none of, are compiled (-Werror) in the release build.
build_status=0
build_only build-sanitize -DCMAKE_BUILD_TYPE=RelWithDebInfo -DGALPHA_SANITIZE=ON \
    -DGALPHA_BUILD_BENCH=OFF -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1" \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_Fortran_FLAGS_RELWITHDEBINFO="-O1 -g1" ||
    build_status=$?
suite_status=0
wait "$release_suite" || suite_status=$?
cat build/ctest.log
[ "$suite_status" = 0 ] || { echo "the release suite failed"; exit 1; }
[ "$build_status" = 0 ] || { echo "the sanitizer build failed"; exit 1; }
stage "build-sanitize: the suite under ASan + UBSan"
ctest --test-dir build-sanitize --output-on-failure -j "$JOBS"
if [ "$deep" = 0 ]; then
    echo "all tests passed in $((SECONDS / 60)) min $((SECONDS % 60)) s (the deep tier: --deep)"
    exit 0
fi

# The ABI against its baseline (abi/libgalpha.abi): an incompatible change fails. libabigail
# reads the types from full debug information: the library alone, unoptimized.
stage "ABI and the version policy"
build_only build-abi -DCMAKE_BUILD_TYPE=Debug -DGALPHA_BUILD_TESTS=OFF \
    -DGALPHA_BUILD_EXAMPLES=OFF -DGALPHA_BUILD_BENCH=OFF -DGALPHA_FORTRAN=OFF \
    -DGALPHA_REQUIRE_FORTRAN=OFF
bash scripts/abi.sh check build-abi/libgalpha.so
bash tests/check_version_policy.sh build-abi/libgalpha.so
# The release suite under every other BLAS/LAPACK installed (the quick tier ran it under
# OpenBLAS): no result may depend on which one the user has.
for blas in $(update-alternatives --list "$(alternative blas)"); do
    dir=$(dirname "$blas")
    [ "$dir" != "/usr/lib/$multiarch/openblas-pthread" ] || continue
    select_blas "$dir"
    stage "build: release suite under $(selected blas) and $(selected lapack)"
    ctest --test-dir build --output-on-failure -j "$JOBS"
done
restore_blas
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
stage "seeded libFuzzer run"
bash scripts/fuzz.sh
echo "all tests passed in $((SECONDS / 60)) min $((SECONDS % 60)) s"
