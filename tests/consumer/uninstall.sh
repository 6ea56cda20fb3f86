#!/bin/sh
# The uninstall target removes every file the install wrote (install_manifest.txt) and the
# folders it created, and nothing else: the folder around the prefix (named galpha, as a
# clone or the release tarball's folder may be) lists exactly what it did before the install.
# Then the same for an install into a prefix that did not exist: it is gone afterwards.
set -eu
build=$1; prefix=$2
top=$(dirname "$prefix")
installed=$(wc -l <"$build/install_manifest.txt")
cmake --build "$build" --target uninstall >/dev/null
find "$top" | sort >"$build/tests/prefix_after_uninstall.txt"
if ! diff "$build/tests/prefix_before_install.txt" "$build/tests/prefix_after_uninstall.txt"
then
    echo "the uninstall did not give back the prefix as it was before the install (< before, > after)"
    exit 1
fi
fresh=$top/galpha-new/prefix
cmake --install "$build" --prefix "$fresh" >/dev/null
cmake --build "$build" --target uninstall >/dev/null
if [ -e "$top/galpha-new" ]; then
    echo "left after uninstall of a new prefix:"; find "$top/galpha-new"; exit 1
fi
find "$top" | sort >"$build/tests/prefix_after_uninstall.txt"
diff "$build/tests/prefix_before_install.txt" "$build/tests/prefix_after_uninstall.txt"
echo "uninstall: nothing left of $installed installed files, and nothing else removed"
