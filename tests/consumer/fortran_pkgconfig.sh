#!/bin/sh
# A Fortran program built with nothing but `pkg-config --cflags --libs galpha`.
set -eu
prefix=$1; src=$2; work=$3; fc=$4; extra=${5:-}
mkdir -p "$work"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha.pc)")"
flags=$(pkg-config --cflags --libs galpha)
echo "pkg-config --cflags --libs galpha: $flags"
cd "$work"
# shellcheck disable=SC2086
"$fc" -Wall -Wno-unused-dummy-argument -Werror $extra "$src" -o consumer_fortran $flags \
    -Wl,-rpath,"$(pkg-config --variable=libdir galpha)"
./consumer_fortran
