// The C handle and the C++ core behind it. Only the C shim and bench/ include this.
#pragma once

#include <atomic>
#include <thread>

#include "solver.hpp"

struct ga_solver {
    ga_solver(int n, int m) : core(n, m) {}
    ga_solver(const ga::ConfigurationSpace &space, int m) : core(space, m) {}
    ga::Solver core;
    // true while a call on this solver runs (and so inside its callbacks); atomic, so that a
    // second thread calling the same solver (not allowed) is refused, not let in
    std::atomic<bool> busy{false};
    // true while the step hook runs (inside a busy call): read-only calls are let in
    std::atomic<bool> in_hook{false};
    // The thread whose last call was refused because another held the solver: the message
    // belongs to that other call, so ga_last_error tells this thread why instead (cleared
    // when the thread's own calls start and end).
    std::atomic<std::thread::id> refused{};
};
