// Checkpoint and restart (ga_get_state, ga_set_state). Layout 4, in doubles:
//   header   [magic, 4, n (= nv), m, t, h_last, h_next, err_prev, grew, sliver_span,
//             matrix kept (0/1), its t, its h, t of its B, tangents (K + 2 C + 4 Z + 8 if
//             they were central differences, as for sensitivities),
//             theta_prev, refresh_steps_left, reuse_backoff, fd_tangents, c_count, c_dt]
//   state    q (nq), v, qdd (nv each), lambda (m), a, a_prev, c, c_prev (nv each)
//   matrix   the iterate it was factorized at: q (nq), v, qdd (nv), lambda (m); q of its B (nq);
//            on a group space the increment xi whose T(xi) it took (nv)
//   active   the constraints in use (m flags; all 1 unless GA_REDUNDANT_DROP dropped some)
//   pivots   blocks of pivot_state_size(N) (backend.hpp) for S_ (N = nv + m), S2_
//            (2 nv + 2 m), P_ and O_ (nv + m each)
//   y        with r first-order states only: y, y', w, w_prev and the kept matrix's y, y'
//            (r each)
//   sens     with np sensitivity parameters only: d/dp_j of q, v, qdd, lambda, a (nv each
//            but lambda: d/dp of q is a tangent; and with first-order states y, y', w) for each j
// (nq = nv = n while the space is R^n: the bytes of layout 4 as they were.)
// Taking one only reads. Restoring rebuilds the kept matrix from the callbacks at the same
// iterate and hands every sparse LU its pivots back, so the restored run repeats the run it
// came from bit for bit (a kept matrix or pivots left out would make the next steps converge
// to other round-off). Layout 2 (galpha 0.2: header up to grew, then the state) is read as a
// restart: no kept matrix, pivots chosen afresh. Layout 3 (no c_count, c_dt, c, c_prev) is
// read as a state whose index-3 error estimate has no consistent accelerations yet.
#include "stepper.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace ga {

namespace {
constexpr double kStateMagic = 26465.0;  // 0x6761, "ga"
constexpr double kStateVersion = 4.0;
constexpr std::size_t kHeader = 21;
constexpr std::size_t kHeader3 = 19;  // layout 3
constexpr std::size_t kHeader2 = 9;   // layout 2

bool is_flag(double x) { return x == 0.0 || x == 1.0; }
bool is_count(double x, double max) { return x >= 0.0 && x <= max && x == std::floor(x); }

struct Layout {
    std::size_t matrix, active, pivots[4], end;  // offsets; pivots of S_, S2_, P_, O_
};

// Layout 4, or with layout3 the one before it (19 header entries, no c and c_prev).
Layout layout(int nq, int nv, int m, bool layout3 = false)
{
    const std::size_t Q = static_cast<std::size_t>(nq), N = static_cast<std::size_t>(nv),
                      M = static_cast<std::size_t>(m);
    Layout l;
    l.matrix = layout3 ? kHeader3 + Q + 4 * N + M : kHeader + Q + 6 * N + M;
    l.active = l.matrix + 2 * Q + 2 * N + M + (nq != nv ? N : 0);  // (a group space: xi)
    l.pivots[0] = l.active + M;
    l.pivots[1] = l.pivots[0] + pivot_state_size(nv + m);
    l.pivots[2] = l.pivots[1] + pivot_state_size(2 * nv + 2 * m);
    l.pivots[3] = l.pivots[2] + pivot_state_size(nv + m);
    l.end = l.pivots[3] + pivot_state_size(nv + m);
    return l;
}
}  // namespace

std::size_t Stepper::checkpoint_size(bool layout3) const
{
    return layout(nq_, nv_, m_, layout3).end + 6 * static_cast<std::size_t>(r());
}

