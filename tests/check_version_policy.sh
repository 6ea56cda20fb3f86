#!/usr/bin/env bash
# The version policy (docs/releases.md) as scripts/abi.sh enforces it, tried on copies of the
# tree's version files with baselines edited to stand for other releases: each case must pass
# or fail as the policy says. LIB: a library with debug information (build-abi's).
set -euo pipefail
lib=$(realpath "${1:?the library, e.g. build-abi/libgalpha.so}")
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/scripts" "$work/abi" "$work/include" "$work/bindings/python/_build"
cp "$root/scripts/abi.sh" "$root/scripts/versions.sh" "$work/scripts/"
cp "$root/include/galpha.h" "$work/include/"
cp "$root/CMakeLists.txt" "$root/CHANGELOG.md" "$work/"
cp "$root/bindings/python/pyproject.toml" "$work/bindings/python/"
cp "$root/bindings/python/_build/galpha_build.py" "$work/bindings/python/_build/"
version=$(bash "$work/scripts/versions.sh")
IFS=. read -r major minor patch <<<"$version"
cd "$work"
bash scripts/abi.sh update "$lib" >/dev/null
cp abi/libgalpha.abi current.abi

expect() {  # expect pass|fail WHAT
    local want=$1 what=$2 out rc=0
    out=$(bash scripts/abi.sh check "$lib" 2>&1) || rc=$?
    if { [ "$want" = pass ] && [ $rc -ne 0 ]; } || { [ "$want" = fail ] && [ $rc -eq 0 ]; }; then
        echo "version policy: expected $want for '$what', got rc $rc:"
        echo "$out"
        exit 1
    fi
    echo "ok ($want): $what -- $(echo "$out" | head -n 1)"
}
edit_abi() {  # edit_abi drop|add FUNCTION: the baseline without it, or with a copy named so
    python3 - "$@" <<'PY'
import re, sys
mode, name = sys.argv[1], sys.argv[2]
text = open("current.abi").read()
if mode == "drop":
    text = re.sub(r"\s*<elf-symbol name='%s'[^\n]*" % name, "", text)
    text = re.sub(r"\s*<function-decl name='%s'.*?</function-decl>" % name, "", text, flags=re.S)
else:  # a function the release had and the library lacks: ga_set_output's twin
    sym = re.search(r"\n(\s*<elf-symbol name='ga_set_output'[^\n]*)", text).group(1)
    decl = re.search(r"\n(\s*<function-decl name='ga_set_output'.*?</function-decl>)", text,
                     re.S).group(1)
    text = text.replace(sym, sym + "\n" + sym.replace("ga_set_output", name), 1)
    text = text.replace(decl, decl + "\n" + decl.replace("ga_set_output", name), 1)
open("abi/libgalpha.abi", "w").write(text)
PY
}
set_version() {  # the version in every place versions.sh reads
    local v=$1 a b c
    IFS=. read -r a b c <<<"$v"
    sed -i "s/^project(galpha VERSION [0-9.]*/project(galpha VERSION $v/" CMakeLists.txt
    sed -i "s/#define GA_VERSION_MAJOR .*/#define GA_VERSION_MAJOR $a/; s/#define GA_VERSION_MINOR .*/#define GA_VERSION_MINOR $b/; s/#define GA_VERSION_PATCH .*/#define GA_VERSION_PATCH $c/" include/galpha.h
    sed -i "s/^version = \".*\"/version = \"$v\"/" bindings/python/pyproject.toml
    sed -i "s/^VERSION = \".*\"/VERSION = \"$v\"/" bindings/python/_build/galpha_build.py
    sed -i "0,/^## \[[0-9.]*\]/s//## [$v]/" CHANGELOG.md
}

expect pass "the library is the release"
edit_abi drop ga_set_tolerances_vector
expect fail "a function added, the version still the release's ($version)"
echo "$major.$((minor - 1)).0" > abi/VERSION
expect pass "a function added, minor raised above the release's ($major.$((minor - 1)).0)"
edit_abi add ga_withdrawn
echo "$version" > abi/VERSION
expect fail "a function removed, the major kept"
set_version "$((major + 1)).0.0"
expect pass "a function removed, the major raised"
set_version "$version"
cp current.abi abi/libgalpha.abi
sed -i 's/^version = ".*"/version = "9.9.9"/' bindings/python/pyproject.toml
expect fail "the Python package says another version"
