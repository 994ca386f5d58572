"""Checkpoint and resume of long runs, bit for bit.

A run is integrated in *segments* of :func:`segment_steps` steps (``Simulation.run``
called repeatedly with ``max_steps``).  After every segment that ends more than
``interval`` seconds of wall time after the last checkpoint, the whole
:class:`~discrete.Simulation` — state, recording, record, pending events — is written
with :func:`discrete.io.save` (atomically: temporary file, ``fsync``, rename) to the
checkpoint file, together with a *key* that identifies the run (for
:func:`hertzchain.runner.run_scenario` the hash of the scenario).  Rerunning the same
run finds the checkpoint, checks the key and continues from it; a checkpoint with
another key is refused (:class:`CheckpointError`: resuming another scenario's state
would silently produce wrong results, and discarding it silently could throw away
hours of work — ``--force`` discards it explicitly).

Why the result is bit for bit that of an uninterrupted run
----------------------------------------------------------
* The kernel's arithmetic per grain does not depend on where a run or a chunk starts or
  ends (:mod:`discrete.kernels`: the fused kick of a chunk's last step is split into the
  same two additions), and :func:`discrete.io.save` stores u, v, a, the running maxima
  and every record array losslessly (float64; checkpoints are not compressed: gzip
  would triple the write time for ~15 % less space), sealed with the SHA-256 of every
  byte (:mod:`theory.integrity`): a checkpoint whose ``dt``, ``steps`` or any value
  changed on disk is refused, never resumed into a different run.
* Segments end on multiples of ``monitor_every`` (and of the kernel's ``UMAX_EVERY``):
  the uninterrupted run cuts its chunks there too, so the chunk sequence — and with it
  the step at which a :class:`~discrete.WaveAt` event is taken — is the same, and the
  running maximum of u receives no extra sample.
* ``Simulation.run`` appends an energy-monitor sample when it returns and another one
  when it starts.  At a segment boundary both are the same sample of the same state
  (the uninterrupted run takes it once, in its loop), so the closing one is dropped
  (:func:`_drop_closing_sample`) before the next segment or the checkpoint.
* The watched-grain maxima of the event test restart from the present velocity at each
  ``run`` call; an event that has not fired has a running maximum that is either below
  its threshold or equal to the present velocity, so the restart changes nothing.

``tests/test_reliability_checkpoint.py`` checks all of this: segmented, saved → loaded
→ continued, and a real process killed with SIGKILL and resumed give the same bits in
every dataset of the output file as one uninterrupted ``run`` call.

Signals: while a segmented run is in progress SIGINT (Ctrl-C) and SIGTERM only set a
flag; the run stops at the end of the present segment, writes a checkpoint and raises
:class:`Interrupted` (a :class:`KeyboardInterrupt`).  A second Ctrl-C interrupts at
once (the last checkpoint stays valid).
"""

from __future__ import annotations

import contextlib
import errno
import math
import os
import signal
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import discrete
from discrete.progress import RunProgress
from theory import integrity

from .cache import CACHE_SCHEMA, canonical_json, is_stale_temporary, param_hash

__all__ = ["DEFAULT_INTERVAL", "CHECKPOINT_SCHEMA", "CheckpointError", "Interrupted",
           "OutputBusy", "OutputWriteError", "checkpoint_path", "deferred_signals",
           "request_stop", "stop_requested",
           "lock_path", "output_lock", "remove_stale_temporaries", "run_key",
           "segment_steps",
           "write_checkpoint", "read_checkpoint", "run_segmented"]

DEFAULT_INTERVAL = 300.0
"""Default wall time between checkpoints, s (``hertzchain run --checkpoint-interval``)."""

CHECKPOINT_SCHEMA = 1
"""Part of every key: bump when checkpoints of older code must not be resumed."""

_PREFIX = "checkpoint_"  # root attributes written by this module


class CheckpointError(ValueError):
    """A checkpoint cannot be used: damaged, or written for another run."""