void Stepper::save_checkpoint(double *buf, const StepController &control) const
{
    const Layout l = layout(nq_, nv_, m_);
    const State &s = accepted_;
    const MatrixRecipe &r = recipe_;
    std::fill(buf, buf + l.end, 0.0);
    const double tangents =
        (r.K ? 1.0 : 0.0) + (r.C ? 2.0 : 0.0) + (r.Z ? 4.0 : 0.0) + (r.central ? 8.0 : 0.0);
    const double header[kHeader] = {kStateMagic,
                                    kStateVersion,
                                    static_cast<double>(nv_),
                                    static_cast<double>(m_),
                                    s.t,
                                    s.h_last,
                                    control.h_next,
                                    control.err_prev,
                                    control.grew ? 1.0 : 0.0,
                                    s.sliver_span,
                                    jacobian_valid_ ? 1.0 : 0.0,
                                    // the recipe only with a kept matrix (a failed step may
                                    // have factorized and left its time there)
                                    jacobian_valid_ ? r.t : 0.0,
                                    jacobian_valid_ ? r.h : 0.0,
                                    jacobian_valid_ ? r.t_b : 0.0,
                                    jacobian_valid_ ? tangents : 0.0,
                                    // without a matrix the rate is stale and unused
                                    jacobian_valid_ ? theta_prev_ : -1.0,
                                    static_cast<double>(refresh_steps_left_),
                                    static_cast<double>(reuse_backoff_),
                                    fd_tangents_ ? 1.0 : 0.0,
                                    static_cast<double>(s.c_count),
                                    s.c_count == 2 ? s.c_dt : 0.0};
    std::copy(header, header + kHeader, buf);
    double *p = buf + kHeader;
    // (c and c_prev as zeros where they are not known, and the recipe without a kept matrix:
    // the same state, the same checkpoint; a stale recipe may hold a failed iterate's NaN)
    const Vec *recipe[] = {&r.q, &r.v, &r.qdd, &r.lambda, &r.q_b, &r.xi};
    for (const Vec *x : {&s.q, &s.v, &s.qdd, &s.lambda, &s.a, &s.a_prev, &s.c, &s.c_prev, &r.q,
                         &r.v, &r.qdd, &r.lambda, &r.q_b, &r.xi}) {
        const bool stale = !jacobian_valid_ && std::find(std::begin(recipe), std::end(recipe),
                                                         x) != std::end(recipe);
        if ((x == &s.c && s.c_count < 1) || (x == &s.c_prev && s.c_count < 2) || stale)
            Eigen::Map<Vec>(p, x->size()).setZero();
        else
            Eigen::Map<Vec>(p, x->size()) = *x;
        p += x->size();
    }
    for (int i = 0; i < m_; ++i)
        buf[l.active + i] = constraint_active(i) ? 1.0 : 0.0;
    S_.save_pivots(buf + l.pivots[0]);
    S2_.save_pivots(buf + l.pivots[1]);
    P_.save_pivots(buf + l.pivots[2]);
    O_.save_pivots(buf + l.pivots[3]);
    p = buf + l.end;
    for (const Vec *x : {&s.y, &s.ydot, &s.w, &s.w_prev, &r.y, &r.ydot}) {
        if (!jacobian_valid_ && (x == &r.y || x == &r.ydot))
            Eigen::Map<Vec>(p, x->size()).setZero();
        else
            Eigen::Map<Vec>(p, x->size()) = *x;
        p += x->size();
    }
}

