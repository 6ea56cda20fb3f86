#include "events.hpp"

#include "model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ga {

void EventLocator::setup(int count)
{
    lo_.assign(count, 0.0);
    hi_.assign(count, 0.0);
    mid_.assign(count, 0.0);
}

int EventLocator::locate(double t0, const double *g0, double t1, const double *g1,
                         const int *direction, Evaluate g, void *context, double *t_root,
                         int *fired)
{
    const int K = count();
    evaluations_ = 0;
    bool any = false;
    for (int k = 0; k < K; ++k)
        any = any || crossing(g0[k], g1[k], direction[k]) != 0;
    if (!any)
        return 0;
    std::copy(g0, g0 + K, lo_.begin());
    std::copy(g1, g1 + K, hi_.begin());
    double lo = t0, hi = t1;
    const double tol =
        100.0 * std::numeric_limits<double>::epsilon() * (std::fabs(t1) + std::fabs(t1 - t0));
    // Illinois: the end kept twice in a row has its values halved in the secant, so that the
    // bracket shrinks from both sides (the plain secant keeps one end for ever on a convex g).
    double w_lo = 1.0, w_hi = 1.0;
    int kept = 0;  // -1: lo kept last time, +1: hi kept last time
    // Bisection whenever two tries have not halved the bracket: never much worse than
    // bisection (a flat crossing stalls the secant near one end), as in Dekker's method.
    double width[2] = {hi - lo, hi - lo};  // before the last two tries: the first bisects
    while (hi - lo > tol) {
        // The secant root of each crossing function; the earliest of them is tried.
        double mid = hi;
        for (int k = 0; k < K; ++k) {
            if (!crossing(lo_[k], hi_[k], direction[k]))
                continue;
            const double a = w_lo * lo_[k], b = w_hi * hi_[k];
            const double t = b == a ? hi : hi - (hi - lo) * b / (b - a);
            mid = std::min(mid, t);
        }
        if (hi - lo > 0.5 * width[0])
            mid = 0.5 * (lo + hi);
        width[0] = width[1];
        width[1] = hi - lo;
        mid = std::clamp(mid, lo + 0.5 * tol, hi - 0.5 * tol);
        if (const int st = g(mid, mid_.data(), context))
            return st;
        ++evaluations_;
        bool before = false;  // a crossing in (lo, mid]
        for (int k = 0; k < K; ++k)
            before = before || crossing(lo_[k], mid_[k], direction[k]) != 0;
        if (before) {
            hi = mid;
            hi_.swap(mid_);
            w_hi = 1.0;
            w_lo = kept == -1 ? 0.5 * w_lo : 1.0;
            kept = -1;
        } else {
            lo = mid;
            lo_.swap(mid_);
            w_lo = 1.0;
            w_hi = kept == 1 ? 0.5 * w_hi : 1.0;
            kept = 1;
        }
    }
    *t_root = hi;
    for (int k = 0; k < K; ++k)
        fired[k] = crossing(lo_[k], hi_[k], direction[k]);
    return 1;
}

void EventSet::configure(int count, ga_event_fn fn, ga_event_y_fn fn_y, const int *direction,
                         const int *terminal, bool with_lambda, int nq, int nv, int m,
                         int r)
{
    // everything is allocated before anything changes: a failure leaves the old set
    std::vector<int> dir(count), term(count), fired(count);
    std::vector<double> lo(count), hi(count), slo(count), shi(count), past(count),
        start(count);
    std::vector<double> qs(count ? nq : 0), vs(count ? nv : 0), ls(count && with_lambda ? m : 0);
    std::vector<double> ys(count && fn_y ? r : 0);
    // a whole root fits into an empty log, however many functions cross at it
    std::vector<Entry> log(count ? std::max(count, GA_EVENT_LOG) : 0);
    EventLocator locator_new;
    locator_new.setup(count);
    for (int k = 0; k < count; ++k) {
        dir[k] = direction ? direction[k] : GA_EVENT_BOTH;
        term[k] = terminal ? (terminal[k] != 0) : 1;
    }
    fn_ = count && !fn_y ? fn : nullptr;
    fn_y_ = count ? fn_y : nullptr;
    with_lambda_ = count && with_lambda;
    direction_.swap(dir);
    terminal_.swap(term);
    this->fired.swap(fired);
    g_lo.swap(lo);
    g_hi.swap(hi);
    g_past.swap(past);
    g_start.swap(start);
    saved_g_lo_.swap(slo);
    saved_g_hi_.swap(shi);
    q.swap(qs);
    v.swap(vs);
    lambda.swap(ls);
    y.swap(ys);
    log_.swap(log);
    locator = std::move(locator_new);
    log_count_ = 0;
    started = false;
}

// g_lo and g_hi change under a failing call only where it searched the rest of a step first
// (search_events leaves them alone when it fails): only then are they copied.
void EventSet::save()
{
    saved_started_ = started;
    saved_t_lo_ = t_lo;
    saved_t_hi_ = t_hi;
    saved_log_count_ = log_count_;
    saved_values_ = started && t_lo < t_hi;
    if (saved_values_) {
        std::copy(g_lo.begin(), g_lo.end(), saved_g_lo_.begin());
        std::copy(g_hi.begin(), g_hi.end(), saved_g_hi_.begin());
    }
}

void EventSet::restore()
{
    started = saved_started_;
    t_lo = saved_t_lo_;
    t_hi = saved_t_hi_;
    log_count_ = saved_log_count_;
    if (saved_values_) {
        std::copy(saved_g_lo_.begin(), saved_g_lo_.end(), g_lo.begin());
        std::copy(saved_g_hi_.begin(), saved_g_hi_.end(), g_hi.begin());
    }
}

