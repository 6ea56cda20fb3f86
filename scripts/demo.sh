#!/usr/bin/env bash
# The README's main command: installs what is missing (as root), builds galpha, and runs the
# demo scenes, printing what each computed.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF >/dev/null
cmake --build build -j "$JOBS" >/dev/null
./build/examples/pendulum_demo
