"""Stop signals, and stops that Python swallowed.

:data:`STOP_SIGNALS` are the signals a command takes as a stop; :func:`handlers_put_back` restores their
handlers after code that takes them over (``ray.init`` does). A Ctrl-C (or a stop signal a command takes as
one) that comes while a garbage collector's callback or a ``__del__`` runs raises its KeyboardInterrupt there,
and Python swallows it ("Exception ignored in ..."), so the command would run on as if no stop had come.
:func:`swallowed_stops_kept` keeps such a stop for a command's length; :func:`raise_if_stopped`, called where
work is handed on (a finished batch) or outputs go into place, raises it again.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)  # Ctrl-C, a kill, a closed terminal
_swallowed_stops: list[KeyboardInterrupt] = []  # kept by swallowed_stops_kept(), raised by raise_if_stopped()
_depth = 0  # swallowed_stops_kept() blocks entered and not yet left (a command nests them)


@contextlib.contextmanager
def handlers_put_back():
    """The stop signals' handlers as they were before the block, put back after it (a handler set outside
    Python, ``None``, cannot be, and is left). Only the main thread may set handlers: elsewhere a no-op.

    A stop signal that came inside the block and met the block's own handler for it as ``sys.exit(signum)``
    (``ray.init``'s for SIGTERM: exit 15 and no word, stop 54's CI) goes to the handler put back, as if the
    block had not taken it: the CLI's makes it a stop, as Ctrl-C; the default one ends the process. A handler
    put back that lets it pass (ignored) leaves the exit as it was; so does an exit whose number is a stop
    signal whose handler the block did not replace (argparse's exit 2 is not a Ctrl-C)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = {signum: signal.getsignal(signum) for signum in STOP_SIGNALS}
    taken = None  # the stop signal that met the block's own handler, handed on once the handlers are back
    try:
        yield
    except SystemExit as cut_short:
        taken = next((s for s in STOP_SIGNALS if cut_short.code == s and signal.getsignal(s) is not before[s]), None)
        raise
    finally:
        for signum, handler in before.items():
            if handler is not None:
                signal.signal(signum, handler)
        if taken is not None:  # the handler put back raises its stop in place of the exit, or lets the exit go on
            signal.raise_signal(taken)


@contextlib.contextmanager
def swallowed_stops_kept():
    """For the block: a Ctrl-C (or a stop signal taken as one) that Python swallowed, because it came while a
    garbage collector's callback or a ``__del__`` ran ("Exception ignored in ..."), is kept instead of
    printed, and :func:`raise_if_stopped` raises it again, so the stop is not lost. Nested blocks share the
    outermost's hook and its kept stops (an inner block's end must not forget one the outer has yet to
    raise). The previous hook afterwards, and every other unraisable error still goes to it."""
    global _depth
    if _depth:
        _depth += 1
        try:
            yield
        finally:
            _depth -= 1
        return
    previous = sys.unraisablehook

    def keep(unraisable) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            _swallowed_stops.append(unraisable.exc_value)
        else:
            previous(unraisable)

    sys.unraisablehook, _depth = keep, 1
    try:
        yield
    finally:
        sys.unraisablehook, _depth = previous, 0
        _swallowed_stops.clear()


def raise_if_stopped() -> None:
    """KeyboardInterrupt if a stop was swallowed since the last call (:func:`swallowed_stops_kept`)."""
    if _swallowed_stops:
        _swallowed_stops.clear()
        raise KeyboardInterrupt
