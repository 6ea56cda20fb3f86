#!/usr/bin/env bash
# libFuzzer over the C API (tests/fuzz/fuzz_api.c): builds galpha with clang, coverage
# instrumentation, ASan and UBSan in build-fuzz, then fuzzes for SECONDS (default 120) from
# the committed findings (tests/fuzz/regressions) and a corpus kept in build-fuzz/corpus.
# A new finding is written to build-fuzz/crash-*: replay it with
#   build-fuzz/tests/fuzz_api build-fuzz/crash-...
# and, once fixed, add it to tests/fuzz/regressions/ under a name that says what broke
# (test_api_sequences replays them in every build).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" libcmocka-dev clang libclang-rt-14-dev
seconds=${1:-120}
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DGALPHA_FUZZ=ON -DGALPHA_SANITIZE=ON -DGALPHA_WERROR=ON -DGALPHA_FORTRAN=OFF \
    -DGALPHA_BUILD_EXAMPLES=OFF -DGALPHA_BUILD_BENCH=OFF -DPython3_EXECUTABLE=/usr/bin/python3 \
    >/dev/null
cmake --build build-fuzz -j "$JOBS" --target fuzz_api >/dev/null
mkdir -p build-fuzz/corpus
cd build-fuzz
echo "=== libFuzzer: ${seconds} s over the C API"
./tests/fuzz_api -max_total_time="$seconds" -timeout=10 -max_len=2048 -print_final_stats=1 \
    corpus ../tests/fuzz/regressions 2>fuzz.log || { tail -n 60 fuzz.log; exit 1; }
grep -E "^stat::(number_of_executed_units|new_units_added)" fuzz.log
