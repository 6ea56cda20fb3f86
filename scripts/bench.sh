#!/usr/bin/env bash
# Regenerates every benchmark of docs/perf (CSV + PNG) with one command: per-step cost against
# the unavoidable work, the chain from 10 to 100 000 links (time per step, peak memory), dense
# LU implementations against the sparse path, work-precision against SUNDIALS IDA, and the
# Python binding's overhead. Installs what is missing (as root). Run it on an idle machine.
set -euo pipefail
cd "$(dirname "$0")/.."
. scripts/deps.sh
ensure_packages "${BUILD_PACKAGES[@]}" libsuitesparse-dev libsundials-dev python3 python3-numpy \
    python3-matplotlib
cmake -S . -B build-demo -DCMAKE_BUILD_TYPE=Release -DGALPHA_BUILD_TESTS=OFF -DGALPHA_BUILD_BENCH=ON >/dev/null
cmake --build build-demo -j "$JOBS" >/dev/null
out=docs/perf
mkdir -p "$out"
b=build-demo/bench
echo "per-step cost"
{ "$b/step_cost" scenes 1e-10; "$b/step_cost" scenes 1e-6 | tail -n +2; } > "$out/step_cost.csv"
echo "chain scaling"
echo "links,n,m,backend,steps,newton_per_step,factorizations_per_step,us_per_step,limit_us,ratio,peak_rss_kib" > "$out/chain.csv"
for N in 10 30 100 300 1000 3000 10000 30000 100000; do
    "$b/step_cost" chain "$N" 10 >> "$out/chain.csv"
done
echo "links,n,m,backend,steps,newton_per_step,factorizations_per_step,us_per_step,limit_us,ratio,peak_rss_kib" > "$out/chain_index2.csv"
for N in 1000 10000 100000; do
    "$b/step_cost" chain "$N" 10 1e-10 1 >> "$out/chain_index2.csv"
done
if command -v valgrind >/dev/null; then
    echo "chain: instructions inside ga_step (callgrind), the work regardless of the memory hierarchy"
    echo "links,instructions_per_step" > "$out/chain_instructions.csv"
    for N in 1000 10000 100000; do
        valgrind --tool=callgrind --toggle-collect=ga_step --callgrind-out-file=/dev/null \
            "$b/step_cost" chain_steps "$N" 10 2>&1 |
            sed -n "s/.*Collected : \([0-9]*\).*/$N,\1/p" |
            awk -F, '{printf "%s,%.0f\n", $1, $2 / 10}' >> "$out/chain_instructions.csv"
    done
fi
echo "linear algebra"
"$b/linear_algebra" > "$out/linear_algebra.csv"
echo "work-precision against IDA"
if [ -x "$b/ida_workprecision" ]; then
    "$b/ida_workprecision" andrews > "$out/wp_andrews.csv" 2>/dev/null
    "$b/ida_workprecision" slider_crank > "$out/wp_slider_crank.csv" 2>/dev/null
fi
echo "python overhead"
GALPHA_LIBRARY=build-demo/libgalpha.so.0 /usr/bin/python3 bench/python_overhead.py \
    build-demo/examples/pendulum_demo > "$out/python_overhead.csv"
/usr/bin/python3 scripts/plot_bench.py "$out"
