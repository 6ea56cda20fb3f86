#!/usr/bin/env bash
# The ABI of libgalpha against its baseline, abi/libgalpha.abi, the ABI of the last release,
# whose version abi/VERSION holds (libabigail's abidw/abidiff, Debian's abigail-tools).
# `check LIB` enforces the version policy (docs/releases.md):
#   an incompatible change (a function removed, a signature or a type changed) fails unless
#   the major version was raised (a new SONAME);
#   additions fail unless the minor (or major) version was raised above the release's;
#   and the version is the same in every place that states it (scripts/versions.sh).
# `update LIB` makes LIB's ABI the baseline, at a release. LIB needs full debug information
# (build-abi, the debug build of the library that `scripts/test.sh --deep` makes).
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?check or update}
lib=${2:?the library, e.g. build-abi/libgalpha.so}
dump() { abidw --headers-dir include --no-corpus-path --drop-private-types \
               --exported-interfaces-only "$lib"; }
version=$(bash scripts/versions.sh)
if [ "$mode" = update ]; then
    dump > abi/libgalpha.abi
    echo "$version" > abi/VERSION
    echo "abi/libgalpha.abi written from $lib, the ABI of release $version"
    exit 0
fi
released=$(cat abi/VERSION)
IFS=. read -r major minor _ <<<"$version"
IFS=. read -r rmajor rminor _ <<<"$released"
new_major=$(( major > rmajor ))
new_minor=$(( major > rmajor || (major == rmajor && minor > rminor) ))
current=$(mktemp)
trap 'rm -f "$current"' EXIT
dump > "$current"
set +e
report=$(abidiff abi/libgalpha.abi "$current")
rc=$?
set -e
# abidiff's status bits: 1 error, 2 usage, 4 ABI change, 8 incompatible change
if (( rc & 3 )); then
    echo "ABI: abidiff failed (status $rc):"
    echo "$report"
    exit 1
fi
if (( rc & 8 )); then
    if (( ! new_major )); then
        echo "ABI: incompatible change against release $released (abidiff status $rc), but the"
        echo "version $version keeps its major: raise GA_VERSION_MAJOR (a new SONAME) or undo it."
        echo "$report"
        exit 1
    fi
    echo "ABI: incompatible change against release $released, major version raised ($version)"
elif (( rc & 4 )); then
    if (( ! new_minor )); then
        echo "ABI: additions against release $released, but the version $version is not a new"
        echo "minor: raise GA_VERSION_MINOR (and the other places scripts/versions.sh reads)."
        echo "$report"
        exit 1
    fi
    echo "ABI: compatible additions against release $released, version $version"
else
    echo "ABI: unchanged against release $released (version $version)"
fi
