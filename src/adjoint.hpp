// The record of a run for the discrete adjoint (adjoint.cpp): every accepted state since
// ga_init with what the backward sweep needs to rebuild its step -- the step size, how a_n
// entered it, q, v, qdd, lambda and, in index 2, eta_bar -- and the derivatives of the start;
// and the service that keeps it and sweeps it backwards (Adjoint).
#pragma once

#include <cstddef>
#include <vector>

#include "galpha.h"
#include "sensitivity.hpp"
#include "types.hpp"

namespace ga {

struct AdjointRecord {
    // How a recorded step began (Stepper::prepare_start): a_n as accepted or rescaled by rho
    // (Regular), the first step's start (differenced, start0), or a start the sweep does not
    // cover (Taylor steps, fresh starts after short steps).
    enum Kind { Regular = 0, First = 1, Unsupported = 2 };
    long capacity = 0;   // steps
    long steps = 0;      // recorded since ga_init
    long max_steps = 0;  // of the full record (ga_set_sensitivity_method)
    int nq = 0, nv = 0, m = 0, r = 0;
    std::vector<double> data;  // capacity + 1 entries of stride(), or interval + 1
    // Checkpointing (ga_set_adjoint_checkpoints): `data` holds the entries of steps base ...
    // base + interval only; the solver's state after steps 0, interval, 2 interval, ... is
    // kept in `checkpoints`, and the sweep recomputes each earlier segment from its own.
    long interval = 0;  // 0: the whole run in data
    long base = 0;
    std::size_t checkpoint_size = 0;
    std::vector<double> checkpoints;
    // per step k >= 1 (with checkpointing): t, h, rho, kind, Newton tolerance, sliver allowed
    // (+ 2 for an adaptive step),
    // and the kept matrix's reuse state as the accepted attempt began (valid, theta,
    // refresh steps left, backoff, finite-difference tangents)
    static constexpr std::size_t kLog = 11;
    std::vector<double> log;
    std::vector<StateDerivative> sigma0, start0;  // per parameter
    long unsupported_at = -1;  // the first step of a kind not covered (-1: none)
    // the step being taken, until commit
    Kind pending_kind = Regular;
    double pending_rho = 1.0;

    static std::size_t stride_for(int nq, int nv, int m, int r)
    {
        return 4 + static_cast<std::size_t>(nq) + 2 * static_cast<std::size_t>(nv) +
               2 * static_cast<std::size_t>(m) + 2 * static_cast<std::size_t>(r);
    }
    std::size_t stride() const { return stride_for(nq, nv, m, r); }
    // entry k: [t, h of the step ending here, rho, kind, q (nq), v, qdd (nv each), lambda,
    // eta (m), y, y' (r each)]
    double *entry(long k) { return data.data() + static_cast<std::size_t>(k - base) * stride(); }
    const double *entry(long k) const
    {
        return data.data() + static_cast<std::size_t>(k - base) * stride();
    }
    double *checkpoint(long c) { return checkpoints.data() + c * checkpoint_size; }
    double *log_entry(long k) { return log.data() + (k - 1) * kLog; }
    // Throw std::bad_alloc.
    void allocate(int nq_, int nv_, int m_, int r_, int np, long capacity_);
    void allocate_checkpointed(int nq_, int nv_, int m_, int r_, int np, long interval_, long count,
                               std::size_t state_size);
};

class Stepper;
class Solver;

// The discrete adjoint as a service of the step (docs/algorithms.md sec. 11): at the doors of
// the transaction it records the run (its first entry at ga_init, room and how the step began
// once a step converged, the step at commit, its removal on undo); ga_adjoint_gradient sweeps
// the record backwards, recomputing checkpointed segments through the kernel (`k_`). The
// derivatives in p come from the forward sensitivities' service.
class Adjoint {
public:
    Adjoint(Stepper &kernel, ForwardSensitivity &forward, Solver &run)
        : k_(kernel), forward_(forward), run_(run)
    {
    }
    Adjoint(const Adjoint &) = delete;
    Adjoint &operator=(const Adjoint &) = delete;

    // ga_set_sensitivity_method, ga_set_adjoint_checkpoints (the C API validated the
    // arguments): the record allocated aside, so that a failure leaves the one before.
    ga_status set_method(int methods, long max_steps);
    ga_status set_checkpoints(long interval, long count);
    void forget() { record_ = AdjointRecord{}; }  // ga_set_sensitivity: forward again

    // The doors of the transaction (transaction.cpp).
    void started();                    // x_0 and the start's derivatives, at ga_init
    ga_status on_converged(double h);  // room, and how the step began
    void on_commit();                  // the accepted step
    void on_undo()
    {
        if (--record_.steps < record_.unsupported_at)
            record_.unsupported_at = -1;  // that step is gone
    }

    ga_status gradient(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ);

private:
    struct Work;
    ga_status step_back(long k, Work &w);
    ga_status sweep(ga_cost_fn running, ga_cost_fn terminal, double *J, double *dJ);
    ga_status replay_segment(long s);

    AdjointRecord record_;
    Stepper &k_;
    ForwardSensitivity &forward_;
    Solver &run_;  // its checkpoints and event search, restored after a sweep
};

}  // namespace ga
