"""One call from initial values to time histories, in the spirit of scipy's solve_ivp."""
import numpy as np

from .errors import GalphaError
from .solver import Solver


class IntegrateResult(dict):
    """Attributes: t (N,), q, v, qdd (N, n), lam (N, m), stats (dict), success (bool),
    status (0 or the failing ga_status), message (str)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __repr__(self):
        return "IntegrateResult(success=%r, message=%r, outputs=%d, steps=%d, t_end=%g)" % (
            self.success, self.message, len(self.t), self.stats.get("steps", 0), self.t[-1])


def integrate(mass, force, constraint, jacobian, t_span, q0, v0, h=None, *, m=None, t_eval=None,
              **options):
    """Integrate from t_span[0] to t_span[1] and record every accepted step, or the states at
    the times t_eval (by dense output, without shortening steps).

    With h: fixed steps h (the last one shortened to land on t_span[1]). Without h: adaptive
    steps controlled by `tolerances=(rtol, atol)` (default 1e-6, 1e-6); the stabilized index-2
    formulation is recommended then (`formulation=galpha.GA_INDEX2_STABILIZED`).

    m, the number of constraints, must be given with constraint callbacks (it was taken as 0,
    which dropped them); without them it is 0.

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
    n = q0.size
    if m is None:
        if constraint is not None:
            raise ValueError("constraint callbacks given without m: say how many constraints "
                             "they compute (m=...)")
        m = 0
    elif m == 0 and constraint is not None:
        raise ValueError("m = 0 with constraint callbacks: they would be ignored; give m")
    ts, qs, vs, as_, ls = [], [], [], [], []
    status, message = 0, "reached t_span[1]"
    with Solver(n, m, mass, force, constraint, jacobian, **options) as s:
        s.init(t0, q0, v0)

        def record():
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
        while True:
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
            if pending is None:
                record()
            else:
                record_eval(t_prev)
        stats = s.stats
    return IntegrateResult(t=np.array(ts), q=np.array(qs), v=np.array(vs), qdd=np.array(as_),
                           lam=np.array(ls).reshape(len(ts), m), stats=stats,
                           success=status == 0, status=status, message=message)
