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
echo "links,n,m,backend,steps,newton_per_step,factorizations_per_step,us_per_step,first_step_us,later_us_per_step,limit_us,ratio,peak_rss_kib" > "$out/chain.csv"
# 50 steps from rest: the first step (pivots chosen for the step's matrix) costs about three
# later ones, so that 10 steps would weigh it five times as much as a run of 50 does
for N in 10 30 100 300 1000 3000 10000 30000 100000; do
    "$b/step_cost" chain "$N" 50 >> "$out/chain.csv"
done
echo "spatial chain scaling (rods on R^3 x SO(3), spherical joints: the sparse path on a group space)"
echo "bodies,n,m,backend,steps,newton_per_step,factorizations_per_step,us_per_step,first_step_us,later_us_per_step,limit_us,ratio,peak_rss_kib" > "$out/spatial_chain.csv"
for N in 1000 3000 10000 30000 100000; do
    "$b/step_cost" spatial_chain "$N" 50 >> "$out/spatial_chain.csv"
done
echo "links,n,m,runs,setup_us,later_us_per_step,setup_in_steps" > "$out/chain_setup.csv"
for N in 1000 10000 100000; do  # ga_create to ga_init against a step (steps 2-10), best of runs
    "$b/step_cost" chain_setup "$N" 10 >> "$out/chain_setup.csv"
done
# the same with glibc's malloc on transparent huge pages (docs/performance.md: setup is mostly
# the first touch of its memory)
echo "links,n,m,runs,setup_us,later_us_per_step,setup_in_steps" > "$out/chain_setup_hugepages.csv"
for N in 1000 10000 100000; do
    GLIBC_TUNABLES=glibc.malloc.hugetlb=1 "$b/step_cost" chain_setup "$N" 10 \
        >> "$out/chain_setup_hugepages.csv"
done
echo "links,n,m,backend,steps,newton_per_step,factorizations_per_step,us_per_step,first_step_us,later_us_per_step,limit_us,ratio,peak_rss_kib" > "$out/chain_index2.csv"
for N in 1000 10000 100000; do
    # (at 100 000 links Newton stalls above 1e-10 at the third step: docs/performance.md)
    "$b/step_cost" chain "$N" 50 1e-10 1 >> "$out/chain_index2.csv" || true
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
    echo "bodies,instructions_per_step" > "$out/spatial_chain_instructions.csv"
    for N in 1000 10000 100000; do
        valgrind --tool=callgrind --toggle-collect=ga_step --callgrind-out-file=/dev/null \
            "$b/step_cost" spatial_chain_steps "$N" 10 2>&1 |
            sed -n "s/.*Collected : \([0-9]*\).*/$N,\1/p" |
            awk -F, '{printf "%s,%.0f\n", $1, $2 / 10}' >> "$out/spatial_chain_instructions.csv"
    done
fi
if command -v valgrind >/dev/null; then
    echo "per-step cost in instructions (callgrind): what the timing ratios cannot resolve"
    collected() {  # instructions collected inside function $1 by step_cost's remaining arguments
        local fn=$1; shift
        valgrind --tool=callgrind --toggle-collect="$fn" --callgrind-out-file=/dev/null \
            "$b/step_cost" "$@" 2>&1 | sed -n "s/.*Collected : \([0-9]*\).*/\1/p"
    }
    echo "scene,newton_tol,instructions_per_step,limit_instructions,ratio" > "$out/step_instructions.csv"
    for sc in slider_crank andrews7 andrews31 andrews31_sparse; do
        steps=$("$b/step_cost" scene_steps "$sc" 1e-6)
        step=$(collected ga_step scene_steps "$sc" 1e-6)
        # the limit: the difference between 2000 and 1000 calls, per call
        l1=$(collected 'ga::Solver::unavoidable_work*' scene_limit "$sc" 1e-6 1000)
        l2=$(collected 'ga::Solver::unavoidable_work*' scene_limit "$sc" 1e-6 2000)
        awk -v sc="$sc" -v n="$steps" -v s="$step" -v a="$l1" -v b="$l2" \
            'BEGIN { l = (b - a) / 1000; printf "%s,1e-06,%.0f,%.0f,%.3f\n", sc, s / n, l, s / n / l }' \
            >> "$out/step_instructions.csv"
    done
