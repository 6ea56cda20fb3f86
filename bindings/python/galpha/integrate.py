"""One call from initial values to time histories, with scipy's solve_ivp conventions."""
from __future__ import annotations

import inspect
import numbers
import sys
from typing import Any, Optional, Sequence, Tuple, Union

import numpy as np

from . import _ffi
from .errors import GalphaError
from .solver import ArrayLike, Solver


class _Fields(dict):
    """A dict whose keys read as attributes too (as scipy's OptimizeResult)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None


class IntegrateResult(_Fields):
    """What integrate() returns, a dict whose keys read as attributes (as scipy's OdeResult).

    t (N,); y (2n + r, N): q, v and the first-order states stacked as solve_ivp's y (rows:
    coordinates, columns: times; on a space with rotations q's rows are its nq numbers); q,
    v, qdd (N, n) and lam (N, m), a row per time; states (N, r) with first-order states;
    success (bool); status (0 reached the end, 1 a terminal event ended the run, < 0 the
    failing ga_status); message (str); nfev (residual evaluations, those of finite-difference
    tangents included), njev (evaluations of the tangent stiffness K_t), nlu (LU
    factorizations) -- solve_ivp's counters -- and stats (every counter of Solver.stats);
    with events: t_events, y_events (rows [q, v, states] at each event), q_events, v_events,
    lam_events (and states_events), lists with one array per event function; with
    dense_output: sol (OdeSolution)."""

    def __repr__(self) -> str:
        return "IntegrateResult(success=%r, message=%r, outputs=%d, steps=%d, t_end=%g)" % (
            self.success, self.message, len(self.t), self.stats.get("steps", 0),
            self.t[-1] if len(self.t) else float("nan"))  # t_eval=[]: no output times


def _hermite(th, h, x0, x1, d0, d1):
    """Cubic Hermite from values x and derivatives d at both ends (th in [0, 1]), and its
    derivative in t."""
    h00, h10 = (2 * th - 3) * th * th + 1, ((th - 2) * th + 1) * th
    h01, h11 = (3 - 2 * th) * th * th, (th - 1) * th * th
    value = h00 * x0 + h10 * h * d0 + h01 * x1 + h11 * h * d1
    g00, g10 = 6 * th * (th - 1), (3 * th - 4) * th + 1
    g11 = (3 * th - 2) * th
    slope = (g00 * (x0 - x1)) / h + g10 * d0 + g11 * d1
    return value, slope


class OdeSolution:
    """The whole run's interpolant, as scipy's dense output: sol(t) is y = [q; v; states] at
    t (shape (2n + r,) for a number t, (2n + r, k) for k times) anywhere in [t_min, t_max];
    sol.q(t), sol.v(t), sol.qdd(t), sol.lam(t) and sol.states(t) the parts, in the same
    shapes. Inside each accepted step q and v are cubic Hermite interpolants from q, v and the
    consistent qdd at its two ends (third-order local accuracy, as ga_interpolate), qdd the
    derivative of v's, the states Hermite from y and y', lam linear between the steps' (second
    order, as the method)."""

    def __init__(self, ts: ArrayLike, qs: ArrayLike, vs: ArrayLike, qdds: ArrayLike,
                 lams: ArrayLike, ys: Optional[ArrayLike] = None,
                 ydots: Optional[ArrayLike] = None) -> None:
        self.ts = np.asarray(ts, dtype=float)
        self._q, self._v, self._a, self._l = (np.asarray(x, dtype=float)
                                              for x in (qs, vs, qdds, lams))
        self._y = None if ys is None else np.asarray(ys, dtype=float)
        self._yd = None if ydots is None else np.asarray(ydots, dtype=float)
        self.t_min, self.t_max = float(self.ts[0]), float(self.ts[-1])

    def _parts(self, t):
        """q, v, qdd, lam, states at t: each (k, .) arrays, and whether t was a number."""
        t = np.asarray(t, dtype=float)
        scalar = t.ndim == 0
        t = np.atleast_1d(t).ravel()
        if np.any(t < self.t_min) or np.any(t > self.t_max) or np.any(np.isnan(t)):
            raise ValueError("t outside the run [%g, %g]" % (self.t_min, self.t_max))
        states = self._y is not None
        if len(self.ts) == 1:
            i = np.zeros(t.size, dtype=int)
            parts = (self._q[i], self._v[i], self._a[i], self._l[i],
                     self._y[i] if states else None)
            return parts, scalar
        i = np.clip(np.searchsorted(self.ts, t, side="right") - 1, 0, len(self.ts) - 2)
        h = (self.ts[i + 1] - self.ts[i])[:, None]
        th = (t[:, None] - self.ts[i][:, None]) / h
        q, _ = _hermite(th, h, self._q[i], self._q[i + 1], self._v[i], self._v[i + 1])
        v, a = _hermite(th, h, self._v[i], self._v[i + 1], self._a[i], self._a[i + 1])
        lam = (1 - th) * self._l[i] + th * self._l[i + 1]
        y = (_hermite(th, h, self._y[i], self._y[i + 1], self._yd[i], self._yd[i + 1])[0]
             if states else None)
        return (q, v, a, lam, y), scalar

    def _one(self, t, k):
        (parts, scalar) = self._parts(t)
        x = parts[k]
        return x[0] if scalar else x.T

    def __call__(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """y = [q; v; states] at t: (2n + r,) for a number, (2n + r, k) for k times."""
        (q, v, _, _, y), scalar = self._parts(t)
        stacked = np.hstack([q, v] + ([y] if y is not None else []))
        return stacked[0] if scalar else stacked.T

    def q(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """Positions at t: (n,) for a number, (n, k) for k times."""
        return self._one(t, 0)

    def v(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """Velocities at t: (n,) for a number, (n, k) for k times."""
        return self._one(t, 1)

    def qdd(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """Accelerations at t (the derivative of v's interpolant): (n,) or (n, k)."""
        return self._one(t, 2)

    def lam(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """Multipliers at t (linear between the steps): (m,) or (m, k)."""
        return self._one(t, 3)

    def states(self, t: Union[float, ArrayLike]) -> np.ndarray:
        """First-order states at t: (r,) or (r, k); ValueError without them."""
        if self._y is None:
            raise ValueError("the run had no first-order states (y0)")
        return self._one(t, 4)


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


_SCIPY_METHODS = ("RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA")


def _solve_ivp_options(options, h, rtol, atol, max_step, first_step, method):
    """solve_ivp's keywords as the Solver options they name; a keyword given twice (in both
    conventions) is refused rather than one of them silently winning."""
    def put(key, value, keyword):
        if key in options:
            raise TypeError("integrate: %s= and %s= say the same thing; give one" % (keyword,
                                                                                     key))
        options[key] = value
    adaptive = [k for k, x in (("rtol", rtol), ("atol", atol), ("max_step", max_step),
                               ("first_step", first_step)) if x is not None]
    if h is not None and adaptive:
        raise ValueError("integrate: h = %g fixes the steps; %s control adaptive steps (leave "
                         "h out for them)" % (float(h), ", ".join(adaptive)))
    if rtol is not None or atol is not None:
        put("tolerances", (1e-6 if rtol is None else rtol, 1e-6 if atol is None else atol),
            "rtol/atol")
    if max_step is not None:
        if not (float(max_step) > 0.0):
            raise ValueError("max_step = %r must be positive" % (max_step,))
        if np.isfinite(float(max_step)):  # solve_ivp's default, inf: no bound
            put("step_limits", (0.0, float(max_step)), "max_step")
    if first_step is not None:
        put("initial_step", float(first_step), "first_step")
    if method is not None:
        names = {"index3": _ffi.GA_INDEX3, "index2": _ffi.GA_INDEX2_STABILIZED,
                 _ffi.GA_INDEX3: _ffi.GA_INDEX3,
                 _ffi.GA_INDEX2_STABILIZED: _ffi.GA_INDEX2_STABILIZED}
        if method not in names:
            hint = (" (%s is one of solve_ivp's ODE methods; galpha integrates the DAE with "
                    "the generalized-alpha method in either formulation)" % method
                    if method in _SCIPY_METHODS else "")
            raise ValueError("method = %r: 'index3' (the default) or 'index2' (the stabilized "
                             "index-2 formulation)%s" % (method, hint))
        put("formulation", names[method], "method")


def integrate(mass: Any, force: Any, constraint: Any, jacobian: Any,
              t_span: Tuple[float, float], q0: ArrayLike, v0: ArrayLike,
              h: Optional[float] = None, *, m: Optional[int] = None,
              t_eval: Optional[ArrayLike] = None, events: Any = None,
              dense_output: bool = False, y0: Optional[ArrayLike] = None,
              progress: Optional[bool] = None, rtol: Optional[float] = None,
              atol: Optional[Union[float, ArrayLike]] = None, max_step: Optional[float] = None,
              first_step: Optional[float] = None, args: Sequence[Any] = (),
              method: Any = None, **options: Any) -> IntegrateResult:
    """Integrate from t_span[0] to t_span[1] and record every accepted step, or the states at
    the times t_eval (by dense output, without shortening steps).

    Callbacks fill their output, mass(t, q, M), or return it, mass(t, q) -> M (decided once,
    from the arguments they take; see galpha.Solver); `args`, a tuple, follows the arguments
    of every callback and event function, as in solve_ivp. A callback that raises
    galpha.CallbackRetry fails the step recoverably (a positive return in C).

    With h: fixed steps h (the last one shortened to land on t_span[1]). Without h: adaptive
    steps held to rtol and atol (solve_ivp's keywords; galpha's defaults 1e-6 and 1e-6, or
    `tolerances=(rtol, atol)`): atol a number or one per row of y (2n + r: positions,
    velocities, first-order states; ga_set_tolerances_vector); max_step bounds the steps
    (`step_limits=(0, max_step)`), first_step sets the first (`initial_step=`). The stabilized
    index-2 formulation is recommended for adaptive runs: method='index2' (or
    `formulation=galpha.GA_INDEX2_STABILIZED`); method='index3' is the default. solve_ivp's
    ODE methods (RK45, Radau, ...) are refused by name.

    m, the number of constraints, must be given with constraint callbacks (it was taken as 0,
    which dropped them); without them it is 0.

    events: a callable or a list of them, g(t, q, v, lam) -> float, with scipy's attributes:
    `direction` (> 0 rising, < 0 falling, 0 either) and `terminal` (True, or the number of
    occurrences after which the run ends; default False), and `multipliers` (True: lam holds the
    consistent multipliers at the located state; else None). Their roots are located on the
    dense output of each step (ga_set_events); the result holds t_events, y_events, q_events,
    v_events and lam_events, and a terminal event ends the run at its time (status 1), the last
    recorded point being the event's state.

    dense_output: the result's `sol` is the whole run's interpolant (OdeSolution): sol(t) is y
    at t (vectorized over t), sol.q, sol.v, sol.qdd, sol.lam and sol.states its parts.

    progress: a progress bar over simulated time (tqdm, optional): None (default) shows it on a
    terminal once a run has lasted a second, True always, False never.

    Adaptive runs without events record through the step hook (Solver.set_step_hook) inside
    one call of Solver.advance; fixed steps and runs with events step from Python.

    y0: the initial first-order states, with the options r, rate, force_y (and coupling) of
    Solver; the result's `states` holds their history (and y their rows), and event functions
    are then g(t, q, v, lam, y).

    `options` go to Solver (rho_inf, newton, stiffness, constraint_accel, ...). A failure of
    the method (no convergence, singular matrix, ...) ends the integration with success=False,
    the failure's message and the histories up to the last accepted step; an exception raised
    by a callback is re-raised.
    """
    # an unknown keyword is integrate's to name (Solver.__init__'s TypeError named its own)
    known = inspect.signature(Solver.__init__).parameters
    unknown = sorted(k for k in options if k not in known or k in ("self", "n", "m"))
    if unknown:
        raise TypeError("integrate() got an unexpected keyword argument %r (integrate takes "
                        "solve_ivp's keywords and Solver's options)" % unknown[0])
    _solve_ivp_options(options, h, rtol, atol, max_step, first_step, method)
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
        # scipy's convention: False, None or 0 never ends the run, True or a count k >= 1
        # ends it at the k-th occurrence
        if terminal is True or terminal is False or terminal is None:
            left.append(1 if terminal else None)
        elif isinstance(terminal, numbers.Real) and terminal >= 0 and int(terminal) == terminal:
            left.append(int(terminal) if int(terminal) > 0 else None)
        else:
            raise ValueError("event %r: terminal = %r must be a bool or a count >= 0"
                             % (getattr(g, "__name__", g), terminal))
    t_ev = [[] for _ in events]
    q_ev = [[] for _ in events]
    v_ev = [[] for _ in events]
    l_ev = [[] for _ in events]
    ts, qs, vs, as_, ls = [], [], [], [], []
    with_states = y0 is not None
    xs, x_ev = [], [[] for _ in events]  # first-order states
    # dense output: t, q, v, qdd, lam (and y, y') at every accepted step
    knots = tuple([] for _ in range(7 if with_states else 5))
    status, message = 0, "reached t_span[1]"
    with Solver(n, m, mass, force, constraint, jacobian, args=args, **options) as s:
        if with_states:
            s.init(t0, q0, v0, y0)
        else:
            s.init(t0, q0, v0)

        # A row of the outputs is computed whole before any list grows: the consistent qdd
        # and lam evaluate callbacks, which may fail (the run then ends with that failure,
        # every list as long as ts).
        def append_row(te, qi, vi, ai, li, xi=None):
            ts.append(te)
            qs.append(qi)
            vs.append(vi)
            as_.append(ai)
            ls.append(li)
            if with_states:
                xs.append(xi)

        def state_y(te):
            if not with_states:
                return None
            return s.y if te == s.t else s.interpolate_y(te)[0]
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
            values = (s.t, s.q, s.v, s.qdd, s.lam) + ((s.y, s.ydot) if with_states else ())
            for x, y in zip(knots, values):
                x.append(y)

        def record_events():
            """Records the events of the last step; the time of a terminal one, else None."""
            for te, k, _ in s.events:
                qi, vi, li = s.interpolate(te)
                xi = s.interpolate_y(te)[0] if with_states else None
                t_ev[k].append(te)
                q_ev[k].append(qi)
                v_ev[k].append(vi)
                l_ev[k].append(li)
                if with_states:
                    x_ev[k].append(xi)
                if left[k] is not None:
                    left[k] -= 1
                    if left[k] == 0:
                        return te
            return None

        def record(te=None):
            append_row(s.t if te is None else te, s.q, s.v, s.qdd, s.lam, state_y(s.t))

        def record_eval(t_prev):
            while pending and pending[0] <= s.t:
                te = pending[0]
                if te == s.t or te == t_prev:
                    record(te)
                else:
                    qi, vi, li = s.interpolate(te)
                    append_row(te, qi, vi, s.interpolate_qdd(te), li, state_y(te))
                pending.pop(0)

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
                    if te > t_prev:
                        qi, vi, li = s.interpolate(te)
                        append_row(te, qi, vi, s.interpolate_qdd(te), li, state_y(te))
                    else:
                        append_row(te, qs[-1], vs[-1], as_[-1], ls[-1],
                                   xs[-1] if with_states else None)
                qi, vi, li = s.interpolate(t_end)
                ai = s.interpolate_qdd(t_end)
                append_row(t_end, qi, vi, ai, li, state_y(t_end))
                if dense_output:
                    ends = (t_end, qi, vi, ai, li)
                    if with_states:
                        ends += s.interpolate_y(t_end)
                    for x, y in zip(knots, ends):
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
    t_out = np.array(ts)
    q_out, v_out = np.array(qs).reshape(len(ts), nq), np.array(vs).reshape(len(ts), n)
    rows = [q_out, v_out]
    result = IntegrateResult(t=t_out, q=q_out, v=v_out, qdd=np.array(as_).reshape(len(ts), n),
                             lam=np.array(ls).reshape(len(ts), m), stats=stats,
                             success=status >= 0, status=status, message=message,
                             nfev=stats["residuals"], njev=stats["stiffness_evals"],
                             nlu=stats["factorizations"])
    if with_states:
        result["states"] = np.array(xs).reshape(len(ts), len(np.atleast_1d(y0)))
        rows.append(result["states"])
    result["y"] = np.hstack(rows).T
    if events:
        result["t_events"] = [np.array(x) for x in t_ev]
        if with_states:
            result["states_events"] = [np.array(x).reshape(len(x), len(np.atleast_1d(y0)))
                                       for x in x_ev]
        result["q_events"] = [np.array(x).reshape(len(x), nq) for x in q_ev]
        result["v_events"] = [np.array(x).reshape(len(x), n) for x in v_ev]
        result["lam_events"] = [np.array(x).reshape(len(x), m) for x in l_ev]
        parts = [result["q_events"], result["v_events"]] + (
            [result["states_events"]] if with_states else [])
        result["y_events"] = [np.hstack(p) for p in zip(*parts)]
    if dense_output:
        result["sol"] = OdeSolution(*knots)
    return result
