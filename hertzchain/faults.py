"""Faults of the file system that a command reports once: a full disk.

On a full disk h5py reports every failed flush of an HDF5 object from its destructor,
outside any ``try`` of ours; :class:`FailedWrites` counts those instead of printing
them, so that ``hertzchain`` commands and a sweep's points end with one message
naming the disk (docs/guide/exit_status.md).  Standard library only: the command
line imports it before NumPy.
"""

from __future__ import annotations

import errno
import sys

__all__ = ["FailedWrites", "is_disk_full", "is_disk_full_text"]


def is_disk_full_text(text: str) -> bool:
    """A message of a write that failed for lack of space (HDF5's, the OS's, ours)."""
    return any(m in text for m in ("errno = 28", "No space left", "File too large",
                                   "disk full", "errno = 27"))


def is_disk_full(exc: BaseException | None) -> bool:
    """A write failed for lack of space (ENOSPC, EFBIG), here or in a cause of ``exc``."""
    seen = 0
    while exc is not None and seen < 10:
        if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EFBIG):
            return True
        if is_disk_full_text(str(exc)):
            return True
        exc = exc.__cause__ or exc.__context__
        seen += 1
    return False


class FailedWrites:
    """HDF5's failed writes while a command or a sweep point runs: counted, not shown.

    On a full disk h5py reports every failed flush from an object's destructor, twice:
    a traceback through ``sys.excepthook`` (Cython prints it before) and ``Exception
    ignored in h5py._objects.ObjectID.__dealloc__`` through ``sys.unraisablehook`` —
    tens to hundreds of them before the one message that matters.  Both hooks are
    replaced while the command runs: disk-full errors are counted (the command ends with
    one message naming the disk), any other error is shown as usual.
    """

    def __init__(self) -> None:
        self.count = 0
        self.example = ""
        self._unraisable = self._except = None

    def __enter__(self):
        self._unraisable, self._except = sys.unraisablehook, sys.excepthook
        sys.unraisablehook, sys.excepthook = self.unraisable_hook, self.except_hook
        return self

    def __exit__(self, *exc) -> None:
        sys.unraisablehook, sys.excepthook = self._unraisable, self._except

    def _absorb(self, exc: BaseException | None) -> bool:
        if not is_disk_full(exc):
            return False
        self.count += 1
        self.example = self.example or str(exc).splitlines()[0]
        return True

    def unraisable_hook(self, unraisable) -> None:
        """``sys.unraisablehook`` while entered: a disk-full error is counted, not shown."""
        if not self._absorb(unraisable.exc_value):
            self._unraisable(unraisable)

    def except_hook(self, kind, value, tb) -> None:
        """``sys.excepthook`` while entered: a disk-full error is counted, not shown."""
        if not self._absorb(value):
            self._except(kind, value, tb)
