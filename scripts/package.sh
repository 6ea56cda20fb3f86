#!/usr/bin/env bash
# The packages, made and tried as their users would (docs/releases.md); run by the test command.
#  1. the source tarball (CPack), and from it a release build configured for /usr;
#  2. the Debian package (cpack -G DEB), installed with dpkg: the README's C program built with
#     `pkg-config --cflags --libs galpha` alone and run with no rpath and no LD_LIBRARY_PATH, no
#     Fortran library in a C link, the Fortran example built with `galpha-fortran`, the Python
#     package from /usr; then removed, and nothing of it left;
#  3. the wheel that carries the C library, installed into a fresh venv (numpy from Debian) and
#     the README's Python program run there, with the library and SuiteSparse from the wheel.
# Everything goes to build-dist/. As root (dpkg). DOCS_HTML: a rendered site to include.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" gfortran python3-venv python3-numpy dpkg-dev
root=$PWD
out=$root/build-dist
rm -rf "$out"
mkdir -p "$out"
version=$(bash scripts/versions.sh)
say() { echo "--- package: $*"; }

say "source tarball"
cmake -S . -B "$out/configure" -DGALPHA_BUILD_TESTS=OFF -DGALPHA_BUILD_BENCH=OFF \
    -DGALPHA_BUILD_EXAMPLES=OFF >/dev/null
(cd "$out" && cpack --config configure/CPackSourceConfig.cmake >/dev/null)
tarball=$out/galpha-$version.tar.gz
tar -tzf "$tarball" >"$out/tarball.txt"
for f in CMakeLists.txt LICENSE CHANGELOG.md README.md include/galpha.h src/capi.cpp \
         bindings/python/pyproject.toml bindings/fortran/galpha.f90 docs/conf.py; do
    grep -qx "galpha-$version/$f" "$out/tarball.txt" || { echo "tarball lacks $f"; exit 1; }
done
if grep -E "^galpha-$version/(build[^/]*|\.git)/" "$out/tarball.txt" | head -n 3 | grep .; then
    echo "tarball holds build trees or .git"; exit 1
fi
echo "$(wc -l <"$out/tarball.txt") files in $(basename "$tarball")"

say "release build from the tarball, for /usr"
tar -xzf "$tarball" -C "$out"
src=$out/galpha-$version
cmake -S "$src" -B "$out/build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr \
    -DGALPHA_WERROR=ON -DGALPHA_REQUIRE_FORTRAN=ON -DGALPHA_BUILD_TESTS=OFF \
    -DGALPHA_BUILD_BENCH=OFF -DGALPHA_BUILD_EXAMPLES=OFF \
    -DGALPHA_PYTHON_INSTALL_DIR=lib/python3/dist-packages \
    ${DOCS_HTML:+-DGALPHA_DOCS_HTML_DIR="$DOCS_HTML"} >/dev/null
cmake --build "$out/build" -j "$JOBS" >/dev/null

say "Debian package"
(cd "$out/build" && cpack -G DEB >/dev/null)
deb=$(ls "$out"/build/galpha_"$version"_*.deb)
dpkg-deb --info "$deb" | sed -n 's/^ \(Package\|Version\|Depends\|Recommends\):/  \1:/p'
dpkg-deb --contents "$deb" | awk '{print $6}' >"$out/deb-contents.txt"
for f in ./usr/include/galpha.h ./usr/share/doc/galpha/LICENSE \
         ./usr/share/doc/galpha/examples/pendulum_demo.c \
         ./usr/lib/python3/dist-packages/galpha/solver.py; do
    grep -qx "$f" "$out/deb-contents.txt" || { echo "the .deb lacks $f"; exit 1; }
done
grep -q "/fortran/gfortran-mod-[0-9]*/galpha.mod$" "$out/deb-contents.txt" ||
    { echo "the .deb lacks the Fortran module in a compiler-specific directory"; exit 1; }
if [ -n "${DOCS_HTML:-}" ]; then
    grep -qx ./usr/share/doc/galpha/html/index.html "$out/deb-contents.txt" ||
        { echo "the .deb lacks the documentation site"; exit 1; }
fi
if dpkg-query -W -f='${Status}' galpha 2>/dev/null | grep -q "install ok installed"; then
    echo "a galpha package is installed already: remove it first (dpkg -r galpha)"; exit 1
