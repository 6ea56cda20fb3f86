#!/usr/bin/env bash
# The README's main command: installs what is missing (as root), builds galpha, and runs the
# paper's scenes (slider-crank; Andrews' mechanism in 7 angles and in 31 coordinates) and the
# pendulum, a pendulum rebounding from a wall (restarted after each impact), the slider-crank
# driven by a DC motor under PI speed control (first-order states), and a 10 000-link
# chain on the sparse path, printing for each the final state, constraint residual, work and
# time (the impacts: their times and energies).
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}"
cmake -S . -B build-demo -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF -DGALPHA_BUILD_BENCH=OFF >/dev/null
cmake --build build-demo -j "$JOBS" >/dev/null
for demo in slider_crank andrews pendulum impact motor_crank chain; do
    ./build-demo/examples/${demo}_demo
    echo
done
