"""Run a sweep on Dask: one task per missing point, results recorded as they arrive.

The client submits every point whose id has no record yet (and, with
``retry_failed``, those whose record is a failure) with ``client.submit`` and consumes
them with ``as_completed``; each finished point is appended to the record log at once
(:class:`~hertzchain.sweep.store.RecordStore`), so killing the sweep loses at most the
points in flight.  The consolidated ``results.h5`` is rewritten atomically every
``consolidate_every`` seconds and at the end (also after an interruption).

By default the sweep starts a :class:`distributed.LocalCluster` of worker processes
with one thread each (numba kernels release nothing to share, and one thread per
process keeps each kernel on its own core); with ``scheduler`` it connects to an
existing ``dask.distributed`` scheduler instead, whose workers must have hertzchain
installed and, for ``full_output``, share the output directory's file system.
Each worker is warmed up once with ``client.run`` (a tiny call of the point function)
so numba kernels (``cache=True``) compile or load once per worker, not once per point.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import logging
import os
import socket
import sys
import time
import traceback
import uuid
from collections.abc import Callable, Iterator, Mapping
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..cache import atomic_path
from ..faults import FailedWrites
from ..measure import unverified
from ..scenario import Scenario, ScenarioError, parse_scenario
from .spec import Point, SweepError, SweepSpec, load_sweep_spec, parse_sweep_spec
from .store import SUMMARY_FIELDS, RecordStore, records_from_table, write_table

__all__ = [
    "DEFAULT_POINT_FUNCTION",
    "MODELS_POINT_FUNCTION",
    "default_point_function",
    "SweepOutcome",
    "run_sweep",
    "run_batch",
    "ensemble_batches",
    "resolve_point_function",
    "function_name",
    "points_to_run",
    "tiny_scenario",
    "default_workers",
    "local_client",
]

DEFAULT_POINT_FUNCTION = "hertzchain.runner:run_scenario"
"""``module:function`` run for each point unless another is given (the discrete chain)."""

MODELS_POINT_FUNCTION = "hertzchain.compare:compare_point"
"""Run for each point, unless another is given, when the sweep asks for the models."""


def default_point_function(spec: SweepSpec) -> str:
    """The point function of a sweep run without one.

    :data:`MODELS_POINT_FUNCTION` (every model of the point, compared:
    :func:`hertzchain.compare.compare_point`) when the base scenario has a ``[models]``
    table or a point runs a continuum; the realisations of a sweep with an
    ``[ensemble]`` (:data:`hertzchain.sweep.ensemble.ENSEMBLE_POINT_FUNCTION`);
    otherwise :data:`DEFAULT_POINT_FUNCTION`.
    """
    if spec.ensemble is not None:
        from .ensemble import ENSEMBLE_POINT_FUNCTION

        return ENSEMBLE_POINT_FUNCTION
    if spec.base.get("models") or any(p.scenario.models.continuum for p in spec.points()):
        return MODELS_POINT_FUNCTION
    return DEFAULT_POINT_FUNCTION

PointFunction = Callable[..., Mapping[str, Any]]
log = logging.getLogger(__name__)


@dataclass
class SweepOutcome:
    """What a call of :func:`run_sweep` did.

    Attributes
    ----------
    directory, table : pathlib.Path
        Output directory and its ``results.h5``.
    n_points : int
        Points in the sweep.
    n_skipped : int
        Points not run because a record existed already.
    n_run : int
        Points finished (ok or failed) by this call.
    n_ok, n_failed, n_pending : int
        Status counts of the whole table after this call.
    n_incomplete : int
        Points with status "ok" or "unverified" whose run ended before its stop condition
        (``completed`` false in the summary; the reason is in ``incomplete_reason``).
    elapsed : float
        Wall time of this call, s.
    interrupted : bool
        True if the call stopped before every point had a record.
    n_lost : int
        Points whose worker died (``KilledWorker``) in this call: left pending, retried
        by a plain rerun.
    n_unverified : int
        Points that ran but whose summary is not verified to the rtol asked for (status
        "unverified", :func:`hertzchain.measure.unverified`).
    """

    directory: Path
    table: Path
    n_points: int
    n_skipped: int
    n_run: int
    n_ok: int
    n_failed: int
    n_pending: int
    elapsed: float
    interrupted: bool = False
    n_incomplete: int = 0
    n_lost: int = 0
    n_unverified: int = 0

    def to_dict(self) -> dict:
        """JSON-able dict (paths as strings)."""
        d = asdict(self)
        d["directory"], d["table"] = str(self.directory), str(self.table)
        return d


def default_workers() -> int:
    """Number of cores this process may use (all of them by default)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def resolve_point_function(fn: PointFunction | str | None) -> PointFunction:
    """Return the callable for ``fn`` (a callable, ``"module:function"`` or None = default).

    Raises
    ------
    SweepError
        If the module or attribute cannot be imported.
    """
    if callable(fn):
        return fn
    text = DEFAULT_POINT_FUNCTION if fn is None else fn
    module, sep, attr = text.partition(":")
    if not sep or not module or not attr:
        raise SweepError(f"point function {text!r} must be given as 'module:function'")
    try:
        obj = getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as exc:
        hint = (" (the runner is not available yet; pass another point function)"
                if fn is None else "")
        raise SweepError(f"cannot import point function {text!r}: "
                         f"{type(exc).__name__}: {exc}{hint}") from exc
    if not callable(obj):
        raise SweepError(f"point function {text!r} is not callable")
    return obj


