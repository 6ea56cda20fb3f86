#!/usr/bin/env bash
# Regenerates every study of docs/paper (CSV + PNG) with one command: installs what is missing
# (as root), builds galpha (release), runs bench/paper_studies and draws the charts.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" python3 python3-numpy python3-matplotlib
cmake -S . -B build-demo -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF -DGALPHA_BUILD_BENCH=ON >/dev/null
cmake --build build-demo -j "$JOBS" --target paper_studies >/dev/null
mkdir -p docs/paper
./build-demo/bench/paper_studies docs/paper "$@"
/usr/bin/python3 scripts/plot_studies.py docs/paper