// g at t: at the end of the last step from the accepted state, inside it from the dense
// output, with lambda (if asked for) as ga_get_lambda and ga_interpolate give it.
ga_status EventSet::values(StepOutput &out, double t, double *g)
{
    EventSet &e = *this;
    double *lambda = e.with_lambda() ? e.lambda.data() : nullptr;
    const double *q = out.positions(), *v = out.velocities(), *y = out.first_order_states();
    if (t == out.time()) {
        if (lambda)
            if (auto st = out.multipliers(lambda))
                return st;
    } else {
        if (auto st = out.interpolate_at(t, e.q.data(), e.v.data(), lambda))
            return st;
        q = e.q.data();
        v = e.v.data();
        if (e.fn_y()) {
            if (auto st = out.interpolate_y_at(t, e.y.data()))
                return st;
            y = e.y.data();
        }
    }
    return out.callbacks().event_functions(e.fn(), e.fn_y(), t, q, v, y, lambda, g, e.count());
}

// A function exactly zero at the start of the search (at ga_init, a restart, or where a
// search stopped) cannot say from that value where it goes: g = t (0.05 - t) from t0 = 0 fell
// through zero at 0.05 unseen in a step of 0.1. Its value just past the start says it (as
// IDA looks past t0): 1e-6 of the interval, or 100 ulps of t where that is more.
ga_status EventSet::start_values(StepOutput &out, const double **start)
{
    EventSet &e = *this;
    *start = e.g_lo.data();
    bool zero = false;
    for (int k = 0; k < e.count(); ++k)
        zero = zero || (e.g_lo[k] == 0.0 && e.g_hi[k] != 0.0);
    const double span = e.t_hi - e.t_lo;
    const double past = std::max(1e-6 * span, 100.0 * std::numeric_limits<double>::epsilon() *
                                                  (std::fabs(e.t_lo) + span));
    if (!zero || !(past < span))
        return GA_OK;
    if (auto st = values(out, e.t_lo + past, e.g_past.data()))
        return st;
    for (int k = 0; k < e.count(); ++k)
        e.g_start[k] = e.g_lo[k] == 0.0 ? e.g_past[k] : e.g_lo[k];
    *start = e.g_start.data();
    return GA_OK;
}

// The rest (t_lo, t_hi] of the last step: what fires there is logged in time order. GA_EVENT
// at a terminal event or a full log, the search left just after the root (or, if the next
// root's entries do not fit, before it) for the next call. A failure leaves t_lo and g_lo as
// they were (the caller's EventSet::restore puts back the log).
ga_status EventSet::search(StepOutput &out)
{
    EventSet &e = *this;
    struct Context {
        EventSet *set;
        StepOutput *out;
    } context{this, &out};
    const auto evaluate = [](double t, double *g, void *c) {
        const Context &x = *static_cast<Context *>(c);
        return static_cast<int>(x.set->values(*x.out, t, g));
    };
    double t_cur = e.t_lo;
    const double *g_cur = nullptr;
    if (auto st0 = start_values(out, &g_cur))
        return st0;
    ga_status st = GA_OK;
    while (t_cur < e.t_hi && e.any_crossing(g_cur, e.g_hi.data())) {
        double t_root = 0.0;
        const int found = e.locator.locate(t_cur, g_cur, e.t_hi, e.g_hi.data(), e.direction(),
                                           evaluate, &context, &t_root, e.fired.data());
        if (found < 0)
            return static_cast<ga_status>(found);
        if (found == 0)
            break;
        const int crossed = static_cast<int>(
            std::count_if(e.fired.begin(), e.fired.end(), [](int f) { return f != 0; }));
        if (e.logged() + crossed > e.capacity()) {
            st = GA_EVENT;
            break;
        }
        bool stop = false;
        for (int k = 0; k < e.count(); ++k) {
            if (e.fired[k]) {
                e.log(t_root, k, e.fired[k]);
                stop = stop || e.terminal(k);
            }
        }
        t_cur = t_root;
        g_cur = e.locator.root_values();
        if (stop || e.log_full()) {
            st = GA_EVENT;
            break;
        }
    }
    if (st == GA_EVENT) {
        e.t_lo = t_cur;
        if (g_cur != e.g_lo.data() && g_cur != e.g_start.data())
            std::copy(g_cur, g_cur + e.count(), e.g_lo.begin());
    } else {
        e.t_lo = e.t_hi;
        e.g_lo.swap(e.g_hi);  // g_hi is written before it is read again
    }
    return st;
}

// At the start of a stepping call: g at the current state if the search starts afresh, else
// the rest of the last step, which a call that stopped at an event left.
ga_status EventSet::resume(StepOutput &out)
{
    EventSet &e = *this;
    if (e.started)
        return e.t_lo < e.t_hi ? search(out) : GA_OK;
    if (auto st = values(out, out.time(), e.g_lo.data()))
        return st;
    e.t_lo = e.t_hi = out.time();
    e.started = true;
    return GA_OK;
}

// After a step was accepted: g at its end, and the search over it (at most steps, nothing
// crosses: then no more than that check).
ga_status EventSet::after_step(StepOutput &out)
{
    EventSet &e = *this;
    const ga_status st =
        e.with_lambda()
            ? values(out, out.time(), e.g_hi.data())
            : out.callbacks().event_functions(e.fn(), e.fn_y(), out.time(), out.positions(),
                                              out.velocities(), out.first_order_states(),
                                              nullptr, e.g_hi.data(), e.count());
    if (st)
        return st;
    e.t_hi = out.time();
    const double *start = nullptr;
    if (auto st2 = start_values(out, &start))
        return st2;
    if (e.any_crossing(start, e.g_hi.data()))
        return search(out);
    e.t_lo = e.t_hi;
    e.g_lo.swap(e.g_hi);
    return GA_OK;
}

}  // namespace ga
