"""``hertzchain reproduce``: the paper's Figs. 2–8 and Table 2, end to end.

One small module per item, in the manner of pyro2's ``problems/<name>.py``: each has its
``QUICK`` and ``FULL`` defaults, a ``run(ctx, ...)`` returning numbers and arrays,
plotting functions that draw on a given matplotlib ``ax``, ``figures(ctx, result)``
saving the PNGs, ``report(rep, result, figures)`` adding its section to the report and
``to_json(result)``.

* :mod:`.fig2` — impact pulse, v̄max/v0 (0.6816, 0.0822) and the k_n convention;
* :mod:`.fig34` — Figs. 3 and 4, mass/stiffness mismatch at δ0 = 0;
* :mod:`.fig5` — precompressed cases a–d;
* :mod:`.fig6` — transmitted-front speed vs Eq. 5;
* :mod:`.fig7` — phase diagram, classified points vs theory;
* :mod:`.fig8` — space–time energy maps of M, N, P, Q;
* :mod:`.table2` — Table 2 (discrete, linear theory, continuum);
* :mod:`.common` — context, cached runs, figures; :mod:`.report` — the report.

With ``workers=2`` (``--workers 2``) the items run in two processes (:data:`LANES` in
``--quick``: Figs. 5 and 7 in a worker forked after Fig. 3; :data:`FULL_LANES` in
``--full``: Fig. 5 alone there), the others in the calling process, which then writes
the report; every number, file and count is that of one process, bit for bit (the
default on two or more cores, :data:`QUICK_WORKERS`, :data:`FULL_WORKERS`).

Examples
--------
>>> from hertzchain.reproduce import reproduce
>>> out = reproduce(["fig2", "table2"], mode="quick", out="repro")  # doctest: +SKIP
>>> out["items"]["fig2"]["vmax_over_v0"]                            # doctest: +SKIP
{'0': 0.68163, '0.001': 0.082183}
"""

from __future__ import annotations

import gc
import importlib
import os
import signal
import sys
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["ITEMS", "FIRST", "LANES", "FULL_LANES", "ItemRun", "run_item", "reproduce",
           "check_items",
           "kernel_threads", "lanes"]

