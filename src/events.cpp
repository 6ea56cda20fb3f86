#include "events.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ga {

namespace {
// +1 / -1: function k crosses zero from a to b in a direction it watches; 0: it does not.
int crossing(double a, double b, int direction)
{
    if (a < 0.0 && b >= 0.0 && direction >= 0)
        return 1;
    if (a > 0.0 && b <= 0.0 && direction <= 0)
        return -1;
    return 0;
}
}  // namespace

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

}  // namespace ga