// The checks of a checkpoint, before anything changes (the transaction's own come after).
ga_status Stepper::check_checkpoint(const double *buf, std::size_t len, std::size_t tail)
{
    const bool layout2 = len >= 2 && buf[0] == kStateMagic && buf[1] == 2.0;
    const bool layout3 = len >= 2 && buf[0] == kStateMagic && buf[1] == 3.0;
    const Layout l = layout(nq_, nv_, m_, layout3);
    const std::size_t expected =
        layout2 ? kHeader2 + static_cast<std::size_t>(nq_) + 4 * static_cast<std::size_t>(nv_) +
                      static_cast<std::size_t>(m_)
                : checkpoint_size(layout3) + tail;
    if (len != expected)
        return diag.fail(GA_ERR_ARG, "checkpoint has %zu doubles, this solver needs %zu", len,
                         expected);
    if (layout2 && r() > 0)
        return diag.fail(GA_ERR_ARG, "a layout-2 checkpoint has no first-order states; this "
                         "solver has %d", r());
    if (buf[0] != kStateMagic || (buf[1] != kStateVersion && !layout2 && !layout3))
        return diag.fail(GA_ERR_ARG, "not a galpha checkpoint (magic %g, layout version %g)",
                         buf[0], buf[1]);
    if (buf[2] != nv_ || buf[3] != m_)
        return diag.fail(GA_ERR_ARG, "checkpoint is for n = %g, m = %g; this solver has n = %d, "
                         "m = %d", buf[2], buf[3], nv_, m_);
    for (std::size_t k = 4; k < len; ++k)
        if (!std::isfinite(buf[k]))
            return diag.fail(GA_ERR_ARG, "checkpoint entry %zu is not finite", k);
    // The step-size controller's entries as a solver writes them: h_last is 0 (no step yet) or
    // a step that moves t (ga_step refuses others), h_next 0 (no proposal) or positive;
    // err_prev is not negative; grew is a flag. Anything else was not written by galpha, and
    // would fail later, far from here (h_last = 1e-320 multiplies a_n by 1e317 when it is
    // rescaled for the next step). (h_next may be a proposal that no longer moves t -- 7e-15
    // made near t = 0, then a ga_step to t = 1000: the solver refused its own checkpoint;
    // an adaptive step raises a proposal to its minimum.)
    const double t = buf[4];
    if (buf[5] < 0.0 || (buf[5] > 0.0 && t + buf[5] == t && t - buf[5] == t))
        return diag.fail(GA_ERR_ARG, "checkpoint entry 5 (h_last = %g) is not a step from "
                         "t = %.17g", buf[5], t);
    if (buf[6] < 0.0)
        return diag.fail(GA_ERR_ARG, "checkpoint entry 6 (h_next = %g) is negative", buf[6]);
    if (buf[7] < 0.0 || !is_flag(buf[8]))
        return diag.fail(GA_ERR_ARG, "checkpoint entries 7-8 (err_prev = %g, grew = %g) are "
                         "not those of galpha's step-size control", buf[7], buf[8]);
    const double sliver_span = layout2 ? 0.0 : buf[9];
    if (sliver_span < 0.0 || sliver_span > buf[5] / kShortStepRatio)
        return diag.fail(GA_ERR_ARG, "checkpoint entry 9 (sliver_span = %g) is not a span of "
                         "short steps after steps of h_last = %g", sliver_span, buf[5]);
    const bool kept = !layout2 && buf[10] == 1.0;
    if (!layout2 && (!is_flag(buf[10]) || (kept && !(buf[12] > 0.0)) ||
                     !is_count(buf[14], 15.0) || !(buf[15] == -1.0 || buf[15] >= 0.0) ||
                     !is_count(buf[16], 32.0) || !is_count(buf[17], 32.0) ||
                     !(buf[17] >= 1.0) || !is_flag(buf[18])))
        return diag.fail(GA_ERR_ARG, "checkpoint entries 10-18 (the kept iteration matrix and "
                         "its reuse) are not those a solver writes");
    const bool with_c = !layout2 && !layout3;
    if (with_c && (!is_count(buf[19], 2.0) || buf[20] < 0.0 || (buf[19] == 2.0 && !(buf[20] > 0.0))))
        return diag.fail(GA_ERR_ARG, "checkpoint entries 19-20 (c_count = %g, c_dt = %g: the "
                         "consistent accelerations of the error estimate) are not those a "
                         "solver writes", buf[19], buf[20]);
    // The constraints in use: as the checkpoint says (layout 2, which does not say, selects
    // them anew at its q). Dropped ones need a solver that drops them.
    for (int i = 0; i < m_ && !layout2; ++i) {
        const double in_use = buf[l.active + i];
        if (!is_flag(in_use))
            return diag.fail(GA_ERR_ARG, "checkpoint entry %zu (constraint %d in use: %g) is "
                             "neither 0 nor 1", l.active + i, i, in_use);
        if (in_use == 0.0 && redundancy != GA_REDUNDANT_DROP)
            return diag.fail(GA_ERR_ARG, "the checkpoint dropped constraint %d as redundant; "
                             "this solver keeps every constraint (GA_REDUNDANT_DROP drops them)",
                             i);
    }
    // (On a group space: q holds rotations, as ga_init asks of q0; so does the q the kept
    // matrix was evaluated at, at l.matrix.)
    const std::size_t q_at = layout2 ? kHeader2 : layout3 ? kHeader3 : kHeader;
    for (const std::size_t at : {q_at, l.matrix}) {
        if (at != q_at && !kept)
            continue;
        if (const Eigen::Index bad = model.space.invalid_rotation(buf + at); bad >= 0)
            return diag.fail(GA_ERR_ARG, "checkpoint entries %zu.. (q[%ld..]) are not a rotation",
                             at + static_cast<std::size_t>(bad), static_cast<long>(bad));
    }
    if (!model.ready())
        return diag.fail(GA_ERR_STATE, "ga_set_state needs the callbacks (ga_set_callbacks)");
    return GA_OK;
}

