#!/usr/bin/env bash
# The ABI of libgalpha against its baseline, abi/libgalpha.abi (libabigail's abidw/abidiff,
# Debian's abigail-tools): `check LIB` fails on an incompatible change (a function removed, a
# signature or a type changed); additions pass. `update LIB` writes the baseline, for a release
# that may break the ABI (and bumps GA_VERSION_MAJOR). LIB needs debug information (the
# sanitizer build of scripts/test.sh has it).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?check or update}
lib=${2:?the library, e.g. build-sanitize/libgalpha.so}
dump() { abidw --headers-dir include --no-corpus-path --drop-private-types \
               --exported-interfaces-only "$lib"; }
if [ "$mode" = update ]; then
    dump > abi/libgalpha.abi
    echo "abi/libgalpha.abi written from $lib"
    exit 0
fi
current=$(mktemp)
trap 'rm -f "$current"' EXIT
dump > "$current"
set +e
report=$(abidiff abi/libgalpha.abi "$current")
rc=$?
set -e
# abidiff's status bits: 1 error, 2 usage, 4 ABI change, 8 incompatible change
if (( rc & 11 )); then
    echo "ABI: incompatible change against abi/libgalpha.abi (abidiff status $rc):"
    echo "$report"
    exit 1
fi
if (( rc & 4 )); then
    echo "ABI: compatible additions against abi/libgalpha.abi"
else
    echo "ABI: unchanged against abi/libgalpha.abi"
fi
