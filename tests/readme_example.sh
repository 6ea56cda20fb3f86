#!/bin/sh
# The C program in README.md compiles against the header and library and runs.
set -eu
readme=$1; include=$2; libdir=$3; work=$4; cc=$5; extra=${6:-}
mkdir -p "$work"
awk '/^```c$/{on=1; next} /^```$/{on=0} on' "$readme" > "$work/readme_example.c"
# shellcheck disable=SC2086
"$cc" -std=c99 -Wall -Werror $extra "$work/readme_example.c" -I"$include" -L"$libdir" -lgalpha \
    -Wl,-rpath,"$libdir" -o "$work/readme_example"
"$work/readme_example"