fi
echo "sensitivities: forward and adjoint against the plain run (interleaved rounds)"
"$b/sensitivity_cost" 21 > "$out/sensitivity_cost.csv"
echo "events that never fire: run time with and without (interleaved rounds)"
"$b/event_cost" 41 > "$out/event_cost.csv"
"$b/event_cost" side_by_side 800 > "$out/event_side_by_side.csv"
if command -v valgrind >/dev/null; then
    echo "events that never fire: instructions inside the stepping calls (callgrind)"
    echo "scene,instructions_without,instructions_with,ratio" > "$out/event_instructions.csv"
    for sc in pendulum slider_crank andrews7 chain1000 andrews7_adaptive_index2; do
        fn=ga_step
        [ "$sc" = andrews7_adaptive_index2 ] && fn=ga_advance
        count() {
            valgrind --tool=callgrind --toggle-collect="$fn" --callgrind-out-file=/dev/null \
                "$b/event_cost" one "$sc" "$1" 2>&1 | sed -n "s/.*Collected : \([0-9]*\).*/\1/p"
        }
        without=$(count 0)
        with=$(count 1)
        awk -v sc="$sc" -v a="$without" -v b="$with" \
            'BEGIN { printf "%s,%d,%d,%.4f\n", sc, a, b, b / a }' >> "$out/event_instructions.csv"
    done
fi
echo "linear algebra"
"$b/linear_algebra" > "$out/linear_algebra.csv"

echo "the lattice's lowest modes (ga_modes_near) against a dynamic step; LAPACK at 10^4 unknowns"
{ "$b/lattice_modes" 36 verify; "$b/lattice_modes" 112 | tail -n +2; } > "$out/lattice_modes.csv"
echo "work-precision against IDA"
if [ -x "$b/ida_workprecision" ]; then
    "$b/ida_workprecision" andrews > "$out/wp_andrews.csv" 2>/dev/null
    "$b/ida_workprecision" slider_crank > "$out/wp_slider_crank.csv" 2>/dev/null
fi
if [ -x "$b/ida_chain" ]; then
    # One run per process (its peak memory is that run's); 0.2 s of the fall from rest; the
    # reference at h = 6.25e-5 (it prints its difference to the run at twice that step).
    echo "chain against IDA with KLU (links: ${CHAIN_IDA_LINKS:=100 1000 10000 100000})"
    echo "links,method,setting,error,cpu_seconds,steps,factorizations,peak_rss_kib" \
        > "$out/chain_ida.csv"
    ref=$(mktemp)
    for N in $CHAIN_IDA_LINKS; do
        "$b/ida_chain" reference "$N" 0.2 6.25e-5 "$ref"
        for h in 4e-2 2e-2 1e-2 5e-3 2.5e-3 1.25e-3 6.25e-4 3.125e-4; do
            "$b/ida_chain" run "$N" 0.2 galpha "$h" "$ref" >> "$out/chain_ida.csv"
        done
        for tol in 1e-2 1e-3 1e-4 1e-5 1e-6 1e-7; do
            "$b/ida_chain" run "$N" 0.2 ida "$tol" "$ref" >> "$out/chain_ida.csv"
            "$b/ida_chain" run "$N" 0.2 galpha_adaptive "$tol" "$ref" >> "$out/chain_ida.csv"
        done
    done
    rm -f "$ref"
fi
if [ -x "$b/petsc_alpha2" ]; then
    # The same method in PETSc (issue 22): a two-material lattice with n = 2 (4 NY - 1) NY
    # unknowns, 0.2 s of its sag from rest; one run per process; reference at h = 1.25e-4.
    echo "lattice against PETSc TSALPHA2 (NY: ${LATTICE_NY:=11 35 112})"
    echo "unknowns,method,setting,error,cpu_seconds,steps,newton_iterations,factorizations,peak_rss_kib" \
        > "$out/lattice_petsc.csv"
    ref=$(mktemp)
    for NY in $LATTICE_NY; do
        "$b/petsc_alpha2" reference "$NY" 0.2 1.25e-4 "$ref"
        for h in 1e-2 5e-3 2.5e-3 1.25e-3 6.25e-4; do
            for m in galpha petsc petsc_lagged; do
                "$b/petsc_alpha2" run "$NY" 0.2 $m "$h" "$ref" >> "$out/lattice_petsc.csv" || true
            done
        done
        for tol in 1e-3 1e-4 1e-5; do
            for m in galpha_adaptive petsc_adaptive petsc_adaptive_lagged; do
                "$b/petsc_alpha2" run "$NY" 0.2 $m "$tol" "$ref" >> "$out/lattice_petsc.csv" || true
            done
        done
    done
    rm -f "$ref"
fi
echo "python overhead"
GALPHA_LIBRARY=build-demo/libgalpha.so.0 /usr/bin/python3 bench/python_overhead.py \
    build-demo/examples/pendulum_demo > "$out/python_overhead.csv"
if /usr/bin/python3 -c "import numba" 2>/dev/null; then
    echo "compiled callbacks and ensembles"
    GALPHA_LIBRARY=build-demo/libgalpha.so.0 /usr/bin/python3 bench/compiled_callbacks.py \
        build-demo/bench/libbench_scenes.so build-demo/bench/c_driver > "$out/compiled_callbacks.csv"
    GALPHA_LIBRARY=build-demo/libgalpha.so.0 /usr/bin/python3 bench/ensemble_scaling.py 1000 \
        > "$out/ensemble_scaling.csv" 2>/dev/null
fi
/usr/bin/python3 scripts/plot_bench.py "$out"
