#!/usr/bin/env bash
# The documentation site: Doxygen reads include/galpha.h (XML), Sphinx with MyST and Breathe
# renders docs/*.md, the C API reference and the Python one (autodoc over the package's
# docstrings, napoleon for their numpy-style sections) into build-docs/html, every warning an
# error. Then, unless --no-browser, the start page and the API page are opened in headless
# Chromium and their screenshots read back (tests/check_site.py): the rendered title and a
# code block must be on them. Debian's python3-sphinx, python3-myst-parser, python3-breathe,
# doxygen, chromium, tesseract-ocr; none is needed by the library.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${DOCS_PACKAGES[@]}"
out=$PWD/build-docs
# The Python reference imports the package, which loads libgalpha: GALPHA_LIBRARY if set, else
# the release build's, else a library built here.
if [ -z "${GALPHA_LIBRARY:-}" ]; then
    GALPHA_LIBRARY=$PWD/build/libgalpha.so.0
    if [ ! -e "$GALPHA_LIBRARY" ]; then
        cmake -S . -B build-docs-lib -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF \
            -DGALPHA_BUILD_EXAMPLES=OFF -DGALPHA_BUILD_BENCH=OFF -DGALPHA_FORTRAN=OFF >/dev/null
        cmake --build build-docs-lib -j "$JOBS" --target galpha >/dev/null
        GALPHA_LIBRARY=$PWD/build-docs-lib/libgalpha.so.0
    fi
fi
export GALPHA_LIBRARY
rm -rf "$out"
mkdir -p "$out/doxygen"
# (Doxygen's paths are relative to docs/, where the Doxyfile is)
(cd docs && { cat Doxyfile; echo "OUTPUT_DIRECTORY = $out/doxygen"; } | doxygen -)
GALPHA_DOXYGEN_XML=$out/doxygen/xml /usr/bin/python3 -m sphinx -W --keep-going -n -q -b html \
    -d "$out/doctrees" docs "$out/html"
echo "site: $out/html/index.html"
if [ "${1:-}" != "--no-browser" ]; then
    /usr/bin/python3 tests/check_site.py "$out/html" "$out/screenshots"
fi
