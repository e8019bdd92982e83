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


@contextlib.contextmanager
def swallowed_stops_kept():
    """For the block: a Ctrl-C (or a stop signal taken as one) that Python swallowed, because it came while a
    garbage collector's callback or a ``__del__`` ran ("Exception ignored in ..."), is kept instead of
    printed, and :func:`raise_if_stopped` raises it again before any output goes into place, so the stop
    is not lost. The previous hook afterwards, and every other unraisable error still goes to it."""
    previous = sys.unraisablehook

    def keep(unraisable) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt):
            _swallowed_stops.append(unraisable.exc_value)
        else:
            previous(unraisable)

    sys.unraisablehook = keep
    try:
        yield
    finally:
        sys.unraisablehook = previous
        _swallowed_stops.clear()


def raise_if_stopped() -> None:
    """KeyboardInterrupt if a stop was swallowed since the last call (:func:`swallowed_stops_kept`)."""
    if _swallowed_stops:
        _swallowed_stops.clear()
        raise KeyboardInterrupt
