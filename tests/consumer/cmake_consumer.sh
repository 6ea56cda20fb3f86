#!/bin/sh
# A CMake project that uses find_package(galpha): shared, static and (if built) Fortran.
set -eu
prefix=$1; src=$2; work=$3; extra=${4:-}
rm -rf "$work"
cmake -S "$src" -B "$work" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_FLAGS="$extra" -DCMAKE_Fortran_FLAGS="$extra" \
    -DCMAKE_EXE_LINKER_FLAGS="$extra" >"$work.log" 2>&1 || { cat "$work.log"; exit 1; }
cmake --build "$work" >>"$work.log" 2>&1 || { cat "$work.log"; exit 1; }
for exe in "$work"/consumer_*; do
    echo "== $(basename "$exe")"
    "$exe"
done