ga_status Stepper::load_checkpoint(const double *buf, bool internal, bool keep_matrix,
                                   StepController &control)
{
    const bool layout2 = buf[1] == 2.0;
    const bool layout3 = buf[1] == 3.0;
    const Layout l = layout(nq_, nv_, m_, layout3);
    const bool kept = !layout2 && buf[10] == 1.0;
    const bool with_c = !layout2 && !layout3;
    const int c_count = with_c ? static_cast<int>(buf[19]) : 0;  // a count of 0-2 (checked)
    const double sliver_span = layout2 ? 0.0 : buf[9];
    if (auto st = setup())
        return st;
    if (!layout2) {
        // The projection and the output matrix take their pivots now, as in the solver they
        // came from, where they existed (set up there by an adaptive step, or by output).
        if (buf[l.pivots[2]] == 1.0)
            setup_projection();
        if (buf[l.pivots[3]] == 1.0)
            setup_output();
        if (!S_.pivots_loadable(buf + l.pivots[0]) || !S2_.pivots_loadable(buf + l.pivots[1]) ||
            !P_.pivots_loadable(buf + l.pivots[2]) || !O_.pivots_loadable(buf + l.pivots[3]))
            return diag.fail(GA_ERR_ARG, "checkpoint entries %zu-%zu (the pivots of the sparse "
                             "factorizations) are not those a solver writes", l.pivots[0],
                             l.end - 1);
    }
    if (redundancy == GA_REDUNDANT_DROP && m_ > 0) {
        if (layout2) {
            const Vec q = Eigen::Map<const Vec>(buf + kHeader2, nq_);
            const std::vector<unsigned char> active_before = active_;
            if (auto st = select_active_constraints(buf[4], q)) {
                restore_active(active_before);
                return st;
            }
        } else {
            bool changed = false;  // in place: the linear algebra holds active_'s address
            for (int i = 0; i < m_; ++i) {
                const unsigned char in_use = buf[l.active + i] != 0.0;
                changed = changed || active_[i] != in_use;
                active_[i] = in_use;
            }
            if (changed)
                invalidate_jacobian();
        }
    }
    State &s = accepted_;
    s.t = buf[4];
    s.h_last = buf[5];
    s.sliver_span = sliver_span;
    control.h_next = buf[6];
    control.err_prev = buf[7];
    control.grew = buf[8] != 0.0;
    const double *p = buf + (layout2 ? kHeader2 : layout3 ? kHeader3 : kHeader);
    for (Vec *x : {&s.q, &s.v, &s.qdd, &s.lambda, &s.a, &s.a_prev}) {
        *x = Eigen::Map<const Vec>(p, x->size());
        p += x->size();
    }
    // A state the check let through up to 1e-6 off is made exact; a solver's own is restored
    // bit for bit: from ga_init's 1e-10 its error moves as the step rotates it (the largest
    // entry of R^T R - I by up to 3x) and by round-off, and passed 1e-10 (fuzzer finding:
    // the restored run then differed by 5e-11), but stays far below 1e-8.
    if (!model.space.euclidean())
        model.space.normalize_rotations(s.q.data(), ConfigurationSpace::kRestoreExact);
    s.c_count = c_count;
    s.c_dt = with_c ? buf[20] : 0.0;
    for (Vec *x : {&s.c, &s.c_prev}) {
        if (with_c) {
            *x = Eigen::Map<const Vec>(p, x->size());
            p += x->size();
        } else {
            x->setZero();
        }
    }
    const double *py = buf + l.end;
    if (!layout2) {
        for (Vec *x : {&s.y, &s.ydot, &s.w, &s.w_prev, &recipe_.y, &recipe_.ydot}) {
            *x = Eigen::Map<const Vec>(py, x->size());
            py += x->size();
        }
    }
    invalidate_jacobian();
    previous_valid_ = false;
    ++state_id_;
    // A checkpoint from before the first step (h_last = 0) still owes that step its corrected
    // starting values, as the solver it was taken from does.
    start_pending_ = s.h_last == 0.0;
    initialized_ = true;
    if (layout2) {
        pivots_forgotten_ = true;
        return GA_OK;
    }

    pivots_forgotten_ = false;
    if (!keep_matrix) {  // (else they hold the factors of this very state)
        S_.load_pivots(buf + l.pivots[0]);
        S2_.load_pivots(buf + l.pivots[1]);
    }
    P_.load_pivots(buf + l.pivots[2]);
    O_.load_pivots(buf + l.pivots[3]);
    if (kept && keep_matrix) {
        MatrixRecipe &r = recipe_;
        r.t = buf[11];
        r.h = buf[12];
        r.t_b = buf[13];
        const int tangents = static_cast<int>(buf[14]);
        r.K = (tangents & 1) != 0;
        r.C = (tangents & 2) != 0;
        r.Z = (tangents & 4) != 0;
        r.central = (tangents & 8) != 0;
        for (Vec *x : {&r.q, &r.v, &r.qdd, &r.lambda, &r.q_b, &r.xi}) {
            *x = Eigen::Map<const Vec>(p, x->size());
            p += x->size();
        }
        jacobian_valid_ = true;
        jacobian_h_ = r.h;
        schur_valid_ = false;
    } else if (kept) {
        MatrixRecipe &r = recipe_;
        r.t = buf[11];
        r.h = buf[12];
        r.t_b = buf[13];
        const int tangents = static_cast<int>(buf[14]);
        r.K = (tangents & 1) != 0;
        r.C = (tangents & 2) != 0;
        r.Z = (tangents & 4) != 0;
        r.central = (tangents & 8) != 0;
        for (Vec *x : {&r.q, &r.v, &r.qdd, &r.lambda, &r.q_b, &r.xi}) {
            *x = Eigen::Map<const Vec>(p, x->size());
            p += x->size();
        }
        // A callback that fails now costs the restored run its bit-identity only: it goes on
        // as after a restart (layout 2), with a fresh matrix and the reuse history forgotten.
        // The adjoint sweep's own restores need the matrix, and say so.
        if (const ga_status st = rebuild_matrix()) {
            invalidate_jacobian();
            if (internal)
                return st;
            diag.clear();
            return GA_OK;
        }
    }
    theta_prev_ = jacobian_valid_ ? buf[15] : -1.0;
    refresh_steps_left_ = static_cast<int>(buf[16]);
    reuse_backoff_ = static_cast<int>(buf[17]);
    fd_tangents_ = buf[18] != 0.0;
    return GA_OK;
}

