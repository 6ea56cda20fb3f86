// The C handle and the C++ core behind it. Only the C shim and bench/ include this.
#pragma once

#include "solver.hpp"

struct ga_solver {
    ga_solver(int n, int m) : core(n, m) {}
    ga::Solver core;
    bool busy = false;  // true while a call on this solver runs (and so inside its callbacks)
};
