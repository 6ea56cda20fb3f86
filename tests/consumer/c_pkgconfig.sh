#!/bin/sh
# A C program that knows galpha only through the installed header and `pkg-config galpha`.
set -eu
prefix=$1; src=$2; work=$3; cc=$4; extra=${5:-}
mkdir -p "$work"
export PKG_CONFIG_PATH="$(dirname "$(find "$prefix" -name galpha.pc)")"
flags=$(pkg-config --cflags --libs galpha)
echo "pkg-config --cflags --libs galpha: $flags"
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror $extra "$src" -o "$work/consumer_c" $flags -lm \
    -Wl,-rpath,"$(pkg-config --variable=libdir galpha)"
"$work/consumer_c"
