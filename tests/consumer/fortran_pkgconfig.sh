#!/bin/sh
# A Fortran program built with nothing but `pkg-config --cflags --libs galpha-fortran` (the
# module from its compiler-specific directory, libgalpha_fortran and, through Requires,
# libgalpha with its rpath), run without LD_LIBRARY_PATH.
set -eu
prefix=$1; src=$2; work=$3; fc=$4; extra=${5:-}
mkdir -p "$work"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha-fortran.pc)")"
flags=$(pkg-config --cflags --libs galpha-fortran)
echo "pkg-config --cflags --libs galpha-fortran: $flags"
case "$flags" in */fortran/*-mod-*) ;; *) echo "no compiler-specific module directory"; exit 1;; esac
cd "$work"
# shellcheck disable=SC2086
"$fc" -Wall -Wno-unused-dummy-argument -Werror $extra "$src" -o consumer_fortran $flags
env -u LD_LIBRARY_PATH ./consumer_fortran