class OutputWriteError(OSError):
    """The run finished but its output file could not be written (disk full, ...).

    The summary is kept (:attr:`summary`) so that the caller can still print it, and so
    is the last checkpoint, if one was written (:attr:`checkpoint`).
    """

    def __init__(self, path: Path, cause: OSError, summary: dict,
                 checkpoint: Path | None) -> None:
        from theory.integrity import write_error

        cause = write_error(cause, path)
        self.path, self.cause, self.summary, self.checkpoint = Path(path), cause, summary, \
            checkpoint
        kept = (f"; the last checkpoint {checkpoint} is kept (rerunning resumes from it)"
                if checkpoint is not None else "")
        super().__init__(cause.errno, f"the run finished but its output could not be "
                         f"written: {cause}{kept}")

    def __str__(self) -> str:
        return str(self.args[1]) if len(self.args) > 1 else super().__str__()


class Interrupted(KeyboardInterrupt):
    """A segmented run stopped on SIGINT/SIGTERM after writing a checkpoint.

    Attributes
    ----------
    signum : int
        The signal (``signal.SIGINT`` or ``signal.SIGTERM``).
    checkpoint : pathlib.Path or None
        The checkpoint written (None if the run had no checkpoint file).
    t : float
        Simulated time reached, s.
    steps : int
        Steps reached.
    """

    def __init__(self, signum: int, checkpoint: Path | None, t: float, steps: int,
                 note: str | None = None) -> None:
        self.signum, self.checkpoint, self.t, self.steps = signum, checkpoint, t, steps
        name = signal.Signals(signum).name
        where = f"at t = {t:.6g} s (step {steps})"
        if note is not None:
            text = f"interrupted by {name} {where}; {note}"
        elif checkpoint is None:
            text = f"interrupted by {name} {where}; no checkpoint (no output file)"
        else:
            text = (f"interrupted by {name} {where}; checkpoint written to {checkpoint}: "
                    "rerun the same command to resume")
        super().__init__(text)

    @property
    def exit_code(self) -> int:
        """Shell convention: 128 + signal number (130 for SIGINT, 143 for SIGTERM)."""
        return 128 + int(self.signum)

    def __str__(self) -> str:
        return str(self.args[0])


def checkpoint_path(out: str | Path) -> Path:
    """The checkpoint file of the output ``out``: ``out`` + ``".ckpt"`` beside it."""
    out = Path(out)
    return out.with_name(out.name + ".ckpt")


def remove_stale_temporaries(out: str | Path) -> list[Path]:
    """Delete temporary files a killed writer left beside ``out`` and its checkpoint.

    :func:`discrete.io.save` and :func:`hertzchain.cache.atomic_path` write to
    ``.<name>.<pid>-<random>.tmp`` in the target directory; a process killed while
    writing leaves one behind.  Only temporaries whose writer is no longer running are
    removed, never another live process's (two runs on one output deleted each
    other's); :func:`output_lock` keeps a second run off the same file anyway.
    """
    import glob

    out = Path(out)
    removed = []
    for name in (out.name, checkpoint_path(out).name):
        for p in out.parent.glob(f".{glob.escape(name)}.*.tmp"):
            if not is_stale_temporary(p, name):
                continue
            with contextlib.suppress(FileNotFoundError):
                p.unlink()
                removed.append(p)
    return removed


class OutputBusy(OSError):
    """Another process is running into the same output file (:func:`output_lock`)."""


def lock_path(out: str | Path) -> Path:
    """The lock file of an output: ``.<name>.lock`` beside it."""
    out = Path(out)
    return out.parent / f".{out.name}.lock"


@contextlib.contextmanager
def output_lock(out: str | Path) -> Iterator[Path]:
    """Hold an advisory lock (``fcntl.flock``) on ``out`` for the duration of a run.

    A second process asking for the same output gets :class:`OutputBusy` naming the
    file and the holder's pid at once (it does not wait: both would compute the same
    run).  The lock file ``.<name>.lock`` is removed on release (while still locked;
    a process that opened it just before then finds it replaced and retries), and the
    kernel releases the lock of a process that ends in any way, even by SIGKILL.  No-op
    where ``fcntl`` is missing.
    """
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield lock_path(out)
        return
    path = lock_path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    for _ in range(10):
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise OutputBusy(errno.EBUSY, f"another run holds {Path(out)} (pid {holder}, "
                             f"lock {path}); wait for it to finish or give another "
                             "output") from None
        try:
            same = os.stat(path).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)  # the holder removed it between our open and flock: again
    else:  # pragma: no cover - ten lost races in a row
        raise OutputBusy(errno.EBUSY, f"could not lock {path}: it keeps being replaced")
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        yield path
    finally:
        with contextlib.suppress(FileNotFoundError):
            path.unlink()
        os.close(fd)  # releases the lock