// The kept iteration matrix, evaluated and factorized as Newton did (Stepper::newton).
ga_status Stepper::rebuild_matrix()
{
    const MatrixRecipe &r = recipe_;
    // A recipe whose tangent this workspace holds no storage for (the sparse path keeps no
    // dense K_t or C_t it did not need at setup; the callbacks changed since, or the
    // checkpoint came from another solver): no rebuild, a fresh matrix (the caller's choice)
    const auto unheld = [](const ModelMatrix &A) {
        return A.dense() && A.size() != static_cast<Eigen::Index>(A.rows()) * A.cols();
    };
    if ((r.K && unheld(K_)) || (r.C && unheld(C_)))
        return diag.fail(GA_ERR_STATE, "the checkpoint's kept matrix holds %s, for which this "
                         "solver's sparse path has no pattern", r.K && unheld(K_) ? "K_t" : "C_t");
    State &x = trial_;  // scratch between steps
    if (!model.space.euclidean())
        xi_ = r.xi;  // the T(xi) the matrix took
    x.q = r.q;
    x.v = r.v;
    x.qdd = r.qdd;
    x.lambda = r.lambda;
    x.y = r.y;
    x.ydot = r.ydot;
    ga_status st = residual(r.t, x);
    if (!st && formulation == GA_INDEX2_STABILIZED && m_ > 0) {
        st = model.jacobian(r.t_b, r.q_b, B_);
        b_t_ = r.t_b;
        b_q_ = &r.q_b;
    }
    const ga_tangent_mode mode = model.tangent_mode;
    const Restore<ga_tangent_mode> keep_mode(model.tangent_mode);
    if (r.central)  // the exact matrix of the sensitivities (factorize_exact)
        model.tangent_mode = GA_TANGENT_AUTO;
    if (!st && r.K)
        st = model.stiffness(r.t, x.q, x.v, x.qdd, x.lambda, rq_, M_, K_, r.central);
    if (!st && r.C)
        st = model.damping(r.t, x.q, x.v, f_, C_, r.central);
    if (!st && r.Z)
        st = model.velocity_constraint_tangent(r.t, x.q, x.v, J_, Z_, r.central);
    model.tangent_mode = mode;
    if (!st && this->r() > 0)
        st = first_order_matrix(r.t, x, r.central);
    const bool central = r.central;
    if (!st)
        st = factorize(r.t, x, r.h, r.K, r.C, r.Z, 0);
    recipe_.central = central && !st;
    return st;
}

}  // namespace ga
