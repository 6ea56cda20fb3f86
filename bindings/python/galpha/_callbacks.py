"""Model callbacks in either convention, with solve_ivp's extra `args`.

A callback may fill its output, `mass(t, q, M)`, or return it, `mass(t, q) -> M` (as
solve_ivp's `fun(t, y)` does). Which one is decided once, when the Solver is built, from the
number of positional arguments the function takes; a function that would take both counts
(defaults, *args) fills, as before returning was allowed. `args` (a tuple) follow the
arguments of either convention: mass(t, q, M, *args) or mass(t, q, *args)."""
import inspect

import numpy as np


def _positional_range(fn):
    """(least, most) positional arguments fn accepts, or None when it cannot be told."""
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):  # builtins, some extension types
        return None
    least, most = 0, 0
    for p in sig.parameters.values():
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD):
            most += 1
            if p.default is p.empty:
                least += 1
        elif p.kind == p.VAR_POSITIONAL:
            most = float("inf")
        elif p.kind == p.KEYWORD_ONLY and p.default is p.empty:
            return None
    return least, most


def returns_output(fn, name, inputs, outputs, nargs):
    """Whether the Python callable fn returns its outputs (True) or fills them (False).
    inputs: the names of its inputs (t first); outputs: those of what it computes."""
    span = _positional_range(fn)
    if span is None:
        return False
    least, most = span
    fills = least <= len(inputs) + len(outputs) + nargs <= most
    if fills:
        return False
    if least <= len(inputs) + nargs <= most:
        return True
    extra = ", *args" if nargs else ""
    raise TypeError(
        "%s takes %s positional arguments; a callback either fills its output, %s(%s%s), or "
        "returns it, %s(%s%s) -> %s" % (
            name, least if least == most else "%s to %s" % (least, most), name,
            ", ".join(inputs + outputs), extra, name, ", ".join(inputs), extra,
            outputs[0] if len(outputs) == 1 else "(%s)" % ", ".join(outputs)))


def adapt(fn, name, inputs, outputs, args):
    """fn as a function that fills its outputs and takes no extra arguments: fn itself when
    it is one already, else a wrapper (once, at set-up: the convention is not decided per
    call). None and compiled callbacks are returned unchanged."""
    if fn is None or not callable(fn):
        return fn
    if not returns_output(fn, name, inputs, outputs, len(args)):
        if not args:
            return fn
        return lambda *a: fn(*a, *args)
    k = len(outputs)

    def store(out, value, what):
        if value is None:
            raise TypeError("%s returned None: a callback that returns its output must return "
                            "%s (one that fills it takes it as an argument)" % (name, what))
        # the output's own shape up to axes of length 1 (one constraint's Jacobian as a
        # vector, its value as a number), never broadcast: a scalar for m = 2 constraints
        # filled both (scipy refuses fun's wrong shape too)
        shape = np.shape(value)
        if [d for d in shape if d != 1] != [d for d in out.shape if d != 1]:
            raise ValueError("%s returned %s of shape %s; %s has shape %s" % (
                name, type(value).__name__, shape, what, out.shape))
        out[...] = np.reshape(value, out.shape)

    # fn(t, q, phi) with args=(g,) takes as many arguments as the returning convention: say
    # which one was taken when the call fails on its arguments
    ambiguous = len(args) == k

    def call(*a):
        try:
            return fn(*a, *args)
        except TypeError as e:
            if ambiguous and hasattr(e, "add_note"):
                e.add_note("galpha: %s was taken as returning its output, %s(%s, *args) -> %s "
                           "(it takes %d arguments and args has %d); one that fills it takes "
                           "the args after its outputs, %s(%s, *args)" % (
                               name, name, ", ".join(inputs), ", ".join(outputs),
                               len(inputs) + len(args), len(args), name,
                               ", ".join(inputs + outputs)))
            raise

    if k == 1:
        def filled(*a):
            store(a[-1], call(*a[:-1]), outputs[0])
    else:
        def filled(*a):
            values = call(*a[:-k])
            if not isinstance(values, (tuple, list)) or len(values) != k:
                raise TypeError("%s returned %r: expected a tuple (%s)" % (
                    name, type(values).__name__, ", ".join(outputs)))
            for out, value, what in zip(a[-k:], values, outputs):
                if out is not None:  # an output the library does not ask for this time
                    store(out, value, what)
    filled.__name__ = getattr(fn, "__name__", name)
    filled.__wrapped__ = fn
    return filled
