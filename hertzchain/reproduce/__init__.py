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

How the items run
-----------------
Each item is one task, except those whose module splits it into parts
(``parts(ctx)``, ``run_part(ctx, part)``, ``combine(ctx, parts)``: Fig. 5's four cases),
which are a task per part and a last task that combines them and draws the figure.
With one worker the tasks run one after the other in this process; with more they run
on a local Dask cluster of worker processes (:func:`hertzchain.sweep.engine.local_client`,
the engine of ``hertzchain sweep``), one kernel thread each.  The tasks are handed out
in :data:`ORDER` (the longest first, so that the last task to start is a short one and
the workers finish together) as workers become free; Table 2 starts after Fig. 8
(:data:`AFTER`), whose point files it reuses.  The tasks share nothing but files, which
are written atomically: every number, file and computed/reused count is that of one
process, bit for bit, for every worker count.

Examples
--------
>>> from hertzchain.reproduce import reproduce
>>> out = reproduce(["fig2", "table2"], mode="quick", out="repro")  # doctest: +SKIP
>>> out["items"]["fig2"]["vmax_over_v0"]                            # doctest: +SKIP
{'0': 0.68163, '0.001': 0.082183}
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import signal
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["ITEMS", "ORDER", "AFTER", "ItemRun", "Task", "TaskOutcome", "WorkerDied",
           "plan", "run_task", "check_items", "kernel_threads", "reproduce"]

ITEMS = ("fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "table2", "validity")
"""Items in report order."""

ORDER = ("fig7", "fig2", "fig6", "fig5", "fig8", "validity", "fig3", "fig4", "table2")
"""Items in the order their tasks are handed to the workers: by decreasing cost, so that
with several workers the last tasks to start are short ones (longest processing time
first: the greedy schedule ends within 4/3 − 1/(3m) of the best on m workers; R. L.
Graham, SIAM J. Appl. Math. 17 (1969) 416).  The costs are the items' CPU times in
``--quick`` (Fig. 7 and Fig. 2 the largest, then Fig. 6 and each Fig. 5 case)."""

AFTER = {"table2": ("fig8",)}
"""Items that start only when others have finished: Table 2 reuses the point files of
Fig. 8 (run at the same time, both would compute them, and the counts of computed and
reused files would depend on the worker count)."""

_MODULES = {"fig2": ("fig2", {}), "fig3": ("fig34", {"item": "fig3"}),
            "fig4": ("fig34", {"item": "fig4"}), "fig5": ("fig5", {}), "fig6": ("fig6", {}),
            "fig7": ("fig7", {}), "fig8": ("fig8", {}), "table2": ("table2", {}),
            "validity": ("validity", {})}


def _module(name: str):
    return importlib.import_module(f"{__name__}.{_MODULES[name][0]}")


@dataclass
class ItemRun:
    """What one item produced."""

    name: str
    result: object
    figures: list = field(default_factory=list)
    numbers: dict = field(default_factory=dict)
    seconds: float = 0.0
    """Seconds its tasks took, summed (CPU-bound: about their CPU time)."""
    computed: list = field(default_factory=list)
    """Files this item computed (its share of ``Context.computed``)."""
    reused: list = field(default_factory=list)
    """Files this item reused (its share of ``Context.reused``)."""

    @property
    def module(self):
        """The item's module (:mod:`.fig2`, ...)."""
        return _module(self.name)


@dataclass(frozen=True)
class Task:
    """One task of a reproduction.

    ``kind`` is ``"item"`` (a whole item: run, figures, numbers), ``"part"`` (part
    ``part`` of an item its module splits) or ``"combine"`` (the item from its parts'
    results: figures, numbers).
    """

    name: str
    kind: str = "item"
    part: str | None = None

    @property
    def key(self) -> str:
        """Unique within a reproduction: ``fig5``, ``fig5:a``, ``fig5:combine``."""
        return self.name if self.kind == "item" else \
            f"{self.name}:{self.part if self.kind == 'part' else 'combine'}"

    @property
    def label(self) -> str:
        """For messages: ``fig5``, ``fig5 (a)``, ``fig5 (figures)``."""
        return self.name if self.kind == "item" else \
            f"{self.name} ({self.part if self.kind == 'part' else 'figures'})"


@dataclass
class TaskOutcome:
    """What a task returned: its value and its share of the context's bookkeeping.

    ``value``: a part's result, or ``(result, figures, numbers)`` of an item;
    ``interrupted``: the fields of a :class:`hertzchain.checkpoint.Interrupted` raised in
    a worker process (signal, checkpoint, t, steps, note), which does not pickle;
    ``started``: False for a task a stopping worker did not start.
    """

    task: Task
    value: object = None
    seconds: float = 0.0
    computed: list = field(default_factory=list)
    reused: list = field(default_factory=list)
    notes: dict = field(default_factory=dict)
    compile_seconds: float = 0.0
    interrupted: tuple | None = None
    started: bool = True


class WorkerDied(ChildProcessError):
    """A worker process died (killed, out of memory, crashed) while running a task."""


def check_items(items) -> list[str]:
    """The items in report order, validated (default: all); ValueError for unknown names."""
    items = list(items or ITEMS)
    bad = [i for i in items if i not in ITEMS]
    if bad:
        raise ValueError(f"unknown item(s) {', '.join(map(repr, bad))}; choose from "
                         f"{', '.join(ITEMS)}")
    return [i for i in ITEMS if i in items]


def plan(names, ctx) -> list[Task]:
    """The tasks of the items ``names`` in the order they are handed out (:data:`ORDER`).

    Every task comes after the tasks it needs: an item's ``"combine"`` after its parts,
    an item of :data:`AFTER` after the items it waits for.
    """
    names = set(names)
    tasks = []
    for name in sorted(names, key=ORDER.index):
        mod = _module(name)
        if hasattr(mod, "parts"):
            tasks += [Task(name, "part", p) for p in mod.parts(ctx)]
            tasks.append(Task(name, "combine"))
        else:
            tasks.append(Task(name))
    done: set[str] = set()
    ordered: list[Task] = []
    while tasks:  # the first task whose needs are met, repeatedly
        task = next(t for t in tasks if _needs(t, tasks + ordered, names) <= done)
        tasks.remove(task)
        ordered.append(task)
        done.add(task.key)
    return ordered


def _needs(task: Task, tasks: list[Task], names: set) -> set[str]:
    """Keys of the tasks ``task`` needs finished (among ``tasks``)."""
    if task.kind == "combine":
        return {t.key for t in tasks if t.name == task.name and t.kind == "part"}
    if task.kind == "part":
        return set()
    return {t.key for t in tasks if t.name in AFTER.get(task.name, ()) and t.name in names
            and t.kind != "part"}


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


@contextmanager
def _compile_timer(ctx):
    """Add the CPU seconds numba spends compiling to ``ctx.compile_seconds``.

    :func:`theory.jitcache.compile_cpu_timer`: real compilations only (not kernels
    loaded from the on-disk cache), nested compiles counted once, the compiling thread's
    CPU time (not the wall time, which on a loaded machine includes waiting for a core).
    """
    from theory.jitcache import compile_cpu_timer

    def add(seconds: float) -> None:
        ctx.compile_seconds += seconds

    with compile_cpu_timer(add):
        yield


def run_task(template, task: Task, inputs=(), *, threads: int | None = None,
             position: str = "", start: float | None = None,
             pickled: bool = False) -> TaskOutcome:
    """Run one task on a fresh copy of the context ``template``; its outcome.

    ``inputs``: the outcomes of the parts of a ``"combine"`` task, in part order;
    ``threads``: kernel threads (:func:`kernel_threads`); ``position``, ``start``: for
    the progress message ("[k/n] item (t s elapsed)", ``start`` from :func:`time.time`).
    With ``pickled`` (a worker process), an :class:`hertzchain.checkpoint.Interrupted`
    is returned in the outcome instead of raised.
    """
    from theory.jitcache import announce_compilation

    from ..checkpoint import Interrupted

    ctx = dataclasses.replace(template, computed=[], reused=[], timings={}, notes={},
                              compile_seconds=0.0)
    out = TaskOutcome(task)
    t0 = time.perf_counter()
    if start is not None:
        ctx.log(f"[{position}] {task.label} ({time.time() - start:.0f} s elapsed)")
    try:
        with kernel_threads(threads), _compile_timer(ctx), \
                announce_compilation(enabled=ctx.progress, log=ctx.log):
            out.value = _run(ctx, task, [i.value for i in inputs])
    except Interrupted as exc:
        if not pickled:
            raise
        note = str(exc).split("; ", 1)[1] if "; " in str(exc) else None
        out.interrupted = (exc.signum, exc.checkpoint, exc.t, exc.steps, note)
    out.seconds = time.perf_counter() - t0
    out.computed, out.reused = ctx.computed, ctx.reused
    out.notes, out.compile_seconds = ctx.notes, ctx.compile_seconds
    return out


def _run(ctx, task: Task, parts: list):
    mod = _module(task.name)
    if task.kind == "part":
        return mod.run_part(ctx, task.part)
    if task.kind == "combine":
        result = mod.combine(ctx, parts)
    else:
        result = mod.run(ctx, **_MODULES[task.name][1])
    figs = mod.figures(ctx, result) if hasattr(mod, "figures") else []
    return result, figs, mod.to_json(result)


def _remote_task(template, task, inputs, threads, position, start) -> TaskOutcome:
    """:func:`run_task` in a worker process (the Dask task).

    Not started once the worker was told to stop (:func:`_stop_on_signals`); an
    exception that would not pickle is raised as a RuntimeError with its message.
    """
    from ..checkpoint import stop_requested

    if stop_requested() is not None:
        return TaskOutcome(task, started=False)
    try:
        return run_task(template, task, inputs, threads=threads, position=position,
                        start=start, pickled=True)
    except Exception as exc:
        import pickle

        try:
            pickle.loads(pickle.dumps(exc))
        except Exception:  # noqa: BLE001 (raised again below, as a plain RuntimeError)
            raise RuntimeError(f"{type(exc).__name__}: {exc}") from None
        raise


def _stop_on_signals() -> None:
    """Make SIGINT stop this worker process's runs instead of the process.

    Run in the worker's main thread: each run stops at its next segment end after
    writing its checkpoint (:func:`hertzchain.checkpoint.request_stop`).  SIGTERM keeps
    its default (the cluster ends its workers with it).
    """
    from ..checkpoint import request_stop

    signal.signal(signal.SIGINT, lambda signum, frame: request_stop(signum))


def _item_runs(names, outcomes: dict[str, TaskOutcome]) -> list[ItemRun]:
    """The items' runs in report order from the outcomes of their tasks.

    ``outcomes`` is in plan order: an item's parts, then the task that made the item.
    """
    runs = []
    for name in names:
        mine = [o for o in outcomes.values() if o.task.name == name]
        result, figs, numbers = mine[-1].value
        runs.append(ItemRun(name, result, figs, numbers, sum(o.seconds for o in mine),
                            [p for o in mine for p in o.computed],
                            [p for o in mine for p in o.reused]))
    return runs


def _in_process(ctx, tasks: list[Task], threads, positions, start) -> dict:
    """Run ``tasks`` here, one after the other; their outcomes by key (in plan order)."""
    outcomes: dict[str, TaskOutcome] = {}
    for task in tasks:
        inputs = [o for o in outcomes.values()
                  if task.kind == "combine" and o.task.name == task.name]
        outcomes[task.key] = run_task(ctx, task, inputs, threads=threads,
                                      position=positions[task.name], start=start)
    return outcomes


def _on_cluster(ctx, tasks: list[Task], workers: int, threads, positions, start) -> dict:
    """Run ``tasks`` on a local cluster of ``workers`` processes; outcomes by key.

    A task is submitted once the tasks it needs have finished (a ``"combine"`` task
    receives its parts' futures), with a priority from its place in the plan, so that
    the scheduler hands the tasks out in plan order as workers become free.  On
    SIGINT/SIGTERM (or a task interrupted by one) the workers are told to stop
    (:func:`_wind_down`).
    """
    import uuid

    from distributed import as_completed

    from ..sweep.engine import local_client

    names = {t.name for t in tasks}
    token = uuid.uuid4().hex[:8]
    outcomes: dict[str, TaskOutcome] = {}
    futures: dict[str, object] = {}
    waiting = list(tasks)
    with local_client(workers, dashboard=False, config=_CLUSTER_CONFIG) as client, \
            _sigterm_raises():
        pids = client.run(_stop_on_signals_pid)
        running = as_completed()

        def submit_ready() -> None:
            for task in [t for t in waiting if _needs(t, tasks, names) <= set(outcomes)]:
                waiting.remove(task)
                inputs = [futures[k] for k in sorted(_needs(task, tasks, names),
                                                     key=[t.key for t in tasks].index)] \
                    if task.kind == "combine" else []
                fut = client.submit(_remote_task, ctx, task, inputs, threads,
                                    positions[task.name], start,
                                    key=f"reproduce-{task.key}-{token}", pure=False,
                                    priority=len(tasks) - tasks.index(task))
                futures[task.key] = fut
                running.add(fut)

        try:
            submit_ready()
            for fut in running:
                task = next(t for t in tasks if futures.get(t.key) is fut)
                out = _result(fut, task)
                if out.interrupted is not None:
                    raise _interrupted(out)
                outcomes[task.key] = out
                submit_ready()
        except KeyboardInterrupt as exc:  # also Interrupted, and SIGTERM here
            _wind_down(pids.values(), getattr(exc, "signum", signal.SIGINT), futures,
                       tasks, exc)
        finally:
            client.cancel(list(futures.values()))
    return {t.key: outcomes[t.key] for t in tasks}


STOP_GRACE = 60.0
"""Seconds a reproduction waits, after SIGINT/SIGTERM, for its workers to stop their
runs with a checkpoint; a second SIGINT stops at once."""


def _wind_down(pids, signum: int, futures: dict, tasks: list[Task], exc: BaseException):
    """Stop the workers after ``exc`` (``signum`` here, or a task interrupted), then raise.

    Each worker gets SIGINT (its runs stop at their next segment end, each after
    writing its checkpoint: :func:`_stop_on_signals`) and its tasks up to
    :data:`STOP_GRACE` s to return; raised: the first interrupted task's
    :class:`~hertzchain.checkpoint.Interrupted` in plan order (with ``signum``), else
    ``exc``.
    """
    import os

    from distributed import wait

    for pid in pids:
        try:
            os.kill(pid, signal.SIGINT)
        except ProcessLookupError:
            pass
    with contextlib.suppress(TimeoutError):
        wait(list(futures.values()), timeout=STOP_GRACE)
    done = {key: f.result() for key, f in futures.items() if f.status == "finished"}
    stopped = [done[t.key] for t in tasks if t.key in done and done[t.key].interrupted]
    if stopped:
        raise _interrupted(stopped[0], signum) from None
    raise exc


def _interrupted(out: TaskOutcome, signum: int | None = None):
    from ..checkpoint import Interrupted

    sig, checkpoint, t, steps, note = out.interrupted
    return Interrupted(sig if signum is None else signum, checkpoint, t, steps, note=note)



def _stop_on_signals_pid() -> int:
    """:func:`_stop_on_signals` (run on each worker by ``client.run``); the worker's pid."""
    import os

    _stop_on_signals()
    return os.getpid()


class _Terminated(KeyboardInterrupt):
    """SIGTERM received by the process that waits for the workers."""

    signum = signal.SIGTERM


@contextmanager
def _sigterm_raises():
    """Inside the block, SIGTERM raises :class:`_Terminated` (in the main thread)."""
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        raise _Terminated("terminated")

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


_CLUSTER_CONFIG = {"distributed.scheduler.allowed-failures": 0,
                   "distributed.scheduler.worker-saturation": 1.0}
"""Dask settings of a reproduction's cluster: a task whose worker dies is not run again
(:class:`WorkerDied`; a crash or the out-of-memory killer would only repeat), and a
worker is given a task only when it is free (so the tasks start in plan order)."""


def _result(fut, task: Task) -> TaskOutcome:
    """The outcome of ``fut``; its worker's death as :class:`WorkerDied`, naming the task."""
    from distributed import KilledWorker

    try:
        return fut.result()
    except KilledWorker:
        raise WorkerDied(f"the worker process running {task.label} died (killed, out of memory "
                         "or crashed); the finished simulations are kept: rerun the same "
                         "command to continue") from None
    except Exception as exc:
        exc.add_note(f"(in the reproduce task {task.key})")
        raise


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
        Kernel threads of each task's discrete runs (:func:`kernel_threads`; the
        results are the same, bit for bit, for every count).  Default: 1 (each worker
        is one core; the serial kernel needs no compiled threaded variant), except in
        ``"full"`` mode with one worker: numba's own count (Fig. 5's 50,000 grains).
    workers : int, optional
        Processes (>= 1): 1 runs the tasks in this process, more on a local Dask
        cluster (module docstring).  Default: the cores this process may use, at most
        the number of tasks.

    Returns
    -------
    dict
        ``items`` (each item's JSON numbers), ``runs`` (:class:`ItemRun` list), ``report``
        (paths), ``computed``/``reused`` (HDF5 files), ``wall_time`` (s),
        ``compile_seconds``, ``workers``, ``context``.

    Raises
    ------
    hertzchain.checkpoint.Interrupted
        SIGINT/SIGTERM during a simulation, after writing its checkpoint.
    WorkerDied
        A worker process died; the message names the task.
    ValueError
        ``workers`` not an integer >= 1.
    """
    from .common import Context

    names = check_items(items)
    if workers is not None and (isinstance(workers, bool) or int(workers) != workers
                                or workers < 1):
        raise ValueError(f"workers must be an integer >= 1 (got {workers!r})")
    ctx = Context(Path(out), mode=mode, force=force, progress=progress,
                  checkpoint_interval=checkpoint_interval)
    tasks = plan(names, ctx)
    if workers is None:
        from ..sweep.engine import default_workers

        workers = min(default_workers(), sum(t.kind != "combine" for t in tasks))
    workers = int(workers)
    if threads is None and (mode == "quick" or workers > 1):
        threads = 1
    positions = {name: f"{k}/{len(names)}" for k, name in enumerate(names, 1)}
    start = time.time()
    t0 = time.perf_counter()
    if workers == 1:
        outcomes = _in_process(ctx, tasks, threads, positions, start)
    else:
        outcomes = _on_cluster(ctx, tasks, workers, threads, positions, start)
    runs = _item_runs(names, outcomes)
    ctx.computed[:] = [p for r in runs for p in r.computed]
    ctx.reused[:] = [p for r in runs for p in r.reused]
    ctx.timings.update({r.name: r.seconds for r in runs})
    for o in outcomes.values():
        ctx.notes.update(o.notes)
        ctx.compile_seconds += o.compile_seconds
    wall = time.perf_counter() - t0
    paths = ()
    if report:
        from .report import write_report

        paths = write_report(ctx, runs, wall)
    return {"items": {r.name: r.numbers for r in runs}, "runs": runs, "report": paths,
            "computed": list(ctx.computed), "reused": list(ctx.reused), "wall_time": wall,
            "compile_seconds": ctx.compile_seconds, "workers": workers, "context": ctx}
