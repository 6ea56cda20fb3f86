// The record of a run for the discrete adjoint (adjoint.cpp): every accepted state since
// ga_init with what the backward sweep needs to rebuild its step -- the step size, how a_n
// entered it, q, v, qdd, lambda and, in index 2, eta_bar -- and the derivatives of the start.
#pragma once

#include <cstddef>
#include <vector>

#include "sensitivity.hpp"
#include "types.hpp"

namespace ga {

struct AdjointRecord {
    // How a recorded step began (Solver::prepare_start): a_n as accepted or rescaled by rho
    // (Regular), the first step's start (differenced, start0), or a start the sweep does not
    // cover (Taylor steps, fresh starts after short steps).
    enum Kind { Regular = 0, First = 1, Unsupported = 2 };
    long capacity = 0;  // steps
    long steps = 0;     // recorded since ga_init
    int n = 0, m = 0;
    std::vector<double> data;  // capacity + 1 entries of stride()
    std::vector<StateDerivative> sigma0, start0;  // per parameter
    long unsupported_at = -1;  // the first step of a kind not covered (-1: none)
    // the step being taken, until commit
    Kind pending_kind = Regular;
    double pending_rho = 1.0;

    std::size_t stride() const { return 4 + 3 * static_cast<std::size_t>(n) + 2 * m; }
    // entry k: [t, h of the step ending here, rho, kind, q, v, qdd (n each), lambda, eta (m)]
    double *entry(long k) { return data.data() + static_cast<std::size_t>(k) * stride(); }
    const double *entry(long k) const
    {
        return data.data() + static_cast<std::size_t>(k) * stride();
    }
    // Throws std::bad_alloc.
    void allocate(int n_, int m_, int np, long capacity_);
};

}  // namespace ga