def run_key(params: dict) -> str:
    """Key of a run from its parameters (JSON-able): schema versions and a SHA-256 prefix."""
    return f"ckpt{CHECKPOINT_SCHEMA}-cache{CACHE_SCHEMA}-{param_hash(params)}"


def segment_steps(sim: discrete.Simulation) -> int:
    """Steps per segment: :attr:`discrete.Simulation.restart_period`.

    The least common multiple of ``Recording.monitor_every`` (the run's chunks end there,
    and the energy monitor samples there) and the kernel's period of the running maximum
    of u.
    """
    return sim.restart_period


def write_checkpoint(path: str | Path, sim: discrete.Simulation, key: str,
                     extra: dict | None = None) -> Path:
    """Write ``sim`` and ``key`` (and ``extra``, JSON-able) to ``path`` atomically."""
    attrs = {f"{_PREFIX}key": key, f"{_PREFIX}extra": canonical_json(extra or {}),
             f"{_PREFIX}written": time.time()}
    from discrete.io import save  # (h5py only when a checkpoint is written)

    return save(path, sim, attrs=attrs, compress=False)  # speed over size


def read_checkpoint(path: str | Path, key: str, *, threads: int | None = None
                    ) -> tuple[discrete.Simulation, dict] | None:
    """The simulation and ``extra`` dict of the checkpoint at ``path`` (None if absent).

    ``threads`` is passed to :func:`discrete.io.load`.

    Raises
    ------
    CheckpointError
        If the file is damaged or was written for a different ``key``.
    """
    import json

    path = Path(path)
    if not path.exists():
        return None
    try:  # verified like every file the package reads (theory.integrity)
        with integrity.open_hdf5(path, what="checkpoint") as f:
            found = f.attrs.get(f"{_PREFIX}key")
            extra = f.attrs.get(f"{_PREFIX}extra")
    except ValueError as exc:
        raise CheckpointError(f"{exc}; delete it (or rerun with --force) to start over"
                              ) from None
    if isinstance(found, bytes):
        found = found.decode()
    if found is None or extra is None:
        raise CheckpointError(f"{path}: not a checkpoint (no {_PREFIX}key attribute); "
                              "delete it (or rerun with --force) to start over")
    if found != key:
        raise CheckpointError(
            f"{path}: checkpoint of a different run (key {found}, this run {key}): "
            "the scenario changed since it was written. Rerun with --force to discard "
            "it, or write to another --out file")
    try:
        from discrete.io import load

        sim = load(path, threads=threads)
        extra = json.loads(extra)
    except ValueError as exc:
        raise CheckpointError(f"damaged checkpoint: {exc}; delete it (or rerun with "
                              "--force) to start over") from None
    return sim, extra


_STOP_REQUESTS: list[int] = []
"""Signals passed to :func:`request_stop`: the flag of every run outside the main thread."""


def request_stop(signum: int) -> None:
    """Stop the segmented runs of this process's other threads as on ``signum``.

    For a process whose runs go on outside its main thread (a Dask worker), where
    :func:`deferred_signals` cannot set handlers: its own SIGINT/SIGTERM handler calls
    this, and every such run stops at the end of its segment, writes its checkpoint
    and raises :class:`Interrupted`, as a run in the main thread would.
    """
    if signum not in _STOP_REQUESTS:
        _STOP_REQUESTS.append(int(signum))


def stop_requested() -> int | None:
    """The first signal passed to :func:`request_stop` in this process, or None."""
    return _STOP_REQUESTS[0] if _STOP_REQUESTS else None


@contextlib.contextmanager
def deferred_signals(enabled: bool = True) -> Iterator[list[int]]:
    """Turn the first SIGINT/SIGTERM into a flag (the yielded list); restore on exit.

    Only in the main thread; elsewhere signals cannot be handled, and the list yielded
    is that of :func:`request_stop`.  A second signal gets the previous handler (Ctrl-C
    twice interrupts at once).
    """
    flag: list[int] = []
    if not enabled or threading.current_thread() is not threading.main_thread():
        yield flag if not enabled else _STOP_REQUESTS
        return
    previous = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}

    def handler(signum, frame):
        flag.append(signum)
        for s, h in previous.items():  # a second signal acts at once
            signal.signal(s, h)

    for s in previous:
        signal.signal(s, handler)
    try:
        yield flag
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def _drop_closing_sample(sim: discrete.Simulation) -> None:
    """Drop the monitor sample ``run`` appended on return; the next ``run`` re-takes it."""
    sim.record.drop_monitor_sample_at(sim.t)


