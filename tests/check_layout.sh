#!/bin/sh
# The solver's layout (docs/design-notes.md, "The solver's layout"), kept by grep:
# - the step kernel (class Stepper: stepper.cpp, init.cpp, error_estimate.cpp, first_order.cpp,
#   output.cpp, checkpoint.cpp, resolution_check.cpp) names no service: it reaches the
#   sensitivities, the adjoint, the events and the hook only through its doors (StepDoors);
# - only solver.cpp and transaction.cpp define members of the class that runs the transaction
#   (Solver): every capability is a class or a function of its own;
# - q moves only through the configuration space: outside configuration_space.hpp no file
#   adds to q, steps it by Taylor or Newmark, or perturbs it by hand.
set -eu
src=$1/src
status=0
kernel="$src/stepper.cpp $src/stepper.hpp $src/init.cpp $src/error_estimate.cpp $src/first_order.cpp
    $src/output.cpp $src/checkpoint.cpp $src/resolution_check.cpp"
# shellcheck disable=SC2086
kernel_services=$(grep -nE '\bsens(\(\))?\.|\bforward_\b|\badjoint_\b|\bSensitivities\b|\bAdjoint\b|\bevents_\b|\bEventSet\b|\bhook_\b|\bStepHook\b|\bSolver\b' \
    $kernel | grep -vE '^[^:]+:[0-9]+:\s*//' | grep -vE 'friend class (ForwardSensitivity|Adjoint);' || true)
if [ -n "$kernel_services" ]; then
    echo "the step kernel names a service or the transaction (use a door, step_doors.hpp):"
    echo "$kernel_services"; status=1
fi
# (and grants no service a friend's access: they use its public doors and services)
friends=$(grep -nE '^\s*friend\b' "$src/stepper.hpp" "$src/solver.hpp" || true)
if [ -n "$friends" ]; then
    echo "the kernel or the transaction grants a friend's access (give it a narrow door):"
    echo "$friends"; status=1
fi
members=$(grep -nE '^[A-Za-z_:<>*& ]*\bSolver::' "$src"/*.cpp | grep -vE '^[^:]*/(solver|transaction)\.cpp:' || true)
if [ -n "$members" ]; then
    echo "a capability defines members of Solver (only solver.cpp and transaction.cpp do):"
    echo "$members"; status=1
fi
# (q itself, not a sensitivity's tangent s.q: "q +=", "x.q = s.q + h * s.v ...", "q + e * v",
# "q[j] + e"; comments aside)
q_sites=$(grep -nE '(^|[^.[:alnum:]_])q(\.segment\([^)]*\))? \+= |\.q = [a-z_0-9]*\.q \+ [a-z_]* \* [a-z_0-9]*\.?v|\.q \+= [a-z_]*\.(d|bt|cbt)\b|(^|[^.[:alnum:]_])q [+-] [a-z_]* \* v\b|\bq\[[a-z]\] [+-] [a-z_]' \
    "$src"/*.cpp "$src"/*.hpp | grep -vE 'configuration_space\.(hpp|cpp)' | grep -vE '^[^:]+:[0-9]+:\s*//' || true)
if [ -n "$q_sites" ]; then
    echo "q moved outside the configuration space:"; echo "$q_sites"; status=1
fi
[ "$status" -eq 0 ] && echo "layout: the kernel names no service, only the transaction defines Solver members, q moves through the space"
exit "$status"
