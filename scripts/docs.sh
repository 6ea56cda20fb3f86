#!/usr/bin/env bash
# The documentation site: Doxygen reads include/galpha.h (XML), Sphinx with MyST and Breathe
# renders docs/*.md and the API reference into build-docs/html, every warning an error. Then,
# unless --no-browser, the start page and the API page are opened in headless Chromium and
# their screenshots read back (tests/check_site.py): the rendered title and a code block must
# be on them. Debian's python3-sphinx, python3-myst-parser, python3-breathe, doxygen, chromium,
# tesseract-ocr; none is needed by the library.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${DOCS_PACKAGES[@]}"
out=$PWD/build-docs
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