def run_segmented(sim: discrete.Simulation, *, t_end: float | None = None, until=None,
                  step_limit: int | None = None, checkpoint: str | Path | None = None,
                  key: str = "", interval: float = DEFAULT_INTERVAL,
                  extra: Callable[[], dict] | None = None, progress: bool = False,
                  signals: bool | list[int] = True) -> str:
    """Integrate ``sim`` like ``sim.run(t_end, until=until, max_steps=...)``, checkpointing.

    The result is bit for bit that of one ``run`` call (module docstring).

    Parameters
    ----------
    sim : discrete.Simulation
        A fresh simulation or one read back with :func:`read_checkpoint`.
    t_end : float, optional
        Absolute end time, s.
    until : event, optional
        Stop event (:class:`discrete.WaveAt` or :class:`discrete.AtTime`).
    step_limit : int, optional
        Absolute step number at which to stop (``max_steps`` of the equivalent single
        call made at step 0).
    checkpoint : path, optional
        Checkpoint file; None: no checkpoints (segments and clean signal handling only).
    key : str
        Identifies the run (:func:`run_key`); stored in the checkpoint.
    interval : float
        Wall time between checkpoints, s (>= 0; 0 writes one after every segment).
    extra : callable, optional
        Returns a JSON-able dict stored with each checkpoint.
    progress : bool
        Show a progress bar (tqdm, stderr) towards the stop condition: grains to the
        ``WaveAt`` grain, else simulated time (:class:`discrete.progress.RunProgress`).
    signals : bool or list
        Defer SIGINT/SIGTERM to the end of a segment (main thread only); or the flag list
        of an enclosing :func:`deferred_signals` (the caller owns the handlers).

    Returns
    -------
    str
        What stopped the run: the event's label, ``"t_end"`` or ``"max_steps"``.

    Raises
    ------
    Interrupted
        On SIGINT/SIGTERM, after writing the checkpoint.
    discrete.InstabilityError
        As ``Simulation.run``; the last checkpoint is left as it was.
    """
    if not (isinstance(interval, int | float) and math.isfinite(interval) and interval >= 0):
        raise ValueError(f"interval must be a finite number of seconds >= 0 (got {interval!r})")
    if t_end is None and until is None and step_limit is None:
        raise ValueError("give t_end (s), until (event) or step_limit")
    end = math.inf
    if t_end is not None:
        end = sim.step_of(float(t_end))  # Simulation.run's own rounding
    if step_limit is not None:
        end = min(end, int(step_limit))
    if sim.steps >= end:  # nothing to integrate: exactly what one call does
        kw = {} if step_limit is None else {"max_steps": max(0, int(step_limit) - sim.steps)}
        return sim.run(t_end, until=until, progress=False, **kw).stopped_by
    period = segment_steps(sim)
    checkpoint = None if checkpoint is None else Path(checkpoint)
    last = time.monotonic()
    bar = RunProgress(sim, t_end=t_end, until=until, step_limit=step_limit, enabled=progress)
    try:
        with (contextlib.nullcontext(signals) if isinstance(signals, list)
              else deferred_signals(signals)) as flag:
            while True:
                stop = min(end, (sim.steps // period + 1) * period)
                info = sim.run(t_end, until=until, max_steps=int(stop - sim.steps),
                               progress=False)
                bar.update()
                if info.stopped_by not in ("t_end", "max_steps") or sim.steps >= end:
                    return info.stopped_by
                _drop_closing_sample(sim)
                now = time.monotonic()
                if checkpoint is not None and (flag or now - last >= interval):
                    write_checkpoint(checkpoint, sim, key, extra() if extra else None)
                    last = time.monotonic()
                if flag:
                    raise Interrupted(flag[0], checkpoint, sim.t, sim.steps)
    finally:
        bar.close()
