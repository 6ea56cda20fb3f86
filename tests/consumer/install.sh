#!/bin/sh
# Fixture: a fresh install of the build tree into a prefix that already holds another
# package's files and folders (beside galpha's own in lib/pkgconfig, include, share/doc and the
# Python directory), inside folders named galpha: uninstall.sh checks that the uninstall
# leaves exactly this listing behind.
set -eu
build=$1; prefix=$2; pydir=$3
top=$(dirname "$prefix")
rm -rf "$top"
mkdir -p "$prefix/lib/pkgconfig" "$prefix/include" "$prefix/share/doc/bystander" \
    "$prefix/$pydir/bystander" "$prefix/share/empty-bystander" "$top/empty-sibling"
echo "Name: bystander" >"$prefix/lib/pkgconfig/bystander.pc"
echo "/* another package */" >"$prefix/include/bystander.h"
echo "another package" >"$prefix/share/doc/bystander/README"
: >"$prefix/$pydir/bystander/__init__.py"
find "$top" | sort >"$build/tests/prefix_before_install.txt"
cmake --install "$build" --prefix "$prefix" >/dev/null
find "$prefix" -type f | sed "s|^$prefix/||" | sort
