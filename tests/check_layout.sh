#!/bin/sh
# The solver's layout (docs/design-notes.md, "The solver's layout"), kept by grep:
# - the step kernel names no service: solver.cpp, control.cpp and init.cpp reach the
#   sensitivities, the adjoint's record, the events and the hook only through the doors in
#   transaction.cpp;
# - the event search, the step hook, the forward sensitivities and the adjoint are services of
#   their own: events.cpp, step_hook.cpp, sensitivity.cpp and adjoint.cpp define no member of
#   the class that runs the transaction;
# - q moves only through the configuration space: outside configuration_space.hpp no file
#   adds to q, steps it by Taylor or Newmark, or perturbs it by hand.
set -eu
src=$1/src
status=0
kernel_services=$(grep -nE '\bsens\.|\bsensitivity_|\badjoint_\b|\brecord_start|\bevents_\b|\bhook_\b' \
    "$src/solver.cpp" "$src/control.cpp" "$src/init.cpp" | grep -vE '^[^:]+:[0-9]+:\s*//' |
    grep -v 'sensitivity_step says otherwise' || true)
if [ -n "$kernel_services" ]; then
    echo "the step kernel names a service (use a door in transaction.cpp):"
    echo "$kernel_services"; status=1
fi
members=$(grep -nE '^[A-Za-z_:<>*& ]*\bSolver::' "$src/events.cpp" "$src/step_hook.cpp" \
    "$src/sensitivity.cpp" "$src/adjoint.cpp" || true)
if [ -n "$members" ]; then
    echo "a service defines members of Solver:"; echo "$members"; status=1
fi
# (q itself, not a sensitivity's tangent s.q: "q +=", "x.q = s.q + h * s.v ...", "q + e * v",
# "q[j] + e"; comments aside)
q_sites=$(grep -nE '(^|[^.[:alnum:]_])q(\.segment\([^)]*\))? \+= |\.q = [a-z_]*\.q \+ [a-z_]* \* [a-z_]*\.v|(^|[^.[:alnum:]_])q [+-] [a-z_]* \* v\b|\bq\[[a-z]\] [+-] [a-z_]' \
    "$src"/*.cpp "$src"/*.hpp | grep -v 'configuration_space.hpp' | grep -vE '^[^:]+:[0-9]+:\s*//' || true)
if [ -n "$q_sites" ]; then
    echo "q moved outside the configuration space:"; echo "$q_sites"; status=1
fi
[ "$status" -eq 0 ] && echo "layout: the kernel names no service, services define no Solver members, q moves through the space"
exit "$status"
