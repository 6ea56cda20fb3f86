#!/usr/bin/env bash
# libFuzzer over the C API (tests/fuzz/fuzz_api.c, the sequences of tests/c/api_sequence.h):
# builds galpha with clang, coverage instrumentation, ASan and UBSan in build-fuzz, then
#
#   scripts/fuzz.sh [RUNS]          CI: deterministic. A fixed seed, a fixed number of inputs
#                                   (default 40000, each on the chain and the rotor: 12.6
#                                   minutes in CI's deep run here, docs/perf/test_tiers.csv), no corpus
#                                   reloading, from the committed corpus (tests/fuzz/corpus) and
#                                   findings (tests/fuzz/regressions) into a fresh directory:
#                                   the same inputs on every machine, so that a red run means
#                                   the change, never luck.
#   scripts/fuzz.sh explore SECONDS the longer exploration before a stop (say 1800): a random
#                                   seed, the corpus kept in build-fuzz/corpus.
#   scripts/fuzz.sh merge           the explored corpus minimized into tests/fuzz/corpus (to
#                                   commit with the change that made it).
#
# A finding is written to build-fuzz/crash-* (or leak-, timeout-): replay it with
#   build-fuzz/tests/fuzz_api build-fuzz/crash-...
# and, once fixed, add it to tests/fuzz/regressions/ under a name that says what broke
# (test_api_sequences replays them in every build).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" libcmocka-dev clang libclang-rt-14-dev
mode=${1:-ci}
case "$mode" in
    explore) seconds=${2:?explore SECONDS} ;;
    merge) ;;
    ci) runs=40000 ;;
    *) runs=$mode; mode=ci ;;
esac
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DGALPHA_FUZZ=ON -DGALPHA_SANITIZE=ON -DGALPHA_WERROR=ON -DGALPHA_FORTRAN=OFF \
    -DGALPHA_BUILD_EXAMPLES=OFF -DGALPHA_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 \
    >/dev/null
cmake --build build-fuzz -j "$JOBS" --target fuzz_api >/dev/null
fuzzer=$PWD/build-fuzz/tests/fuzz_api
mkdir -p tests/fuzz/corpus build-fuzz/corpus
# (the timeout is a hang, not a slow machine: the slowest input takes well under a second)
common=(-timeout=60 -max_len=2048 -print_final_stats=1)
case "$mode" in
ci)
    work=$(mktemp -d)
    trap 'rm -rf "$work"' EXIT
    echo "=== libFuzzer: $runs inputs from seed 1 over the C API"
    (cd build-fuzz && "$fuzzer" -seed=1 -runs="$runs" -reload=0 "${common[@]}" \
        "$work" ../tests/fuzz/corpus ../tests/fuzz/regressions 2>fuzz.log) ||
        { tail -n 60 build-fuzz/fuzz.log; exit 1; }
    ;;
explore)
    echo "=== libFuzzer: $seconds s of exploration over the C API"
    (cd build-fuzz && "$fuzzer" -max_total_time="$seconds" "${common[@]}" \
        corpus ../tests/fuzz/corpus ../tests/fuzz/regressions 2>fuzz.log) ||
        { tail -n 60 build-fuzz/fuzz.log; exit 1; }
    ;;
merge)
    merged=$(mktemp -d)
    trap 'rm -rf "$merged"' EXIT
    "$fuzzer" -merge=1 "${common[@]}" "$merged" tests/fuzz/corpus build-fuzz/corpus \
        2>build-fuzz/merge.log
    rm -f tests/fuzz/corpus/*
    cp "$merged"/* tests/fuzz/corpus/
    echo "tests/fuzz/corpus: $(ls tests/fuzz/corpus | wc -l) inputs"
    exit 0
    ;;
esac
grep -E "^stat::(number_of_executed_units|new_units_added)" build-fuzz/fuzz.log
