#!/bin/sh
# galpha's results do not depend on the system BLAS/LAPACK: the 200 golden cases
# (tests/c/test_golden.c) hash the same under every BLAS and LAPACK that Debian's alternatives
# offer on this machine (reference, OpenBLAS pthread and serial, BLIS) as under the one
# selected, each loaded ahead of the selected one by LD_LIBRARY_PATH, in this one test.
# Skipped (exit 77) when only one BLAS is installed.
set -eu
golden=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)
blas=$(update-alternatives --list "libblas.so.3-$multiarch" 2>/dev/null || true)
lapack=$(update-alternatives --list "liblapack.so.3-$multiarch" 2>/dev/null || true)
reference_lapack=$(echo "$lapack" | grep '/lapack/' | head -n 1 || true)
if [ "$(echo "$blas" | grep -c .)" -lt 2 ]; then
    echo "one BLAS installed ($blas): nothing to compare"
    exit 77
fi
GALPHA_GOLDEN_RECORD=$work/selected.inc "$golden" >/dev/null
compared=0
for b in $blas; do
    dir=$(dirname "$b")
    # a BLAS that brings its own LAPACK (OpenBLAS) with it; BLIS with the reference LAPACK
    l=$(echo "$lapack" | grep "^$dir/" | head -n 1 || true)
    [ -n "$l" ] || l=$reference_lapack
    path=$dir:$(dirname "$l")
    loaded=$(LD_LIBRARY_PATH=$path ldd "$golden" | grep -E 'lib(blas|lapack)\.so\.3' |
        awk '{print $3}' | tr '\n' ' ')
    case "$loaded" in
    *"$b"*"$l"* | *"$l"*"$b"*) ;;
    *) echo "LD_LIBRARY_PATH=$path loads $loaded, not $b and $l"; exit 1 ;;
    esac
    name=$(basename "$dir")
    if ! LD_LIBRARY_PATH=$path GALPHA_GOLDEN_COMPARE=$work/selected.inc "$golden" \
        >"$work/$name.log" 2>&1; then
        grep -E "differs|cases," "$work/$name.log" || tail -n 20 "$work/$name.log"
        echo "results under $b and $l differ from those under the selected BLAS"
        exit 1
    fi
    echo "$name: $(grep -o '[0-9]* cases, 0 differ' "$work/$name.log") ($b, $l)"
    compared=$((compared + 1))
done
echo "the golden cases are the same bits under all $compared BLAS/LAPACK pairs"
