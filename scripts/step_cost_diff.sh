#!/usr/bin/env bash
# Instructions per step inside ga_step (callgrind) of two builds side by side: a reshaping of
# the solver (issue 35) must keep the step's cost, and wall times here scatter by 20-50 %.
#   scripts/step_cost_diff.sh BASE_BUILD_DIR NEW_BUILD_DIR [out.csv]
# Each build dir needs bench/step_cost (cmake --build DIR --target step_cost). Scenes: the
# slider-crank, Andrews (7 and 31 coordinates, the latter sparse too) and the 1000-link chain
# (index 3, and index 2).
set -euo pipefail
base=$1 new=$2 out=${3:-/dev/stdout}
collected() {  # instructions inside ga_step for step_cost's arguments
    valgrind --tool=callgrind --toggle-collect=ga_step --callgrind-out-file=/dev/null "$@" 2>&1 |
        sed -n "s/.*Collected : \([0-9]*\).*/\1/p"
}
{
    echo "case,steps,base_per_step,new_per_step,ratio"
    for sc in slider_crank andrews7 andrews31 andrews31_sparse; do
        n=$("$new/bench/step_cost" scene_steps "$sc" 1e-6)
        nb=$("$base/bench/step_cost" scene_steps "$sc" 1e-6)
        [ "$n" = "$nb" ] || { echo "$sc: $nb steps in the base, $n here" >&2; exit 1; }
        a=$(collected "$base/bench/step_cost" scene_steps "$sc" 1e-6)
        b=$(collected "$new/bench/step_cost" scene_steps "$sc" 1e-6)
        awk -v c="$sc" -v n="$n" -v a="$a" -v b="$b" \
            'BEGIN { printf "%s,%d,%.0f,%.0f,%.4f\n", c, n, a / n, b / n, b / a }'
    done
    a=$(collected "$base/bench/step_cost" chain_steps 1000 10)
    b=$(collected "$new/bench/step_cost" chain_steps 1000 10)
    awk -v a="$a" -v b="$b" 'BEGIN { printf "chain1000,10,%.0f,%.0f,%.4f\n", a / 10, b / 10, b / a }'
    # index 2: step_cost's timing mode (200 runs of 20 steps at 1000 links, a fixed count)
    a=$(collected "$base/bench/step_cost" chain 1000 20 1e-10 1)
    b=$(collected "$new/bench/step_cost" chain 1000 20 1e-10 1)
    awk -v a="$a" -v b="$b" \
        'BEGIN { printf "chain1000_index2,4000,%.0f,%.0f,%.4f\n", a / 4000, b / 4000, b / a }'
} > "$out"