fi
dpkg -i "$deb" >/dev/null
trap 'dpkg -r galpha >/dev/null 2>&1 || true' EXIT
# the README's C program, as a newcomer builds it: nothing but pkg-config
work=$out/user
mkdir -p "$work"
/usr/bin/python3 - "$root/README.md" "$work" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
blocks = dict()
for lang, code in re.findall(r"^```(\w+)\n(.*?)^```$", text, re.S | re.M):
    blocks.setdefault(lang, code)
open(sys.argv[2] + "/demo.c", "w").write(blocks["c"])
open(sys.argv[2] + "/demo.py", "w").write(blocks["python"])
PY
flags=$(env -u PKG_CONFIG_PATH pkg-config --cflags --libs galpha)
echo "pkg-config --cflags --libs galpha: $flags"
# under /usr pkg-config leaves out the system's directories: nothing but the library
[ "$(echo $flags)" = "-lgalpha" ] || { echo "galpha.pc under /usr: expected -lgalpha alone"; exit 1; }
# shellcheck disable=SC2086
(cd "$work" && cc demo.c $flags -o demo)
if readelf -d "$work/demo" | grep -E "RPATH|RUNPATH"; then echo "demo has an rpath"; exit 1; fi
if readelf -d "$work/demo" | grep NEEDED | grep -i fortran; then echo "a C program links Fortran"; exit 1; fi
(cd "$work" && env -u LD_LIBRARY_PATH ./demo)
fflags=$(env -u PKG_CONFIG_PATH pkg-config --cflags --libs galpha-fortran)
echo "pkg-config --cflags --libs galpha-fortran: $fflags"
# shellcheck disable=SC2086
(cd "$work" && gfortran "$src/examples/fortran/pendulum.f90" $fflags -o pendulum_f &&
    env -u LD_LIBRARY_PATH ./pendulum_f | tail -n 1)
(cd "$work" && env -u GALPHA_LIBRARY -u PYTHONPATH /usr/bin/python3 -c \
    "import galpha; print('Python from the .deb: galpha', galpha.__version__, galpha.library_path)")
dpkg -r galpha >/dev/null
trap - EXIT
left=$(grep -v '/$' "$out/deb-contents.txt" | sed 's|^\.||' | while read -r f; do
           [ -e "$f" ] && echo "$f"; done || true)
[ -z "$left" ] || { echo "left after dpkg -r galpha:"; echo "$left"; exit 1; }
echo "the .deb installed, served the README's C program and Fortran, and left nothing behind"

say "wheel"
/usr/bin/python3 -m venv "$out/venv-build"
GALPHA_WHEEL_LIBRARY=$out/build/libgalpha.so.0 "$out/venv-build/bin/pip" wheel -q --no-deps \
    --disable-pip-version-check -w "$out/wheel" "$src/bindings/python"
wheel=$(ls "$out"/wheel/galpha-"$version"-py3-none-*.whl)
/usr/bin/python3 -m zipfile -l "$wheel" | awk 'NR > 1 {print "  " $1}' | grep _libs/
/usr/bin/python3 -m venv --system-site-packages "$out/venv"
"$out/venv/bin/pip" install -q --no-deps --disable-pip-version-check "$wheel"
cat >"$work/check_wheel.py" <<'PY'
import os, runpy, sys
runpy.run_path(sys.argv[1], run_name="__main__")  # the README's program
import galpha
package = os.path.dirname(galpha.__file__)
assert galpha.library_path.startswith(package), galpha.library_path
maps = open("/proc/self/maps").read()
for lib in ("libgalpha.so.0", "libklu.so.1", "libcholmod.so.3"):
    paths = {line.split()[-1] for line in maps.splitlines() if lib in line}
    assert paths and all(p.startswith(package) for p in paths), (lib, paths)
print("wheel: galpha", galpha.__version__, "with its own library and SuiteSparse from", package)
PY
(cd "$work" && env -u GALPHA_LIBRARY -u PYTHONPATH -u PKG_CONFIG_PATH \
    "$out/venv/bin/python" check_wheel.py demo.py)
echo "packages: $(basename "$tarball"), $(basename "$deb"), $(basename "$wheel")"
