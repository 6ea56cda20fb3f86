#!/bin/sh
# The uninstall target removes every file the install wrote (install_manifest.txt) and
# galpha's own directories; nothing of galpha is left in the prefix.
set -eu
build=$1; prefix=$2
cmake --build "$build" --target uninstall >/dev/null
left=$(find "$prefix" -type f | sed "s|^$prefix/||")
if [ -n "$left" ]; then echo "left after uninstall:"; echo "$left"; exit 1; fi
if find "$prefix" -type d | grep galpha; then echo "galpha's directories left"; exit 1; fi
echo "uninstall: nothing left of $(wc -l < "$build/install_manifest.txt") installed files"
