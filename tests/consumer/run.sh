#!/bin/sh
# Install galpha into a fresh temporary prefix and build a C program against it with nothing
# but `pkg-config --cflags --libs galpha`, then run it.
set -eu
build=$1; src=$2; work=$3; cc=$4; extra=${5:-}
rm -rf "$work"
mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >"$work/install.log"
pc=$(find "$work/prefix" -name galpha.pc)
export PKG_CONFIG_PATH=$(dirname "$pc")
flags=$(pkg-config --cflags --libs galpha)
libdir=$(pkg-config --variable=libdir galpha)
echo "pkg-config: $flags"
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Wextra -Werror $extra "$src/consumer.c" -o "$work/consumer" $flags -lm \
    -Wl,-rpath,"$libdir"
"$work/consumer"
