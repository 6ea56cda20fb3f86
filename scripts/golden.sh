#!/usr/bin/env bash
# The check for a change that must change no result (a move of code, a refactor): the 200
# golden cases of tests/c/test_golden.c, run by COMMIT and by the working tree on this
# machine, hash for hash. The two builds use the same compiler, libm, BLAS and CPU, so that a
# difference is the change's alone.
#
#   scripts/golden.sh [COMMIT]      (default HEAD: what the uncommitted changes change)
#
# Release builds of test_golden only, in build-golden/ (kept: a second call rebuilds little).
set -euo pipefail
cd "$(dirname "$0")/.."
base=${1:-HEAD}
commit=$(git rev-parse --verify "$base^{commit}")
JOBS=$(nproc 2>/dev/null || echo 2)
out=$PWD/build-golden
mkdir -p "$out"
rm -rf "$out/base-src"
git worktree prune
trap 'git worktree remove --force "$out/base-src" >/dev/null 2>&1 || true' EXIT
git worktree add --detach -q "$out/base-src" "$commit"
build() {  # source directory, build directory
    cmake -S "$1" -B "$2" -DCMAKE_BUILD_TYPE=Release -DGALPHA_FORTRAN=OFF \
        -DGALPHA_BUILD_BENCH=OFF >/dev/null
    cmake --build "$2" -j "$JOBS" --target test_golden >/dev/null
}
echo "=== building $(git rev-parse --short "$commit") and the working tree"
build "$out/base-src" "$out/base"
build . "$out/work"
GALPHA_GOLDEN_RECORD="$out/base.inc" "$out/base/tests/c/test_golden" >/dev/null
if GALPHA_GOLDEN_COMPARE="$out/base.inc" "$out/work/tests/c/test_golden" >"$out/compare.log" 2>&1
then
    grep -E "cases, 0 differ" "$out/compare.log"
    echo "golden: the working tree gives $(git rev-parse --short "$commit")'s results, bit for bit"
else
    grep -E "differs|not recorded|cases," "$out/compare.log" || tail -n 20 "$out/compare.log"
    echo "golden: the working tree changes results of $(git rev-parse --short "$commit")" >&2
    exit 1
fi
