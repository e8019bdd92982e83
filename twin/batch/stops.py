"""Stops that Python swallowed: a Ctrl-C (or a stop signal a command takes as one) that comes while a garbage
collector's callback or a ``__del__`` runs raises its KeyboardInterrupt there, and Python swallows it
("Exception ignored in ..."), so the command would run on as if no stop had come. :func:`swallowed_stops_kept`
keeps such a stop for a command's length; :func:`raise_if_stopped`, called where work is handed on (a finished
batch) or outputs go into place, raises it again.
"""

from __future__ import annotations

import contextlib
import sys

_swallowed_stops: list[KeyboardInterrupt] = []  # kept by swallowed_stops_kept(), raised by raise_if_stopped()
_depth = [0]  # swallowed_stops_kept() blocks entered and not yet left (a command nests them)


@contextlib.contextmanager
def swallowed_stops_kept():
    """For the block: a Ctrl-C (or a stop signal taken as one) that Python swallowed, because it came while a
    garbage collector's callback or a ``__del__`` ran ("Exception ignored in ..."), is kept instead of
    printed, and :func:`raise_if_stopped` raises it again, so the stop is not lost. Nested blocks share the
    outermost's hook and its kept stops (an inner block's end must not forget one the outer has yet to
    raise). The previous hook afterwards, and every other unraisable error still goes to it."""
    if _depth[0]:
        _depth[0] += 1
        try:
            yield
        finally:
            _depth[0] -= 1
        return
    previous = sys.unraisablehook

    def keep(unraisable) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            _swallowed_stops.append(unraisable.exc_value)
        else:
            previous(unraisable)

    sys.unraisablehook, _depth[0] = keep, 1
    try:
        yield
    finally:
        sys.unraisablehook, _depth[0] = previous, 0
        _swallowed_stops.clear()


def raise_if_stopped() -> None:
    """KeyboardInterrupt if a stop was swallowed since the last call (:func:`swallowed_stops_kept`)."""
    if _swallowed_stops:
        _swallowed_stops.clear()
        raise KeyboardInterrupt
