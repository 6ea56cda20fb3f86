#!/bin/sh
# Fixture: a fresh install of the build tree into a temporary prefix.
set -eu
build=$1; prefix=$2
rm -rf "$prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
find "$prefix" -type f | sed "s|^$prefix/||" | sort
