"""One call from initial values to time histories, in the spirit of scipy's solve_ivp."""
import numpy as np

from .errors import GalphaError
from .solver import Solver


class IntegrateResult(dict):
    """Attributes: t (N,), q, v, qdd (N, n), lam (N, m), stats (dict), success (bool),
    status (0 or the failing ga_status), message (str)."""

    __getattr__ = dict.__getitem__

    def __repr__(self):
        return "IntegrateResult(success=%r, message=%r, steps=%d, t_end=%g)" % (
            self.success, self.message, len(self.t) - 1, self.t[-1])


def integrate(mass, force, constraint, jacobian, t_span, q0, v0, h, *, m=0, **options):
    """Integrate from t_span[0] to t_span[1] with fixed steps h (the last one shortened to land
    on t_span[1]) and record every accepted step.

    `options` go to Solver (rho_inf, newton, stiffness, constraint_accel, ...). A failure of
    the method (no convergence, singular matrix, ...) ends the integration with success=False
    and the histories up to the last accepted step; an exception raised by a callback is
    re-raised.
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    q0 = np.asarray(q0, dtype=float)
    n = q0.size
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

        record()
        while True:
            remaining = t1 - s.t
            if remaining <= 1e-12 * max(1.0, abs(t1)):
                break
            try:
                s.step(h if remaining > h * (1.0 + 1e-9) else remaining)
            except GalphaError as e:
                status, message = e.status, str(e)
                break
            record()
        stats = s.stats
    return IntegrateResult(t=np.array(ts), q=np.array(qs), v=np.array(vs), qdd=np.array(as_),
                           lam=np.array(ls).reshape(len(ts), m), stats=stats,
                           success=status == 0, status=status, message=message)
