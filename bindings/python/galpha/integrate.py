"""One call from initial values to time histories, in the spirit of scipy's solve_ivp."""
import sys

import numpy as np

from .errors import GalphaError
from .solver import Solver


class _Fields(dict):
    """A dict whose keys read as attributes too (as scipy's OptimizeResult)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


class IntegrateResult(_Fields):
    """Attributes: t (N,), q, v, qdd (N, n), lam (N, m), stats (dict), success (bool),
    status (0 or the failing ga_status, 1 when a terminal event ended the run), message (str);
    with first-order states (y0): states (N, r); with events: t_events, y_events ([q, v]
    stacked), q_events, v_events, lam_events (and states_events) (lists, one array per event
    function); with dense_output: sol (OdeSolution)."""

    def __repr__(self):
        return "IntegrateResult(success=%r, message=%r, outputs=%d, steps=%d, t_end=%g)" % (
            self.success, self.message, len(self.t), self.stats.get("steps", 0), self.t[-1])


class OdeSolution:
    """The whole run's interpolant, as scipy's dense output: sol(t) is y = [q; v] at t (shape
    (2n,) for a scalar t, (2n, k) for k times) anywhere in [t_min, t_max]; sol.q(t), sol.v(t)
    the halves. Inside each accepted step, q and v are cubic Hermite interpolants from q, v and
    the consistent qdd at its two ends (third-order local accuracy, as ga_interpolate)."""

    def __init__(self, ts, qs, vs, qdds):
        self.ts = np.asarray(ts, dtype=float)
        self._q, self._v, self._a = (np.asarray(x, dtype=float) for x in (qs, vs, qdds))
        self.t_min, self.t_max = float(self.ts[0]), float(self.ts[-1])

    def _both(self, t):
        t = np.asarray(t, dtype=float)
        scalar = t.ndim == 0
        t = np.atleast_1d(t)
        if np.any(t < self.t_min) or np.any(t > self.t_max) or np.any(np.isnan(t)):
            raise ValueError("t outside the run [%g, %g]" % (self.t_min, self.t_max))
        i = np.clip(np.searchsorted(self.ts, t, side="right") - 1, 0, max(len(self.ts) - 2, 0))
        if len(self.ts) == 1:
            q, v = self._q[i].T, self._v[i].T
            return (q[:, 0], v[:, 0]) if scalar else (q, v)
        h = self.ts[i + 1] - self.ts[i]
        th = ((t - self.ts[i]) / h)[:, None]
        hh = h[:, None]
        h00, h10 = (2 * th - 3) * th * th + 1, ((th - 2) * th + 1) * th
        h01, h11 = (3 - 2 * th) * th * th, (th - 1) * th * th
        q0, q1, v0, v1 = self._q[i], self._q[i + 1], self._v[i], self._v[i + 1]
        a0, a1 = self._a[i], self._a[i + 1]
        q = h00 * q0 + h10 * hh * v0 + h01 * q1 + h11 * hh * v1
        v = h00 * v0 + h10 * hh * a0 + h01 * v1 + h11 * hh * a1
        return (q[0], v[0]) if scalar else (q.T, v.T)

    def __call__(self, t):
        q, v = self._both(t)
        return np.concatenate([q, v])

    def q(self, t):
        return self._both(t)[0]

    def v(self, t):
        return self._both(t)[1]


def _progress_bar(progress, t0, t1, unit="s"):
    """A tqdm bar over simulated time (or runs), or None: progress=None shows one on a terminal
    for runs that last over a second, if tqdm is installed (Debian: python3-tqdm); True asks
    for it (tqdm needed), False never."""
    if progress is False:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        if progress:
            raise
        return None
    if progress is None and not sys.stderr.isatty():
        return None
    if unit != "s":
        return tqdm(total=t1 - t0, unit=unit, delay=0.0 if progress else 1.0, desc="galpha",
                    leave=False)
    return tqdm(total=t1 - t0, unit="s", unit_scale=True, delay=0.0 if progress else 1.0,
                desc="galpha", leave=False, bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s "
                "[{elapsed}<{remaining}]")


def integrate(mass, force, constraint, jacobian, t_span, q0, v0, h=None, *, m=None, t_eval=None,
              events=None, dense_output=False, y0=None, progress=None, **options):
    """Integrate from t_span[0] to t_span[1] and record every accepted step, or the states at
    the times t_eval (by dense output, without shortening steps).

    With h: fixed steps h (the last one shortened to land on t_span[1]). Without h: adaptive
    steps controlled by `tolerances=(rtol, atol)` (default 1e-6, 1e-6); the stabilized index-2
    formulation is recommended then (`formulation=galpha.GA_INDEX2_STABILIZED`).

    m, the number of constraints, must be given with constraint callbacks (it was taken as 0,
    which dropped them); without them it is 0.

    events: a callable or a list of them, g(t, q, v, lam) -> float, with scipy's attributes:
    `direction` (> 0 rising, < 0 falling, 0 either) and `terminal` (True, or the number of
    occurrences after which the run ends; default False), and `multipliers` (True: lam holds the
    consistent multipliers at the located state; else None). Their roots are located on the
    dense output of each step (ga_set_events); the result holds t_events, y_events, q_events,
    v_events and lam_events, and a terminal event ends the run at its time (status 1), the last
    recorded point being the event's state.

    dense_output: the result's `sol` is the whole run's interpolant (OdeSolution) of q and v.

    progress: a progress bar over simulated time (tqdm, optional): None (default) shows it on a
    terminal once a run has lasted a second, True always, False never.

    Adaptive runs without events record through the step hook (Solver.set_step_hook) inside
    one call of Solver.advance; fixed steps and runs with events step from Python.

    y0: the initial first-order states, with the options r, rate, force_y (and coupling) of
    Solver; the result's `states` holds their history, and event functions are then
    g(t, q, v, lam, y).

    `options` go to Solver (rho_inf, newton, stiffness, constraint_accel, ...). A failure of
    the method (no convergence, singular matrix, ...) ends the integration with success=False
    and the histories up to the last accepted step; an exception raised by a callback is
    re-raised.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError("t_span = (%g, %g): the end must come after the start" % (t0, t1))
    if h is not None and not (float(h) > 0.0 and np.isfinite(float(h))):
        raise ValueError("h = %r: a fixed step must be positive and finite" % (h,))
    if (constraint is None) != (jacobian is None):
        raise ValueError("constraint and jacobian come together (or neither: m = 0)")
    if t_eval is not None and any(not t0 <= float(t) <= t1 for t in t_eval):
        raise ValueError("t_eval: every time must lie in t_span = [%g, %g]" % (t0, t1))
    q0 = np.asarray(q0, dtype=float)
    n, nq = np.asarray(v0).size, q0.size  # (nq != n on a space with rotations)
    if dense_output and nq != n:
        raise ValueError("dense_output: the whole run's interpolant is a polynomial in q, "
                         "not defined on a space with rotations; use t_eval (galpha's own "
                         "dense output on the group) instead")
    if m is None:
        if constraint is not None:
            raise ValueError("constraint callbacks given without m: say how many constraints "
                             "they compute (m=...)")
        m = 0
    elif m == 0 and constraint is not None:
        raise ValueError("m = 0 with constraint callbacks: they would be ignored; give m")
    if events is None:
        events = []
    elif callable(events):
        events = [events]
    events = list(events)
    left = []  # occurrences left before each terminal event ends the run (None: never)
    for g in events:
        terminal = getattr(g, "terminal", False)
        if terminal is True or terminal is False or terminal is None:
            left.append(1 if terminal else None)
        elif int(terminal) >= 1 and int(terminal) == terminal:
            left.append(int(terminal))
        else:
            raise ValueError("event %r: terminal = %r must be a bool or a positive count"
                             % (getattr(g, "__name__", g), terminal))
    t_ev = [[] for _ in events]
    q_ev = [[] for _ in events]
    v_ev = [[] for _ in events]
    l_ev = [[] for _ in events]
    ts, qs, vs, as_, ls = [], [], [], [], []
    with_states = y0 is not None
    xs, x_ev = [], [[] for _ in events]  # first-order states
    knots = ([], [], [], [])  # dense output: t, q, v, qdd at every accepted step
    status, message = 0, "reached t_span[1]"
    with Solver(n, m, mass, force, constraint, jacobian, **options) as s:
        if with_states:
            s.init(t0, q0, v0, y0)
        else:
            s.init(t0, q0, v0)

        def states_at(te):
            if with_states:
                xs.append(s.y if te == s.t else s.interpolate_y(te)[0])
        if events:
            # all logged, none terminal in C: the run ends here, after the terminal one's
            # occurrence, and every event of a step lies in the step just taken
            class _Logged:
                def __init__(self, g):
                    self.g, self.direction = g, getattr(g, "direction", 0)

                def __call__(self, t, q, v, lam, *y):
                    return self.g(t, q, v, lam, *y)
            s.set_events([_Logged(g) for g in events],
                         multipliers=any(getattr(g, "multipliers", False) for g in events),
                         states=with_states)

        def knot():
            knots[0].append(s.t)
            knots[1].append(s.q)
            knots[2].append(s.v)
            knots[3].append(s.qdd)

        def record_events():
            """Records the events of the last step; the time of a terminal one, else None."""
            for te, k, _ in s.events:
                qi, vi, li = s.interpolate(te)
                t_ev[k].append(te)
                q_ev[k].append(qi)
                v_ev[k].append(vi)
                l_ev[k].append(li)
                if with_states:
                    x_ev[k].append(s.interpolate_y(te)[0])
                if left[k] is not None:
                    left[k] -= 1
                    if left[k] == 0:
                        return te
            return None

        def record():
            states_at(s.t)
            ts.append(s.t)
            qs.append(s.q)
            vs.append(s.v)
            as_.append(s.qdd)
            ls.append(s.lam)

        def record_eval(t_prev):
            while pending and pending[0] <= s.t:
                te = pending.pop(0)
                if te == s.t or te == t_prev:
                    record()
                    ts[-1] = te
                else:
                    qi, vi, li = s.interpolate(te)
                    states_at(te)
                    ts.append(te)
                    qs.append(qi)
                    vs.append(vi)
                    as_.append(s.interpolate_qdd(te))
                    ls.append(li)

        pending = sorted(float(t) for t in t_eval) if t_eval is not None else None
        if pending is None:
            record()
        else:
            record_eval(t0)
        if dense_output:
            knot()
        bar = _progress_bar(progress, t0, t1)
        if h is None and not events:
            last = [t0]

            def after_step(t, q, v, lam):
                if pending is None:
                    record()
                else:
                    record_eval(last[0])
                if dense_output:
                    knot()
                if bar is not None:
                    bar.update(t - last[0])
                last[0] = t
            s.set_step_hook(after_step)
            try:
                s.advance(t1)
            except GalphaError as e:
                status, message = e.status, str(e)
            finally:
                if bar is not None:
                    bar.close()
            stepped = True
        else:
            stepped = False
        while not stepped:
            remaining = t1 - s.t
            if remaining <= 1e-12 * max(1.0, abs(t1)):
                break
            t_prev = s.t
            try:
                if h is None:
                    s.step_adaptive(t1)
                else:
                    s.step(h if remaining > h * (1.0 + 1e-9) else remaining)
            except GalphaError as e:
                status, message = e.status, str(e)
                break
            t_end = record_events() if events else None
            if t_end is not None:
                # the run ends at the event: outputs up to it, then its state
                while pending and pending[0] < t_end:
                    te = pending.pop(0)
                    qi, vi, li = s.interpolate(te) if te > t_prev else (qs[-1], vs[-1], ls[-1])
                    if with_states:
                        xs.append(s.interpolate_y(te)[0] if te > t_prev else xs[-1])
                    ts.append(te)
                    qs.append(qi)
                    vs.append(vi)
                    as_.append(s.interpolate_qdd(te) if te > t_prev else as_[-1])
                    ls.append(li)
                qi, vi, li = s.interpolate(t_end)
                ai = s.interpolate_qdd(t_end)
                states_at(t_end)
                ts.append(t_end)
                qs.append(qi)
                vs.append(vi)
                as_.append(ai)
                ls.append(li)
                if dense_output:
                    for x, y in zip(knots, (t_end, qi, vi, ai)):
                        x.append(y)
                status, message = 1, "a terminal event occurred"
                break
            if pending is None:
                record()
            else:
                record_eval(t_prev)
            if dense_output:
                knot()
            if bar is not None:
                bar.update(s.t - t_prev)
        if bar is not None and not stepped:
            bar.close()
        stats = s.stats
    result = IntegrateResult(t=np.array(ts), q=np.array(qs), v=np.array(vs),
                             qdd=np.array(as_), lam=np.array(ls).reshape(len(ts), m),
                             stats=stats, success=status >= 0, status=status, message=message)
    if with_states:
        result["states"] = np.array(xs).reshape(len(ts), len(np.atleast_1d(y0)))
    if events:
        result["t_events"] = [np.array(x) for x in t_ev]
        if with_states:
            result["states_events"] = [np.array(x).reshape(len(x), len(np.atleast_1d(y0)))
                                       for x in x_ev]
        result["q_events"] = [np.array(x).reshape(len(x), nq) for x in q_ev]
        result["v_events"] = [np.array(x).reshape(len(x), n) for x in v_ev]
        result["lam_events"] = [np.array(x).reshape(len(x), m) for x in l_ev]
        result["y_events"] = [np.hstack([a, b]) for a, b in
                              zip(result["q_events"], result["v_events"])]
    if dense_output:
        result["sol"] = OdeSolution(*knots)
    return result