ITEMS = ("fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "table2", "validity")
"""Items in report order."""

_MODULES = {"fig2": ("fig2", {}), "fig3": ("fig34", {"item": "fig3"}),
            "fig4": ("fig34", {"item": "fig4"}), "fig5": ("fig5", {}), "fig6": ("fig6", {}),
            "fig7": ("fig7", {}), "fig8": ("fig8", {}), "table2": ("table2", {}),
            "validity": ("validity", {})}


@dataclass
class ItemRun:
    """What one item produced."""

    name: str
    module: object
    result: object
    figures: list = field(default_factory=list)
    numbers: dict = field(default_factory=dict)
    seconds: float = 0.0
    computed: list = field(default_factory=list)
    """Files this item computed (its share of ``Context.computed``)."""
    reused: list = field(default_factory=list)
    """Files this item reused (its share of ``Context.reused``)."""


def check_items(items) -> list[str]:
    """The items in report order, validated (default: all); ValueError for unknown names."""
    items = list(items or ITEMS)
    bad = [i for i in items if i not in ITEMS]
    if bad:
        raise ValueError(f"unknown item(s) {', '.join(map(repr, bad))}; choose from "
                         f"{', '.join(ITEMS)}")
    return [i for i in ITEMS if i in items]


def run_item(ctx, name: str) -> ItemRun:
    """Run one item: simulate (or reuse), analyse, save its figures."""
    mod_name, kwargs = _MODULES[name]
    mod = importlib.import_module(f"{__name__}.{mod_name}")
    start = time.perf_counter()
    c0, r0 = len(ctx.computed), len(ctx.reused)
    result = mod.run(ctx, **kwargs)
    figs = mod.figures(ctx, result) if hasattr(mod, "figures") else []
    run = ItemRun(name, mod, result, figs, mod.to_json(result), time.perf_counter() - start,
                  list(ctx.computed[c0:]), list(ctx.reused[r0:]))
    ctx.timings[name] = run.seconds
    from .common import trim_heap

    trim_heap()  # (measured: 36 MB less kept after Fig. 8, 345 against 381 MB)
    return run


QUICK_THREADS = 1
"""Kernel threads of ``--quick`` (:func:`reproduce`'s default there).

Results are bitwise the same for every thread count (``tests/discrete/test_parallel.py``);
what one thread saves is the first compile.  On two cores a run whose window reaches
:data:`discrete.simulation.PARALLEL_MIN_GRAINS` (10,000; in ``--quick`` the settling of
the incident wave, Figs. 2 and 5) uses the blocked, threaded kernel, a second compiled
variant; on one thread every ``--quick`` run uses the plain kernel only (blocking pays on
one thread from :data:`discrete.simulation.SERIAL_BLOCK_MIN_GRAINS` grains).  Measured
(issue 13): settling the δ0/d = 1e-3 wave with an empty kernel cache, 29 s CPU on one
thread against 78 s on two, the same wave bit for bit."""


@contextmanager
def kernel_threads(threads: int | None):
    """Set numba's thread count for the solvers' kernels inside the block (None: unchanged).

    Capped at ``numba.config.NUMBA_NUM_THREADS``; the previous count is restored.
    """
    if threads is None:
        yield
        return
    import numba

    if int(threads) != threads or threads < 1:
        raise ValueError(f"threads must be None or an integer >= 1 (got {threads!r})")
    before = numba.get_num_threads()
    numba.set_num_threads(min(int(threads), int(numba.config.NUMBA_NUM_THREADS)))
    try:
        yield
    finally:
        numba.set_num_threads(before)


FIRST = ("fig8", "table2")
"""Items one process runs before any other (then the rest in report order); with two
processes, the calling process runs them right after Fig. 3 (:data:`LANES`).

Memory (issue 13): Fig. 8's largest point run (Q, 4,879 × 1,000-grain energy grids,
37 MiB per kind) needs three grids on top of what the process holds already (the two
kinds, stored once in ``discrete.recording.EnergyGrid``, and one grid-sized map at a
time in :func:`.fig8.maps_from_grid`; :func:`.table2._reduce` works by row blocks,
``hertzchain.measure.total_energy_rows``).  Measured, AMD EPYC Zen 4, warm, one process
(ru_maxrss after each item, 2026-11-27, load 3-5): Fig. 8 first 340 MiB (main: 342),
after Fig. 3 375 MiB (410 before the row blocks), Fig. 7 in report order after the
rest 380 MiB (main: 394).  The numbers are the same, bit for bit (the items share only
files)."""

LANES = (("fig5", "fig7"), ("fig3", "fig8", "table2", "fig2", "fig4", "fig6", "validity"))
"""The two lanes of a parallel reproduction (``workers=2``), each run in its order.

The calling process runs the second lane's leading :data:`FIRST` items if it starts with
them, else its Fig. 3, then forks a worker for the first lane and goes on with the rest
of the second.  Fig. 3 (3.4 s) goes first because it loads what most items use (the
discrete and continuum kernels, py-pde, matplotlib): forked after it, the worker shares
those pages instead of loading its own copies (measured: 0.08 GB less PSS over both
processes than forking before any item, 0.56 against 0.64 GB).  Fig. 8 and Table 2 come
right after it, on the lowest floor the calling process has after the fork (375 MiB
peak, :data:`FIRST`); before the issue-13 grid storage they had to run before the fork
(~10 s on one core: two processes 43.3 s wall on the idle machine, against 35-37 s
forked after Fig. 3).
Balanced by the items' CPU time in ``--quick`` (measured warm, AMD EPYC Zen 4, issue 13,
2026-11-27, load 3-5): fig5 15-20 s + fig7 14-16 s in the worker against fig8 8-10 +
table2 0.7 + fig2 16 + fig4 1 + fig6 5 + validity 4 s after fig3's 3.5-4.5 s.  Items
that share files stay in one lane, in report order: Table 2 reuses Fig. 8's point files
(in two lanes both would compute them, and Table 2 would count them as computed rather
than reused).  The lanes share only the cache of settled waves (``Context.cache``,
written atomically): Fig. 5 settles the δ0/d = 1e-3 wave first in its lane, ~15 s
before Fig. 6 needs it in the other; had both settled it at once, they would have
computed the same wave, bit for bit."""

QUICK_WORKERS = 2
"""Worker processes of ``--quick`` (:func:`reproduce`'s default there; capped at the cores
this process may use).  Either count computes every simulation with the same code on one
kernel thread: the numbers are the same, bit for bit.

Two, for the wall time (issue 13: ≤ 40 s after compilation).  Measured on an idle 2-core
AMD EPYC Zen 4 (family 25 model 17, AVX-512; load 0.0-1.5), warm, fresh ``--out``,
``benchmarks/reproduce.py`` on 2026-11-27 11:18 UTC: one worker 60.9 s wall, 61.4 s CPU,
peak 480 MB (PSS); two workers 36.8 s wall, 62.5 s CPU, 590 MB PSS over both processes
(largest RSS 510 MB).  Under load from other jobs (2.7-5.4, earlier that day) the load
decided the wall time more than the count (one 84-146 s, two 78-172 s).  Peak memory
(issue 13, ``benchmarks/reproduce.py --reference``, 2026-11-27 13:37 UTC, load 3-7,
beside the same run of the earlier code): one worker 384 MB peak RSS (was 498), two
workers 392 MB in the larger process (was 528) and 411 MB PSS over both (was 529) —
:data:`FIRST`, :data:`.table2.RUN_ORDER`, :func:`.common.map_large_arrays`,
:func:`.common.trim_heap`, ``discrete.Record.energy_grids``.  With the phase-averaged
split's denser grid rows (interface chains with a faster right section, Fig. 7's
corners) and the runner's row-by-row stacking, idle, 14:05 UTC: one worker 415 MB,
71.8 s wall; two 376 MB in the larger process, 455 MB PSS over both, 43.3 s wall
(67.9 s CPU; forked after Fig. 3, before :data:`FIRST`, two took 35-37 s).  With the
energy grid stored once (``discrete.recording.EnergyGrid``) and the worker forked after
Fig. 3 again (:data:`LANES`), 2026-11-27 16:10-16:47 UTC, load 3-10 (no idle machine
that afternoon), ``--json`` byte-identical to main's in every run: one worker 396-398 MB
peak RSS (main 414-464 in the same session), 64-68 s CPU; two workers 396 MB in the
larger process (main 376), 396-444 MB PSS over both (main 365-445), 68-71 s CPU, wall
48-63 s at load ~3 (main 98 s at load 4.7), 96-107 s at load 7-8.  Re-measured on the
idle machine (``benchmarks/reproduce.py --reference``, 2026-11-27 17:03 UTC): two workers
36.1-36.9 s wall (the ≤ 40 s target met), 64 s CPU, 396 MB peak RSS in the larger process,
440-470 MB PSS over both; one worker 60-62 s wall, 398-399 MB peak RSS.  Without
:func:`.common.map_large_arrays` (load 9-11): one worker 450 MB, two 434 MB in the larger
(kept).  Of that, ~240 MiB is the floor of any process that runs a point (measured,
RSS): Python with NumPy 26 MiB, SciPy (sparse, linalg, optimize) +50, h5py +11, numba
+53, the solver and py-pde +25, matplotlib +26, the discrete kernels loaded +45, the
continuum's +6.  ``--workers 1`` (``workers=1``) runs everything in one process."""

FULL_LANES = (("fig5",), ("fig3", "fig2", "fig4", "fig6", "fig7", "fig8", "table2",
                           "validity"))
"""The two lanes of a parallel ``--full`` reproduction (``workers=2``, :data:`LANES`'s rules).

Fig. 5's four cases are shared: when the calling lane has run its items it runs the
cases the worker has not started, last first (:func:`.fig5.run_spare`; claim files,
:func:`.common.claim`), and the worker reuses their files: the same numbers, files and
counts as one process (``tests/hertzchain/test_reproduce_parallel.py``).  Measured
(issue 13, idle AMD EPYC Zen 4, after the Rosenau pass's four-node links and the lighter
validity and Fig. 7 items, before the sharing): 102.6 s wall, the calling lane idle from
~75 s while the worker ran Fig. 5's cases c and d.

Fig. 5 alone in the forked worker: its continuum (Eq. 4 on 150,000 nodes, one compiled
loop, single-threaded: 50,096-109,500 Yoshida-4 steps per case over an active window
that grows to ~70,000 nodes) is about half of ``--full``'s CPU time, and in one process
it left the second core idle (the old default: one process with threaded discrete
kernels, 320 s wall for 388 s CPU on the idle machine).  Measured (issue 13, AMD EPYC
Zen 4, 2 cores shared with other jobs, 2026-11-27): the lanes finished within 3 % of
each other (load 4.4-7.5: Fig. 5 396 s; Figs. 3, 2, 4, 6, 7, 8, Table 2 and the
validity item 386 s; load 6-16: 1,302 against 1,316 s); Fig. 3 goes first in the
calling process for the same reason as in :data:`LANES`.  Since Figs. 2, 6 and 7's
``--full`` steps (their ``FULL``: Fig. 2 at rtol 1e-5, Fig. 6 at twice the default step,
Fig. 7's points in this process with Blanes–Moan 4) the calling lane's items, run in
one process on one kernel thread (``--workers 1`` without Fig. 5, warm, AMD EPYC Zen 4,
2026-11-27 16:41-16:50 UTC), take 109.5 s CPU (98.8 user + 10.7 system; load 7-8)
against 197.2 s before (177.2 + 20.0, Fig. 7 on Dask; load 4-7): 1.80× less, so ~100 s
for the lane that took ~180 s on the idle machine (issue 13: ≤ ~110 s).  In a two-lane
run under load 6-10 (16:22 UTC) the lane finished in 0.72× Fig. 5's wall time (381
against 529 s, Fig. 5 as before).  No item moves: Fig. 5's lane (~180 s idle) aims at
~100 s (its continuum's work), about this lane's ~100 s; moving the validity map (~25 s
CPU) or Fig. 6 (~17 s) to it would tip the balance the other way."""

FULL_WORKERS = 2
"""Worker processes of ``--full`` (:func:`reproduce`'s default there, capped at the cores
this process may use), each on one kernel thread: the same numbers, bit for bit, as
one process on any thread count (``tests/discrete/test_parallel.py``).

Measured (issue 13, AMD EPYC Zen 4, 2 cores shared with other jobs, fresh ``--out``,
warm kernels, ``/usr/bin/time``): one process (``--workers 1``, threaded kernels)
547 s wall, 391 s CPU at load 4.7-7.0, two (:data:`FULL_LANES`) 402 s wall (0.73×),
434 s CPU at load 4.4-7.5; an earlier pair under load 6-16: 1,976 s / 447 s against
1,343 s / 433 s (0.68×); the ``--json`` output byte-identical in all four.  Under such
load the wall times say little beyond the ratio; the CPU time is what the lanes share,
and it bounds the wall at about half of it: ~200 s for the idle machine's ~390 s CPU if
the lanes stay balanced there (issue 13's 120 s needs less CPU, mostly in Fig. 5's
continuum, not more processes).  After Figs. 2, 6 and 7's ``--full`` steps (load 6-10,
2026-11-27 16:22 UTC, two workers): 538 s wall, 306 s CPU (294 user + 12 system), peak
RSS 0.54 GB; the numbers of every item but Figs. 2 and 6 bitwise those before (Fig. 5
was not changed)."""

_JOIN_GRACE = 10.0
"""Seconds the calling process waits, after a SIGINT/SIGTERM, for the worker to stop by
itself (a terminal's Ctrl-C reaches both) before passing the signal on."""


def lanes(names, workers: int, mode: str = "quick") -> list[list[str]]:
    """The items ``names`` (report order) split into the mode's lanes, empty lanes dropped.

    :data:`LANES` in ``"quick"`` mode, :data:`FULL_LANES` in ``"full"``.  One lane (all
    of ``names``, :data:`FIRST` first) if ``workers`` is 1 or only one lane has items.
    """
    if workers == 1:
        return [[n for n in FIRST if n in names] + [n for n in names if n not in FIRST]]
    table = FULL_LANES if mode == "full" else LANES
    out = [[n for n in lane if n in names] for lane in table]
    out[1] += [n for n in names if n not in table[0] + table[1]]
    return [lane for lane in out if lane]


@contextmanager
def _compile_timer(ctx):
    """Add the seconds numba spends compiling to ``ctx.compile_seconds``.

    numba's ``"numba:compile"`` events (:mod:`numba.core.event`) fire only for a real
    compilation, not for a kernel loaded from its on-disk cache; nested compiles are
    counted once (the outermost event's duration).
    """
    from numba.core import event

    def add(seconds: float) -> None:
        ctx.compile_seconds += seconds

    with event.install_timer("numba:compile", add):
        yield


def _run_lane(ctx, names, order: dict, start: float, threads) -> list[ItemRun]:
    from theory.jitcache import announce_compilation

    runs = []
    with kernel_threads(threads), _compile_timer(ctx), \
            announce_compilation(enabled=ctx.progress, log=ctx.log):
        for name in names:  # "item k of n" before each item's messages
            ctx.log(f"[{order[name]}/{len(order)}] {name} ({time.perf_counter() - start:.0f} "
                    "s elapsed)")
            runs.append(run_item(ctx, name))
    return runs


def _die_with_parent() -> None:
    """Ask Linux to send this (worker) process SIGTERM when its parent dies (best effort)."""
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


def _lane_worker(conn, ctx, names, order, start, threads) -> None:
    """Body of the worker process: run a lane, send its runs (modules dropped) back."""
    import pickle

    from ..checkpoint import Interrupted

    _die_with_parent()
    try:
        runs = _run_lane(ctx, names, order, start, threads)
        payload = ("ok", [(r.name, r.result, r.figures, r.numbers, r.seconds, r.computed,
                           r.reused) for r in runs], ctx.notes, ctx.compile_seconds)
    except Interrupted as exc:
        note = str(exc).split("; ", 1)[1] if "; " in str(exc) else None
        payload = ("interrupted", exc.signum, exc.checkpoint, exc.t, exc.steps, note)
    except BaseException as exc:  # noqa: BLE001 (re-raised in the calling process)
        import traceback

        try:
            pickle.dumps(exc)
        except Exception:  # noqa: BLE001
            exc = RuntimeError(f"reproduce worker failed: {exc!r}")
        payload = ("error", exc, traceback.format_exc())
    try:
        conn.send(payload)
    except (OSError, EOFError):  # the calling process is gone
        pass
    finally:
        conn.close()


def _stop_worker(proc, exc: BaseException) -> None:
    """After ``exc`` in the calling process: let the worker stop (checkpoint), then reap it."""
    from ..checkpoint import Interrupted

    proc.join(_JOIN_GRACE)  # a terminal's Ctrl-C (process group) reached it too
    if proc.is_alive():
        sig = (exc.signum if isinstance(exc, Interrupted) else
               signal.SIGINT if isinstance(exc, KeyboardInterrupt) else signal.SIGTERM)
        try:
            os.kill(proc.pid, sig)
        except ProcessLookupError:
            pass
        proc.join(60.0)
    if proc.is_alive():
        proc.kill()
        proc.join()


def _run_parallel(ctx, parts, order, start, threads) -> list[ItemRun]:
    """Run the lanes ``parts`` (:func:`lanes`); the runs in report order.

    The leading :data:`FIRST` items of ``parts[1]`` here (else its Fig. 3, if first:
    :data:`LANES`), then ``parts[0]`` in a forked worker and the rest of ``parts[1]`` here,
    then (if the worker runs Fig. 5) the cases of Fig. 5 the worker has not started.
    """
    import shutil
    import tempfile

    # Fig. 5's cases can be shared: this lane runs those the worker has not started
    # once its own items are done (fig5.run_spare); the claim files live in a directory
    # of this call (a --force run recomputes each case where it is claimed: not shared)
    share = "fig5" in parts[0] and not ctx.force
    if share:
        ctx.claims = Path(tempfile.mkdtemp(prefix="hertzchain-claims-"))
    try:
        return _run_lanes(ctx, parts, order, start, threads, share)
    finally:
        if share:
            shutil.rmtree(ctx.claims, ignore_errors=True)
            ctx.claims = None


def _run_lanes(ctx, parts, order, start, threads, share: bool) -> list[ItemRun]:
    import multiprocessing as mp

    from ..checkpoint import Interrupted

    # the items before the fork load the kernels the worker shares: the lane's leading
    # FIRST items (--quick), else its Fig. 3 (--full's lane starts with it)
    k = 0
    while k < len(parts[1]) and parts[1][k] in FIRST:
        k += 1
    k = k or int(parts[1][0] == "fig3")
    first = _run_lane(ctx, parts[1][:k], order, start, threads)
    fork = mp.get_context("fork")
    recv, send = fork.Pipe(duplex=False)
    proc = fork.Process(target=_lane_worker, name="hertzchain-reproduce-lane",
                        args=(send, ctx, parts[0], order, start, threads))
    for stream in (sys.stdout, sys.stderr):  # (else the worker would write their buffers too)
        stream.flush()
    # the worker's collector leaves the inherited objects (and their pages) alone; a
    # ``hertzchain`` command has frozen its imports already (cli._process_gc), and those
    # stay frozen here: unfreeze only if nothing was frozen before
    frozen_before = gc.get_freeze_count()
    gc.freeze()
    try:
        proc.start()
    finally:
        if not frozen_before:
            gc.unfreeze()
    send.close()
    try:
        mine = first + _run_lane(ctx, parts[1][k:], order, start, threads)
        spared = (_run_spare(ctx, start, threads,
                             lambda: recv.poll() or not proc.is_alive()) if share else [])
        try:
            payload = recv.recv()
        except EOFError:
            payload = ("error", RuntimeError(
                f"the reproduce worker (items {', '.join(parts[0])}) died "
                f"(exit code {proc.exitcode})"), "")
    except BaseException as exc:
        _stop_worker(proc, exc)
        raise
    finally:
        recv.close()
    proc.join()
    if payload[0] == "interrupted":
        raise Interrupted(*payload[1:5], note=payload[5])
    if payload[0] == "error":
        raise payload[1]
    theirs = [ItemRun(name, importlib.import_module(f"{__name__}.{_MODULES[name][0]}"),
                      *rest) for name, *rest in payload[1]]
    done_here = set(spared)
    for r in theirs:  # files the worker reused because this lane computed them
        r.computed += [p for p in r.reused if p in done_here]
        r.reused = [p for p in r.reused if p not in done_here]
    ctx.notes.update(payload[2])
    ctx.compile_seconds += payload[3]
    return _in_report_order(ctx, mine + theirs, order)


def _run_spare(ctx, start: float, threads, stop) -> list:
    """Run the calling lane's share of the worker's Fig. 5 (:func:`.fig5.run_spare`).

    Returns the files it computed (counted as the worker's item's, which reuses them).
    """
    from theory.jitcache import announce_compilation

    from . import fig5

    c0 = len(ctx.computed)
    with kernel_threads(threads), _compile_timer(ctx), \
            announce_compilation(enabled=ctx.progress, log=ctx.log):
        ctx.log(f"fig5: this process takes the cases the worker has not started "
                f"({time.perf_counter() - start:.0f} s elapsed)")
        fig5.run_spare(ctx, stop)
    return ctx.computed[c0:]


def _in_report_order(ctx, runs, order: dict) -> list[ItemRun]:
    """``runs`` sorted by ``order``, and the context's files and timings in that order."""
    runs = sorted(runs, key=lambda r: order[r.name])
    ctx.computed[:] = [p for r in runs for p in r.computed]
    ctx.reused[:] = [p for r in runs for p in r.reused]
    ctx.timings.clear()
    ctx.timings.update({r.name: r.seconds for r in runs})
    return runs


def reproduce(items=None, *, mode: str = "quick", out: str | Path = "hertzchain-reproduce",
              force: bool = False, progress: bool = True, report: bool = True,
              checkpoint_interval: float | None = 300.0,
              threads: int | None = None, workers: int | None = None) -> dict:
    """Reproduce the given items and write the report.

    Parameters
    ----------
    items : sequence of str, optional
        Among :data:`ITEMS` (default: all).
    mode : {"quick", "full"}
        Run sizes (see each module's ``QUICK`` and ``FULL``).
    out : path
        Output directory.
    force : bool
        Recompute every simulation even if its HDF5 file exists (checkpoints discarded).
    progress : bool
        Progress bars and messages on stderr.
    report : bool
        Write ``report.md`` and ``report.html``.
    checkpoint_interval : float or None
        Wall time between checkpoints of a simulation, s (>= 0); after a kill, calling
        again with the same arguments resumes from the last one, bit for bit
        (:mod:`.common`).  None: no checkpoints.
    threads : int, optional
        Kernel threads of the discrete runs (:func:`kernel_threads`; the results are
        the same, bit for bit, for every count).  Default: :data:`QUICK_THREADS` in
        ``"quick"`` mode; in ``"full"`` 1 with two workers, numba's own count with one
        (Fig. 5's 50,000 grains).
    workers : {1, 2}, optional
        Processes: 2 runs the items in two lanes (:data:`LANES`, in ``"full"`` mode
        :data:`FULL_LANES`), one in a forked worker (POSIX only), each on ``threads``
        kernel threads; the numbers, files and counts are those of one process, bit for
        bit; 2 needs ``threads`` 1.  Default (with ``threads`` None or 1):
        :data:`QUICK_WORKERS` or :data:`FULL_WORKERS`, at most the usable cores; 1 with
        more threads, and in ``"full"`` mode if the items fill only one lane.

    Returns
    -------
    dict
        ``items`` (each item's JSON numbers), ``runs`` (:class:`ItemRun` list), ``report``
        (paths), ``computed``/``reused`` (HDF5 files), ``wall_time`` (s).

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during a simulation, after writing its checkpoint (with two
        workers: once both have stopped, each after writing its checkpoint).
    ValueError
        ``workers`` not 1 or 2.
    """
    from .common import Context, map_large_arrays

    map_large_arrays()  # (freed arrays go back to the system: issue 13's peak memory)
    names = check_items(items)
    if workers is None:
        default = QUICK_WORKERS if mode == "quick" else FULL_WORKERS
        from ..sweep.engine import default_workers  # (the usable cores)

        workers = min(default, default_workers()) if threads in (None, 1) else 1
        if mode == "full" and len(lanes(names, workers, mode)) == 1:
            workers = 1  # (e.g. ``--full fig5``: one process, on numba's threads)
    if workers not in (1, 2) or isinstance(workers, bool):
        raise ValueError(f"workers must be 1 or 2 (got {workers!r})")
    if threads is None and (mode == "quick" or workers == 2):
        threads = QUICK_THREADS if mode == "quick" else 1
    if workers == 2 and threads != 1:
        raise ValueError(f"workers=2 runs each lane on one kernel thread (threads=1; got "
                         f"threads={threads!r}): a forked process must not start the "
                         "threaded kernel after its parent has (GNU OpenMP)")
    if workers == 2 and not hasattr(os, "fork"):
        workers = 1
    ctx = Context(Path(out), mode=mode, force=force, progress=progress,
                  checkpoint_interval=checkpoint_interval)
    start = time.perf_counter()
    order = {name: k for k, name in enumerate(names, 1)}
    parts = lanes(names, workers, mode)
    if len(parts) == 1:
        runs = _in_report_order(ctx, _run_lane(ctx, parts[0], order, start, threads), order)
    else:
        runs = _run_parallel(ctx, parts, order, start, threads)
    wall = time.perf_counter() - start
    paths = ()
    if report:
        from .report import write_report

        paths = write_report(ctx, runs, wall)
    return {"items": {r.name: r.numbers for r in runs}, "runs": runs, "report": paths,
            "computed": list(ctx.computed), "reused": list(ctx.reused), "wall_time": wall,
            "compile_seconds": ctx.compile_seconds, "context": ctx}
