#!/bin/sh
# A C program that knows galpha only through the installed header and `pkg-config galpha`:
# built with those flags alone and run without LD_LIBRARY_PATH (the prefix is outside the
# system's library directories, so galpha.pc carries the rpath); no Fortran in a C link.
set -eu
prefix=$1; src=$2; work=$3; cc=$4; extra=${5:-}
mkdir -p "$work"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha.pc)")"
flags=$(pkg-config --cflags --libs galpha)
echo "pkg-config --cflags --libs galpha: $flags"
case "$flags" in *fortran*) echo "galpha.pc names the Fortran library"; exit 1;; esac
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror $extra "$src" -o "$work/consumer_c" $flags -lm
# (LAPACK itself may need libgfortran: what counts is what the program links)
if readelf -d "$work/consumer_c" | grep NEEDED | grep -i fortran; then
    echo "a C program links a Fortran library"; exit 1
fi
env -u LD_LIBRARY_PATH "$work/consumer_c"
