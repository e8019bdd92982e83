"""One writer per output folder: an exclusive lock on ``DIR/.twin.lock`` while a command writes there.

The lock is the operating system's (``flock``), so a process that dies, however it dies, releases
it, and the next command takes the folder over; the file only records the holder's PID for the
message a second writer gets.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import pathlib

from twin.exceptions import TwinError

LOCK_NAME = ".twin.lock"


class FolderBusy(TwinError):
    """Another process is writing into the same output folder."""


@contextlib.contextmanager
def folder_lock(folder: pathlib.Path):
    """Hold ``folder``'s lock for the ``with`` block, or raise FolderBusy naming the holder's PID."""
    path = folder / LOCK_NAME
    handle = open(path, "a+")
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            holder = handle.read().strip() or "unknown"
            raise FolderBusy(f"{folder} is being written by process {holder}: wait for it to finish, "
                             "or choose another --out") from None
        handle.seek(0)
        handle.truncate()
        handle.write(f"{os.getpid()}\n")
        handle.flush()
        yield
    finally:
        handle.close()  # releases the lock