def function_name(fn: PointFunction) -> str:
    """Stable name of a point function, ``module:qualname`` (with a partial's arguments).

    Stored with every record: a record made by another function counts as missing.
    """
    if isinstance(fn, functools.partial):
        args = [repr(a) for a in fn.args] + [f"{k}={v!r}" for k, v in sorted(fn.keywords.items())]
        return f"{function_name(fn.func)}({', '.join(args)})"
    module = getattr(fn, "__module__", None) or type(fn).__module__
    qualname = getattr(fn, "__qualname__", None) or type(fn).__qualname__
    return f"{module}:{qualname}"


def points_to_run(points: list[Point], records: Mapping[str, dict], fname: str | None,
                  retry_failed: bool = False) -> list[Point]:
    """The points a run has to compute.

    Those without a record, with a record made by another function (unless ``fname``
    is None), with ``retry_failed`` with a failed record, and always those an older
    version booked as failed when their worker died (``dask: KilledWorker``).
    """
    todo = []
    for p in points:
        rec = records.get(p.id)
        if (rec is None or (fname is not None and rec.get("point_function", fname) != fname)
                or (retry_failed and rec.get("status") != "ok") or _lost_record(rec)):
            todo.append(p)
    return todo


# -- worker side ----------------------------------------------------------------------
def _plain(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return value


def _check_summary(summary: Any) -> dict[str, Any]:
    if not isinstance(summary, Mapping):
        raise TypeError(f"the point function returned {type(summary).__name__}, not a dict")
    missing = [k for k in SUMMARY_FIELDS if k not in summary]
    if missing:
        raise KeyError(f"the run summary lacks the keys {missing}")
    return {str(k): _plain(v) for k, v in summary.items()}


def run_point(point_function: PointFunction, scenario: Scenario, point_id: str,
              values: Mapping[str, Any], out: str | None = None) -> dict[str, Any]:
    """Run one point and return its record; any ``Exception`` becomes a failed record.

    This is the Dask task.  The record has ``id``, ``values``, ``status`` ("ok",
    "unverified" — it ran, but a ``*_meets_rtol`` key of its summary is false
    (:func:`hertzchain.measure.unverified`): its numbers are kept, flagged — or
    "failed"), ``error`` (``"Type: message"``, or which keys did not verify),
    ``traceback``, ``summary``, ``point_wall_time`` (s), ``worker`` ("host:pid") and
    ``full_output``.
    """
    t0 = time.perf_counter()
    rec: dict[str, Any] = {"id": point_id, "values": dict(values),
                           "worker": f"{socket.gethostname()}:{os.getpid()}",
                           "full_output": ""}
    with FailedWrites() as failed:  # h5py's destructor tracebacks on a full disk: counted
        try:
            summary = point_function(scenario, out=None if out is None else Path(out),
                                     progress=False)
            summary = _check_summary(summary)
            bad = unverified(summary)  # not verified to rtol: reported, but not "ok"
            rec.update(status="unverified" if bad else "ok",
                       error=f"not verified to rtol: {', '.join(bad)} false" if bad else "",
                       summary=summary)
            if out is not None and Path(out).exists():
                rec["full_output"] = str(out)
        except Exception as exc:  # noqa: BLE001 - a failed point must not stop the sweep
            rec.update(status="failed", error=f"{type(exc).__name__}: {exc}", summary={},
                       traceback="".join(traceback.format_exc(limit=-6)))
    if failed.count and rec["status"] != "failed":  # a write failed, and was absorbed
        rec.update(status="failed", summary={},
                   error=f"OSError: disk full: {failed.count} HDF5 write(s) failed "
                         f"({failed.example})")
    rec["point_wall_time"] = time.perf_counter() - t0
    return rec


def run_batch(point_function: PointFunction, scenarios: list[Scenario], point_ids: list[str],
              values: list[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Run a batch of points together and return their records (an ensemble's Dask task).

    ``point_function.batch(scenarios)`` returns one summary per scenario (the
    realisations integrated together, :mod:`hertzchain.sweep.ensemble`); each record
    is :func:`run_point`'s, its ``point_wall_time`` the batch's divided among its
    points.  If the batch fails, every point is run alone (:func:`run_point`), so a
    point's failure stays its own.
    """
    t0 = time.perf_counter()
    worker = f"{socket.gethostname()}:{os.getpid()}"
    try:
        summaries = [_check_summary(x) for x in point_function.batch(scenarios)]
        if len(summaries) != len(scenarios):
            raise RuntimeError(f"the batch returned {len(summaries)} summaries for "
                               f"{len(scenarios)} points")
    except Exception:  # noqa: BLE001 - each point then fails (or not) on its own
        return [run_point(point_function, sc, pid, v)
                for sc, pid, v in zip(scenarios, point_ids, values, strict=True)]
    wall = (time.perf_counter() - t0) / max(len(scenarios), 1)
    return [{"id": pid, "values": dict(v), "worker": worker, "full_output": "",
             "status": "ok", "error": "", "summary": summ, "point_wall_time": wall}
            for pid, v, summ in zip(point_ids, values, summaries, strict=True)]


def ensemble_batches(spec: SweepSpec, todo: list[Point]) -> list[list[Point]]:
    """The points of an ensemble sweep cut into batches (the unit a Dask worker takes).

    Realisations of one point of the other axes (same values but the seed), in order,
    at most ``spec.ensemble.batch`` per batch.
    """
    ens = spec.ensemble
    groups: dict[str, list[Point]] = {}
    for p in todo:
        key = repr(sorted((k, repr(v)) for k, v in p.values.items() if k != ens.name))
        groups.setdefault(key, []).append(p)
    return [pts[i:i + ens.batch] for pts in groups.values()
            for i in range(0, len(pts), ens.batch)]


def tiny_scenario(table: Mapping[str, Any]) -> Scenario | None:
    """A very short run of the same chain type: for warming up (compiling) a worker.

    The first section and the initial condition are kept (so caches such as a settled
    wave to cut are filled too), later sections are cut to at most 40 grains and the
    run lasts 2 µs.  If that is not a valid scenario, the initial condition becomes an
    impact and every section at most 40 grains; returns None if that fails too.
    """
    chain = dict(table.get("chain", {}))
    sections = [dict(s) for s in chain.get("sections", [])]
    run = {"t_end": 2e-6, "max_steps": 10_000}
    tries = []
    if sections:
        tries.append(({**chain, "sections": sections[:1] + [
            dict(s, n=min(int(s.get("n", 1)), 40)) for s in sections[1:]]},
            dict(table.get("initial", {}))))
    tries.append(({**chain, "sections": [dict(s, n=min(int(s.get("n", 1)), 40))
                                         for s in sections]},
                  {"kind": "impact", "v0": 1.0}))
    for tiny_chain, initial in tries:
        try:
            return parse_scenario({"name": "warm-up", "chain": tiny_chain,
                                   "initial": initial, "run": run})
        except ScenarioError:
            continue
    return None


def _warm(point_function: PointFunction, scenario: Scenario) -> dict[str, Any]:
    t0 = time.perf_counter()
    try:
        point_function(scenario, out=None, progress=False)
        error = ""
    except Exception as exc:  # noqa: BLE001 - the tiny run only has to compile
        error = f"{type(exc).__name__}: {exc}"
    return {"seconds": time.perf_counter() - t0, "error": error}


# -- client side ------------------------------------------------------------------------
@contextlib.contextmanager
def _dask_client(client, scheduler: str | None, workers: int | None,
                 processes: bool) -> Iterator[Any]:
    if client is not None:
        yield client
        return
    from distributed import Client

    if scheduler is not None:
        with Client(scheduler, timeout="30s") as c:
            c.wait_for_workers(1, timeout=120)
            yield c
        return
    with local_client(workers, processes=processes) as c:
        yield c


@contextlib.contextmanager
def local_client(workers: int | None = None, *, processes: bool = True,
                 dashboard: bool = True, config: Mapping[str, Any] | None = None
                 ) -> Iterator[Any]:
    """A client of a new :class:`distributed.LocalCluster`, closed with the block.

    ``workers`` workers (default :func:`default_workers`) of one thread each: worker
    processes (``processes``), or threads of this process.  ``dashboard``: serve the
    dashboard on a free port; ``config``: Dask settings in force while the cluster
    runs (e.g. ``{"distributed.scheduler.allowed-failures": 0}``).
    """
    import dask
    from distributed import Client, LocalCluster

    n = workers or default_workers()
    with dask.config.set(dict(config or {})), \
            LocalCluster(n_workers=n, threads_per_worker=1, processes=processes,
                         dashboard_address=":0" if dashboard else None,
                         silence_logs=logging.ERROR) as cluster, Client(cluster) as c:
        yield c


@contextlib.contextmanager
def _exclusive(directory: Path) -> Iterator[None]:
    """Hold an advisory lock so two sweeps never write the same directory."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    with (directory / ".lock").open("w") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise SweepError(f"another sweep is writing to {directory}") from None
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def _coerce_spec(spec: SweepSpec | str | os.PathLike | Mapping) -> SweepSpec:
    if isinstance(spec, SweepSpec):
        return spec
    if isinstance(spec, Mapping):
        return parse_sweep_spec(dict(spec))
    return load_sweep_spec(spec)


def run_sweep(spec: SweepSpec | str | os.PathLike | Mapping, *,
              out: str | os.PathLike | None = None,
              point_function: PointFunction | str | None = None,
              workers: int | None = None, scheduler: str | None = None, client=None,
              processes: bool = True, full_output: bool = False,
              retry_failed: bool = False, max_points: int | None = None,
              progress: bool = True, warmup: Callable[[], Any] | str | None = "auto",
              consolidate_every: float = 30.0,
              on_result: Callable[[dict], None] | None = None) -> SweepOutcome:
    """Run the missing points of a sweep on Dask and write the results table.

    Parameters
    ----------
    spec : SweepSpec, path or dict
        The sweep (a TOML file is read with :func:`load_sweep_spec`).
    out : path-like, optional
        Output directory (default ``./<spec name>-sweep``); see
        :mod:`hertzchain.sweep.store` for its layout.
    point_function : callable or str, optional
        ``f(scenario, *, out, progress) -> dict`` run for each point, or
        ``"module:function"``; default :func:`default_point_function` (every model of
        the point when ``[base.models]`` asks for them, else the discrete chain).  Must
        be importable (picklable by reference) on the workers when they are processes.
    workers : int, optional
        Worker processes of the local cluster (default: all cores).
    scheduler : str, optional
        Address of an existing ``dask.distributed`` scheduler (instead of a local cluster).
    client : distributed.Client, optional
        An existing client to use (neither closed nor warmed-up twice by this call).
    processes : bool
        Local cluster of processes (default) or of threads in this process.
    full_output : bool
        Pass ``out=DIR/runs/<id>.h5`` to the point function for a full per-run file.
    retry_failed : bool
        Also rerun points whose record is a failure.
    max_points : int, optional
        Stop (cleanly, resumable) after this many points finished in this call.
    progress : bool
        Show a tqdm progress bar (points done, failures, ETA) on stderr.
    warmup : callable, "auto" or None
        Run once on every worker with ``client.run`` before the points; "auto" calls the
        point function on :func:`tiny_scenario` of the first point (errors ignored).
    consolidate_every : float
        Seconds between atomic rewrites of ``results.h5`` while running.
    on_result : callable, optional
        Called in the client with each record after it is stored (a test hook; an
        exception from it, e.g. ``KeyboardInterrupt``, interrupts the sweep cleanly).

    Returns
    -------
    SweepOutcome

    Raises
    ------
    SweepError
        Invalid specification, unknown point function, or directory in use.
    """
    t_start = time.perf_counter()
    spec = _coerce_spec(spec)
    points = spec.points()
    directory = Path(out) if out is not None else Path.cwd() / f"{spec.name}-sweep"
    directory.mkdir(parents=True, exist_ok=True)
    table_path = directory / "results.h5"
    with _exclusive(directory):
        store = RecordStore(directory / "records.jsonl")
        records = store.load()
        if not records and table_path.exists():  # the records are lost, the table is not
            restored = records_from_table(table_path)
            if restored:
                log.warning("records.jsonl of %s is missing: %d finished point(s) restored "
                            "from %s", directory, len(restored), table_path)
                records.update({r["id"]: r for r in store.append_many(
                    list(restored.values()))})
        fn = resolve_point_function(default_point_function(spec) if point_function is None
                                    else point_function)
        fname = function_name(fn)
        todo = points_to_run(points, records, fname, retry_failed)
        n_skipped = len(points) - len(todo)
        with atomic_path(directory / "spec.json") as tmp:
            tmp.write_text(spec.to_json() + "\n", encoding="utf-8")
        n_run, interrupted, n_lost = 0, False, 0
        try:  # the table is written once, on the way out (and every consolidate_every s)
            if todo:
                if warmup == "auto":
                    tiny = tiny_scenario(spec.point_table(todo[0].values))
                    warmup = None if tiny is None else functools.partial(_warm, fn, tiny)
                n_run, interrupted, n_lost = _execute(
                    spec, points, todo, records, store, fn, fname, directory, table_path,
                    client=client, scheduler=scheduler, workers=workers,
                    processes=processes, full_output=full_output, max_points=max_points,
                    progress=progress, warmup=warmup if callable(warmup) else None,
                    consolidate_every=consolidate_every, on_result=on_result,
                    n_skipped=n_skipped)
        finally:
            write_table(table_path, spec, points, records)
    statuses = [records[p.id]["status"] if p.id in records else "pending" for p in points]
    incomplete = sum(1 for p in points if p.id in records
                     and records[p.id]["status"] in ("ok", "unverified")
                     and (records[p.id].get("summary") or {}).get("completed") is False)
    return SweepOutcome(
        directory=directory, table=table_path, n_points=len(points), n_skipped=n_skipped,
        n_run=n_run, n_ok=statuses.count("ok"), n_failed=statuses.count("failed"),
        n_pending=statuses.count("pending"), elapsed=time.perf_counter() - t_start,
        interrupted=interrupted or statuses.count("pending") > 0, n_incomplete=incomplete,
        n_lost=n_lost, n_unverified=statuses.count("unverified"))


def _worker_lost(exc: BaseException) -> bool:
    """A dask-side failure that says nothing about the point: its worker died.

    ``KilledWorker`` (the scheduler gave up after the worker running it died
    ``allowed-failures`` times: a crash, the OOM killer, a lost node).  Such a point is
    left pending, so a plain rerun retries it (not recorded as a failure that only
    ``--retry-failed`` would retry).
    """
    try:
        from distributed import KilledWorker
    except ImportError:  # pragma: no cover - dask is a dependency of sweeps
        return False
    return isinstance(exc, KilledWorker)


def _lost_record(rec: Mapping[str, Any] | None) -> bool:
    """A record of an older version that booked a worker loss as a point failure."""
    return bool(rec) and rec.get("status") == "failed" and str(
        rec.get("error", "")).startswith("dask: KilledWorker")


NO_WORKER_GRACE = 120.0
"""Seconds without any worker after which a sweep with pending points stops, s."""


class _WorkerWatch:
    """Stops a sweep whose cluster has had no worker for :data:`NO_WORKER_GRACE` s.

    Losing every worker (a remote cluster's nodes gone, every worker process killed
    without a nanny to restart it) left the driver waiting forever without a word.
    """

    def __init__(self, client, directory: Path, every: float = 2.0) -> None:
        self.client, self.directory, self.every = client, directory, every
        self.last_check = time.monotonic()
        self.since: float | None = None

    def check(self) -> None:
        now = time.monotonic()
        if now - self.last_check < self.every:
            return
        self.last_check = now
        try:
            n = len(self.client.scheduler_info().get("workers", {}))
        except Exception:  # noqa: BLE001 - the scheduler itself is gone
            n = 0
        if n:
            self.since = None
            return
        if self.since is None:
            self.since = now
            log.warning("the cluster has no worker; waiting up to %.0f s", NO_WORKER_GRACE)
        elif now - self.since >= NO_WORKER_GRACE:
            raise SweepError(
                f"the cluster has had no worker for {now - self.since:.0f} s (every worker "
                f"was lost): stopping; the finished points are kept in {self.directory}. "
                "Rerun the same command (with workers) to compute the rest")


def _batches(completed, watch: _WorkerWatch) -> Iterator[list]:
    """``completed.batches()``, checking for a cluster without workers while waiting."""
    while not completed.is_empty():
        if completed.has_ready():
            yield completed.next_batch(block=False)
            continue
        watch.check()
        time.sleep(0.05)


def _failed_record(point: Point, exc: BaseException) -> dict[str, Any]:
    return {"id": point.id, "values": point.values, "status": "failed",
            "error": f"dask: {type(exc).__name__}: {exc}", "summary": {},
            "point_wall_time": None, "worker": "", "full_output": ""}


def _execute(spec: SweepSpec, points: list[Point], todo: list[Point],
             records: dict[str, dict], store: RecordStore, fn: PointFunction, fname: str,
             directory: Path, table_path: Path, *, client, scheduler, workers, processes,
             full_output, max_points, progress, warmup, consolidate_every, on_result,
             n_skipped) -> tuple[int, bool, int]:
    from concurrent.futures import CancelledError

    from distributed import as_completed
    from tqdm.auto import tqdm

    runs = directory / "runs"
    if full_output:
        runs.mkdir(exist_ok=True)
    token = uuid.uuid4().hex[:8]
    n_run, n_failed, stopped = 0, 0, False
    lost: list[str] = []
    pending: dict[str, tuple[Any, Point]] = {}
    with _dask_client(client, scheduler, workers, processes) as c, \
            tqdm(total=len(points), initial=n_skipped, desc=spec.name, unit="pt",
                 disable=not progress, dynamic_ncols=True, mininterval=0.5) as bar:
        try:
            if progress and client is None:
                bar.write(f"Dask dashboard: {c.dashboard_link}", file=sys.stderr)
            if warmup is not None:
                bar.set_postfix_str("warming up workers")
                report = c.run(warmup)
                log.info("warm-up: %s", report)
            batched = spec.ensemble is not None and callable(getattr(fn, "batch", None))
            for p in [] if batched else todo:
                target = str(runs / f"{p.id}.h5") if full_output else None
                fut = c.submit(run_point, fn, p.scenario, p.id, p.values, target,
                               key=f"hertzchain-point-{p.id}-{token}", pure=False)
                pending[fut.key] = (fut, p)
            for pts in ensemble_batches(spec, todo) if batched else []:
                fut = c.submit(run_batch, fn, [p.scenario for p in pts], [p.id for p in pts],
                               [p.values for p in pts],
                               key=f"hertzchain-batch-{pts[0].id}-{token}", pure=False)
                pending[fut.key] = (fut, pts)
            bar.set_postfix(failed=0, refresh=False)
            last_write = time.monotonic()
            completed = as_completed([f for f, _ in pending.values()])
            watch = _WorkerWatch(c, directory)
            for batch in _batches(completed, watch):  # one fsync per batch of points
                done = []
                for fut in batch:
                    _, item = pending.pop(fut.key)
                    pts = item if isinstance(item, list) else [item]  # (an ensemble batch)
                    try:
                        res = fut.result()
                    except CancelledError:
                        continue
                    except Exception as exc:  # noqa: BLE001 - e.g. KilledWorker
                        if _worker_lost(exc):  # not the point's fault: stays pending
                            lost.extend(p.id for p in pts)
                            log.warning("point(s) %s lost their worker (%s); they stay "
                                        "pending", [p.id for p in pts], type(exc).__name__)
                            continue
                        res = [_failed_record(p, exc) for p in pts]
                    for rec in res if isinstance(res, list) else [res]:
                        rec["point_function"] = fname
                        done.append(rec)
                del batch
                if max_points is not None:
                    done = done[:max_points - n_run]
                appended = store.append_many(done)
                # book the whole batch (it is on disk) before any hook may interrupt, so
                # the table written on the way out holds every record that is on disk
                for rec in appended:
                    records[rec["id"]] = rec
                    n_run += 1
                    n_failed += rec["status"] != "ok"
                    bar.update(1)
                bar.set_postfix(failed=n_failed, refresh=False)
                if on_result is not None:
                    for rec in appended:
                        on_result(rec)
                if max_points is not None and n_run >= max_points:
                    stopped = True
                    break
                if time.monotonic() - last_write >= consolidate_every:
                    write_table(table_path, spec, points, records)
                    last_write = time.monotonic()
        except BaseException:
            stopped = True
            raise
        finally:
            if pending:
                c.cancel([f for f, _ in pending.values()])
                pending.clear()
    return n_run, stopped or bool(lost), len(lost)
